#pragma once
// Where one pose is in a workspace analysis (issue 17): its kinematics as `mow eval`
// reports them, the grid cell holding it and that cell's region in every working mode, and
// per assembly mode whether it is in the maximal operational workspace, else the nearest
// point that is. `mow eval --step` and workspace_server's /query_pose both answer from here.

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "maximal_workspace/kinematics/pose_analysis.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

// How far the pose's variables that are not on the grid may be from the grid's values (m,
// rad) for the pose to lie on it: a pose written in decimal, or through a quaternion,
// differs from them by rounding.
constexpr double kOnGridTolerance = 1e-9;

struct AssemblyModeAtPose {
  std::int8_t sign = 0;  // of det J_DKP
  // The pose's cell is in this assembly mode's maximal operational workspace: some working
  // mode has a non-debris region of this sign there.
  bool in_maximal = false;
  // One of those regions is joined to the start's by transitions: the robot reaches the
  // pose from the start without crossing a DKP singularity.
  bool reachable = false;
  // The working modes (indices into the analysis's) with a non-debris region of this sign
  // at the cell, and those regions.
  std::vector<int> modes;
  std::vector<std::int32_t> regions;
  // The pose itself when in_maximal, else the centre of the nearest cell of the maximal
  // workspace (smallest grid index among equals); none when that workspace is empty.
  bool has_nearest = false;
  std::uint64_t nearest_cell = 0;  // grid index, when has_nearest and not in_maximal
  Pose nearest;
  double distance = INFINITY;  // gridDistance from the pose to `nearest`
  // For an analysis over an orientation set, when the pose's position is in the grid's box:
  // the shares of the set its position reaches (coverageAt), in the maximal workspace
  // reachable from the start and in the traditional one.
  bool has_coverage = false;
  double coverage = 0.0, traditional_coverage = 0.0;
};

struct PoseQuery {
  // Every chain's IKP and, per working mode of the analysis (in its order), det J_DKP,
  // the measure and the limits: analysePose, what `mow eval` writes.
  PoseAnalysis kinematics;
  // The pose lies in the grid's box with its other variables at the grid's values (within
  // kOnGridTolerance); only then are `cell`, `in_workspace` and the regions about it.
  bool on_grid = false;
  std::uint64_t cell = 0;
  bool in_workspace = false;  // the cell is in the analysis's workspace (connected to the start)
  std::vector<std::int32_t> regions;  // per working mode: the cell's region, -1 for none
  std::array<AssemblyModeAtPose, 2> assembly_modes;  // sign +1, then -1
};

// Distance between two poses over the grid's variables alone: Euclidean, m for a
// translational grid; an angle counts as its difference within a half turn times the
// robot's characteristic length. The other variables are not the grid's to change.
double gridDistance(const RobotModel& model, const Grid& grid, const Pose& a, const Pose& b);

// `model` is the analysis's robot. Never throws for a finite pose; a non-finite one is
// off the grid, with NaN figures.
PoseQuery queryPose(const RobotModel& model, const WorkspaceAnalysis& analysis, const Pose& pose);

}  // namespace maximal_workspace
