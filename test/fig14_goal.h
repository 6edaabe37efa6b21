#pragma once
// The chapter's Fig. 14 situation on an analysis, shared by the planner tests.

#include <cstdint>

#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace::test {

// The start's region of an analysis and the regions transitions join to it.
class StartGroup {
 public:
  explicit StartGroup(const WorkspaceAnalysis& analysis) : analysis_(analysis) {
    const Grid& grid = analysis.grid();
    grid.cellOf(grid.spec().start, &start_cell_);
    start_region_ = analysis.label(start_cell_, analysis.startMode());
  }

  std::uint64_t startCell() const { return start_cell_; }
  std::int32_t startRegion() const { return start_region_; }

  // A region at `cell` reachable from the start through transitions (non-debris, of the
  // start's sign, joined to the start's region in the transition graph), or -1.
  std::int32_t reachedIn(std::uint64_t cell) const {
    const std::vector<Region>& regions = analysis_.regions();
    const std::vector<std::int32_t>& component = analysis_.transitions().component;
    for (int m = 0; m < static_cast<int>(analysis_.modes().size()); ++m) {
      const std::int32_t label = analysis_.label(cell, m);
      if (label >= 0 && !regions[label].debris && regions[label].sign == regions[start_region_].sign &&
          component[label] == component[start_region_]) {
        return label;
      }
    }
    return -1;
  }

 private:
  const WorkspaceAnalysis& analysis_;
  std::uint64_t start_cell_ = 0;
  std::int32_t start_region_ = -1;
};

// A cell reachable from the start through transitions that no single working mode joins to
// the start (in no mode do both lie in one region), more than 0.3 m from the start so the
// exact goal pose is away from singularities; 0 when there is none. Cells are tried with a
// stride, in grid order.
inline std::uint64_t fig14Goal(const WorkspaceAnalysis& a) {
  const Grid& grid = a.grid();
  const StartGroup group(a);
  const int modes = static_cast<int>(a.modes().size());
  for (std::uint64_t cell = 0; cell < grid.cellCount(); cell += 101) {
    if (!a.inside(cell) || group.reachedIn(cell) < 0) continue;
    bool single = false;
    for (int m = 0; m < modes && !single; ++m) {
      const std::int32_t label = a.label(cell, m);
      single = label >= 0 && label == a.label(group.startCell(), m);
    }
    if (!single && (grid.pose(cell).position - grid.pose(group.startCell()).position).norm() > 0.3) return cell;
  }
  return 0;
}

}  // namespace maximal_workspace::test
