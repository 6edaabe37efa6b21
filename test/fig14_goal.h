#pragma once
// The chapter's Fig. 14 situation on a dense analysis, shared by the planner tests.

#include <cstdint>

#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace::test {

// A voxel reachable from the start through transitions (its region is joined to the
// start's in the transition graph) that no single working mode joins to the start (in no
// mode do both lie in one region), more than 0.3 m from the start so the exact goal pose is
// away from singularities; 0 when there is none.
inline std::uint32_t fig14Goal(const WorkspaceAnalysis& a) {
  const std::int32_t start_region = a.regions.label(0, a.start_mode);
  auto centre = [&a](std::uint32_t voxel) { return a.grid.pose(a.map.voxel_cell[voxel]).position; };
  for (std::uint32_t v = 0; v < a.map.voxelCount(); v += 101) {
    bool single = false, reachable = false;
    for (int m = 0; m < a.map.mode_count; ++m) {
      const std::int32_t label = a.regions.label(v, m);
      if (label < 0) continue;
      single = single || label == a.regions.label(0, m);
      const Region& region = a.regions.regions[label];
      reachable = reachable || (!region.debris && region.sign == a.regions.regions[start_region].sign &&
                                a.transitions.component[label] == a.transitions.component[start_region]);
    }
    if (!single && reachable && (centre(v) - centre(0)).norm() > 0.3) return v;
  }
  return 0;
}

}  // namespace maximal_workspace::test
