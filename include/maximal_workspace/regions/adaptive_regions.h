#pragma once
// Regions and transitions on the adaptive workspace, block by block, never expanded to a
// per-voxel array: the same definitions as regions.h and transitions.h.

#include <cstdint>
#include <vector>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/regions/regions.h"
#include "maximal_workspace/regions/transitions.h"
#include "maximal_workspace/workspace/block_labels.h"

namespace maximal_workspace {

struct AdaptiveRegionMap {
  std::vector<LabelLayer> layers;  // per working mode: region ids, kNoLabel in the band or outside
  // Grouped by mode, each mode's in block order of first cell; seed_voxel is the grid
  // index of that cell.
  std::vector<Region> regions;

  std::int32_t label(std::uint64_t block, int cell, int mode) const { return layers[mode].label(block, cell); }
};

AdaptiveRegionMap labelRegionsAdaptive(const Grid& grid, const AdaptiveWorkspace& workspace,
                                       const DebrisThreshold& debris, int threads);

struct AdaptiveTransitions {
  TransitionGraph graph;         // points' voxel: the grid index of the inside cell
  std::uint64_t ikp_faces = 0;   // faces between the workspace and a tested outside cell
};

AdaptiveTransitions findTransitionsAdaptive(const RobotModel& model, const Grid& grid, const PoseClassifier& classifier,
                                            const AdaptiveWorkspace& workspace, const AdaptiveRegionMap& regions,
                                            const TransitionOptions& options);

}  // namespace maximal_workspace
