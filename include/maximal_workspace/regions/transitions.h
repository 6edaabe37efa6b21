#pragma once
// Transitions between working modes (chapter section 5): two working modes that differ in
// one couple's branch are one and the same configuration where that couple's
// discriminant is zero, so a region of each that touches that IKP boundary with the same
// sign of det J_DKP can be joined there without crossing a DKP singularity.
// Each IKP boundary face gives one exact point, found by bisection along the grid step
// that leaves the couple's reach, and an edge for every such pair of regions at it.

#include <cstdint>
#include <vector>

#include "maximal_workspace/model/pose.h"

namespace maximal_workspace {

// 32 bytes: at 1 mm the delta-like robot has 6.7 M points. Where a point's pose is asked,
// TransitionGraph::pose gives it whole.
struct TransitionPoint {
  Eigen::Vector3d position;  // the limiting chain's discriminant is 0 here (to the tolerance)
  std::uint64_t cell : 48;   // grid index of the workspace cell whose face it lies on
  std::uint64_t input : 8;   // the couple changing branch
  std::uint64_t chain : 8;   // the chain whose discriminant was bisected
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
  // The points' orientations (ZYZ): on a grid without rotational variables every point
  // has the grid's, `orientation`, and `orientations` is empty; else it holds each point's.
  Eigen::Vector3d orientation = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> orientations;
  std::vector<Transition> transitions;  // ordered by (from_region, to_region)
  // Per region: its connected component in the graph (regions joined by transitions,
  // always of one sign; transitions touching debris do not join), numbered in order of
  // their smallest region id.
  std::vector<std::int32_t> component;

  Pose pose(std::size_t point) const {
    Pose result;
    result.position = points[point].position;
    result.euler_zyz = orientations.empty() ? orientation : orientations[point];
    return result;
  }
};

}  // namespace maximal_workspace
