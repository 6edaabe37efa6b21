#pragma once
// The regions of every working mode over the block structure, never expanded to a
// per-cell array: a label layer per working mode. Internal to the engine.

#include <functional>
#include <vector>

#include "maximal_workspace/regions/regions.h"
#include "maximal_workspace/workspace/cancellation.h"
#include "maximal_workspace/workspace/grid.h"
#include "workspace/block_storage.h"

namespace maximal_workspace {

struct RegionLabels {
  std::vector<LabelLayer> layers;  // per working mode: region ids, kNoLabel in the band or outside
  // Grouped by mode, each mode's in block order of first cell.
  std::vector<Region> regions;

  std::int32_t label(std::uint64_t block, int cell, int mode) const { return layers[mode].label(block, cell); }
};

// progress(fraction): called after each working mode, from the calling thread; `cancelled`
// is asked while each mode is labelled.
RegionLabels labelRegions(const Grid& grid, const WorkspaceCells& cells, const DebrisThreshold& debris, int threads,
                          const std::function<void(double)>& progress = {}, const CancelCheck& cancelled = {});

}  // namespace maximal_workspace
