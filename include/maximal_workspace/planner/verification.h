#pragma once
// A plan is only as good as its check: follow the planned input trajectory through the
// direct kinematics, by Newton continuation of all the chains' equations (Eq. 1) from the
// previous pose, with the platform's orientation free, and confirm that the platform
// follows the planned TCP path, keeps its orientation, that det J_DKP keeps its sign, and
// that the robot keeps its limits (inputs in range, joint cones, rods apart).
// Independent of the planner: it uses only the robot model and the trajectory.

#include <cmath>
#include <cstdint>
#include <string>

#include "maximal_workspace/planner/trajectory.h"

namespace maximal_workspace {

struct Verification {
  bool passed = false;
  std::string message;             // the verdict with its figures, or why it failed
  double max_deviation = 0.0;      // m, largest |TCP - planned TCP| over all samples
  double max_waypoint_deviation = 0.0;  // m, the same at the plan's waypoints
  double max_rotation = 0.0;       // rad, largest orientation change from the start
  double min_abs_measure = 0.0;    // smallest |normalised det J_DKP| met
  // Smallest margins to the robot's limits met (kinematics/constraints.h); +infinity
  // where the robot file sets none.
  double min_input_margin = INFINITY, min_cone_margin = INFINITY, min_rod_margin = INFINITY;
  std::size_t samples = 0;
  std::size_t failed_sample = 0;  // when it failed: the trajectory sample where it did
};

// Passes when every sample's DKP solution is within `tolerance` (m) of the planned TCP,
// its orientation within `tolerance` (rad) of the planned one, det J_DKP has `sign`
// throughout, and no limit of the robot is broken by more than `tolerance` (m or rad).
Verification verifyByDkpContinuation(const RobotModel& model, const InputTrajectory& trajectory, std::int8_t sign,
                                     double tolerance = 1e-6);

}  // namespace maximal_workspace
