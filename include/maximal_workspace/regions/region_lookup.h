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
  RegionLookup(const Grid& grid, const std::vector<WorkingMode>& modes, const std::vector<Region>& regions,
               const TransitionGraph& transitions)
      : grid_(grid), modes_(modes), regions_(regions), transitions_(transitions) {}
  virtual ~RegionLookup() = default;

  const Grid& grid() const { return grid_; }
  const std::vector<WorkingMode>& modes() const { return modes_; }
  const std::vector<Region>& regions() const { return regions_; }
  const TransitionGraph& transitions() const { return transitions_; }
  // The cell is in the workspace (connected to the start).
  virtual bool inside(std::uint64_t cell) const = 0;
  // The region of working mode `mode` at a cell, or -1 (singular band, or not inside).
  virtual std::int32_t label(std::uint64_t cell, int mode) const = 0;

 private:
  const Grid& grid_;
  const std::vector<WorkingMode>& modes_;
  const std::vector<Region>& regions_;
  const TransitionGraph& transitions_;
};

// Views over an analysis, which must outlive them.
std::unique_ptr<RegionLookup> regionLookup(const WorkspaceAnalysis& analysis);
std::unique_ptr<RegionLookup> regionLookup(const AdaptiveAnalysis& analysis);

}  // namespace maximal_workspace
