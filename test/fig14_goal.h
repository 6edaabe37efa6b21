#pragma once
// The chapter's Fig. 14 situation on an analysis, shared by the planner tests.

#include <cstdint>

#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace::test {

// A cell reachable from the start through transitions (its region is joined to the
// start's in the transition graph) that no single working mode joins to the start (in no
// mode do both lie in one region), more than 0.3 m from the start so the exact goal pose is
// away from singularities; 0 when there is none. Cells are tried with a stride, in grid order.
inline std::uint64_t fig14Goal(const WorkspaceAnalysis& a) {
  const Grid& grid = a.grid();
  std::uint64_t start = 0;
  grid.cellOf(grid.spec().start, &start);
  const std::int32_t start_region = a.label(start, a.startMode());
  const std::vector<Region>& regions = a.regions();
  const std::vector<std::int32_t>& component = a.transitions().component;
  const int modes = static_cast<int>(a.modes().size());
  for (std::uint64_t cell = 0; cell < grid.cellCount(); cell += 101) {
    if (!a.inside(cell)) continue;
    bool single = false, reachable = false;
    for (int m = 0; m < modes; ++m) {
      const std::int32_t label = a.label(cell, m);
      if (label < 0) continue;
      single = single || label == a.label(start, m);
      const Region& region = regions[label];
      reachable = reachable || (!region.debris && region.sign == regions[start_region].sign &&
                                component[label] == component[start_region]);
    }
    if (!single && reachable && (grid.pose(cell).position - grid.pose(start).position).norm() > 0.3) return cell;
  }
  return 0;
}

}  // namespace maximal_workspace::test
