#pragma once
// What a consumer of an analysis (the planner) asks of it, whichever structure holds the
// voxels: the dense arrays of workspace_analysis.h or the blocks of adaptive_analysis.h.
// Cells are grid indices.

#include <cstdint>
#include <memory>
#include <vector>

#include "maximal_workspace/regions/adaptive_analysis.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

class RegionLookup {
 public:
  virtual ~RegionLookup() = default;
  virtual const Grid& grid() const = 0;
  virtual const std::vector<WorkingMode>& modes() const = 0;
  virtual const std::vector<Region>& regions() const = 0;
  virtual const TransitionGraph& transitions() const = 0;
  // The cell is in the workspace (connected to the start).
  virtual bool inside(std::uint64_t cell) const = 0;
  // The region of working mode `mode` at a cell, or -1 (singular band, or not inside).
  virtual std::int32_t label(std::uint64_t cell, int mode) const = 0;
};

// Views over an analysis, which must outlive them.
std::unique_ptr<RegionLookup> regionLookup(const WorkspaceAnalysis& analysis);
std::unique_ptr<RegionLookup> regionLookup(const AdaptiveAnalysis& analysis);

}  // namespace maximal_workspace
