#pragma once
// A plan is only as good as its check: follow the planned input trajectory through the
// direct kinematics, by Newton continuation of all the chains' equations (Eq. 1) from the
// previous pose, with the platform's orientation free, and confirm that the platform
// follows the planned TCP path, keeps its orientation, and that det J_DKP keeps its sign.
// Independent of the planner: it uses only the robot model and the trajectory.

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
  std::size_t samples = 0;
};

// Passes when every sample's DKP solution is within `tolerance` (m) of the planned TCP,
// its orientation within `tolerance` (rad) of the planned one, and det J_DKP has `sign`
// throughout.
Verification verifyByDkpContinuation(const RobotModel& model, const InputTrajectory& trajectory, std::int8_t sign,
                                     double tolerance = 1e-6);

}  // namespace maximal_workspace
