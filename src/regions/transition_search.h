#pragma once
// Finding the transitions of an analysis over its block structure. Internal to the engine.

#include <cstdint>
#include <functional>
#include <vector>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/regions/transitions.h"
#include "regions/region_labels.h"

namespace maximal_workspace {

struct TransitionOptions {
  // The search stops when the bracket along the step is shorter (m, or rad on a
  // rotational grid variable).
  double tolerance = 1e-9;
  double margin = 0.0;
  // Working modes of the uncoupled auxiliary: a transition flips one chain's branch
  // instead of a whole couple's.
  bool uncoupled = false;
  int threads = 0;
  std::function<void(double)> progress;  // fraction done, from the worker threads, serialised
};

struct TransitionSearch {
  TransitionGraph graph;
  std::uint64_t ikp_faces = 0;    // faces between the workspace and a tested outside cell
  std::uint64_t ikp_entries = 0;  // those faces counted once per chain not assembled across them
};

TransitionSearch findTransitions(const RobotModel& model, const Grid& grid, const PoseClassifier& classifier,
                                 const WorkspaceCells& cells, const RegionLabels& regions, const TransitionOptions& options);

// partner[m][k]: the working mode equal to m but for group k's branch (a group: an input's
// chains, or a single chain for uncoupled modes); -1 where none is analysed.
std::vector<std::vector<int>> partnerModes(const RobotModel& model, const std::vector<WorkingMode>& modes,
                                           bool uncoupled);

// The last point found assembled on the segment from `inside` (the chain assembled) to
// `outside` (not), the bracket narrowed until it is shorter than `tolerance`, the segment
// being `length` long (the grid step).
Pose findReachBoundary(const Chain& chain, const Eigen::Vector3d& platform_node, const Pose& inside,
                       const Pose& outside, double length, double tolerance);

// Calls found(block, cell, d, direction) for every face between a workspace cell and a
// tested outside cell, in block order within [first_block, end_block).
void forEachIkpFace(const WorkspaceCells& cells, const std::vector<std::uint8_t>& blocks_with_outside,
                    std::uint64_t first_block, std::uint64_t end_block,
                    const std::function<void(std::uint64_t, int, int, int)>& found);
// Per block: whether it holds a tested outside cell.
std::vector<std::uint8_t> blocksWithOutside(const WorkspaceCells& cells, int threads);

}  // namespace maximal_workspace
