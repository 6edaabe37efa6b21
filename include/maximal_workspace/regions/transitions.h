#pragma once
// Transitions between working modes (chapter section 5): two working modes that differ in
// one couple's branch are one and the same configuration where that couple's
// discriminant is zero, so a region of each that touches that IKP boundary with the same
// sign of det J_DKP can be joined there without crossing a DKP singularity.
// Each IKP boundary face gives one exact point, found by bisection along the grid step
// that leaves the couple's reach, and an edge for every such pair of regions at it.

#include <cstdint>
#include <vector>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/regions/regions.h"
#include "maximal_workspace/workspace/singularity_map.h"

namespace maximal_workspace {

struct TransitionPoint {
  Pose pose;                   // the limiting chain's discriminant is 0 here (to the tolerance)
  std::uint32_t voxel = 0;     // the inside voxel whose face it lies on
  std::uint8_t input = 0;      // the couple changing branch
  std::uint8_t chain = 0;      // the chain whose discriminant was bisected
};

struct Transition {
  std::uint32_t from_region = 0;  // from_region's mode has the lower index
  std::uint32_t to_region = 0;
  std::uint8_t input = 0;
  std::int8_t sign = 0;           // the assembly mode both regions belong to
  std::vector<std::uint32_t> points;  // into TransitionGraph::points
};

struct TransitionGraph {
  std::vector<TransitionPoint> points;
  std::vector<Transition> transitions;  // ordered by (from_region, to_region)
  // Per region: its connected component in the graph (regions joined by transitions,
  // always of one sign; transitions touching debris do not join), numbered in order of
  // their smallest region id.
  std::vector<std::int32_t> component;
};

struct TransitionOptions {
  // Bisection stops when the bracket along the step is shorter (m, or rad on a
  // rotational grid variable).
  double tolerance = 1e-9;
  double singular_threshold = 1e-3;
  // Working modes of the uncoupled auxiliary: a transition flips one chain's branch
  // instead of a whole couple's.
  bool uncoupled = false;
  int threads = 0;
};

TransitionGraph findTransitions(const RobotModel& model, const Grid& grid, const PoseClassifier& classifier,
                                const WorkspaceMap& map, const SingularityMap& singularities, const RegionMap& regions,
                                const TransitionOptions& options);

// What one IKP boundary face contributes: its exact point, and the pairs of regions
// (lower mode's first) that it joins.
struct FaceTransition {
  bool has_point = false;
  TransitionPoint point;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> region_pairs;
};

// partner[m][k]: the working mode equal to m but for group k's branch (a group: an input's
// chains, or a single chain for uncoupled modes); -1 where none is analysed.
std::vector<std::vector<int>> partnerModes(const RobotModel& model, const std::vector<WorkingMode>& modes,
                                           bool uncoupled);

// The face from the inside cell centre `inside` to the outside one `outside`, `length` apart,
// where `chain` leaves its reach; labels[m]: the region of working mode m at the inside
// cell (or -1). `measures` is scratch of one entry per working mode. The point's voxel is
// left for the caller to set.
FaceTransition transitionAcrossFace(const RobotModel& model, const PoseClassifier& classifier,
                                    const std::vector<std::vector<int>>& partner, const Pose& inside,
                                    const Pose& outside, double length, int chain, const std::int32_t* labels,
                                    const std::vector<Region>& regions, const TransitionOptions& options,
                                    double* measures);

// The graph of the faces' findings, in face order, and its connected components.
TransitionGraph joinTransitions(const std::vector<FaceTransition>& faces, const std::vector<Region>& regions);

// The last point found assembled on the segment from `inside` (the chain assembled) to
// `outside` (not), bisected until the bracket is shorter than `tolerance`, the segment
// being `length` long (the grid step).
Pose bisectReachBoundary(const Chain& chain, const Eigen::Vector3d& platform_node, const Pose& inside,
                         const Pose& outside, double length, double tolerance);

}  // namespace maximal_workspace
