#include "maximal_workspace/planner/path_request.h"

#include <cmath>

#include <Eigen/Geometry>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/regions/workspace_analysis.h"  // resolveStartMode

namespace maximal_workspace {

bool startLeftOut(const PathRequest& request) {
  const auto zero = [](const auto& values) {
    for (double value : values) {
      if (value != 0.0) return false;
    }
    return true;
  };
  return zero(request.start.position) && zero(request.start.orientation) && request.start_inputs.empty() &&
         request.start_working_mode.empty();
}

Pose requestedPose(const RequestPose& request, const RobotModel& model, const std::string& what) {
  Pose pose = model.reference.pose;
  pose.position = Eigen::Vector3d(request.position[0], request.position[1], request.position[2]);
  if (!pose.position.allFinite()) throw InputError(what + ": position must be finite");
  const Eigen::Quaterniond q(request.orientation[0], request.orientation[1], request.orientation[2], request.orientation[3]);
  // A message whose orientation was left out holds (0, 0, 0, 0): the reference orientation.
  if (q.coeffs().isZero(0.0)) return pose;
  if (!(std::abs(q.norm() - 1.0) < 1e-6)) throw InputError(what + ": orientation must be a unit quaternion");
  pose.setRotation(q.normalized().toRotationMatrix());
  return pose;
}

Pose referenceOrientationPose(const RequestPose& request, const RobotModel& model, const std::string& what) {
  const Pose requested = requestedPose(request, model, what);
  const double angle =
      Eigen::AngleAxisd(requested.rotation() * model.reference.pose.rotation().transpose()).angle();
  if (angle > 1e-6) {
    throw InputError(what + ": orientation must be the robot's reference orientation (it differs by " + numberText(angle) + " rad)");
  }
  Pose pose = model.reference.pose;
  pose.position = requested.position;
  return pose;
}

PlanRequest resolvePathRequest(const RobotModel& model, const std::vector<WorkingMode>& modes, const PathRequest& request) {
  PlanRequest plan;
  const auto pose = request.orientationSet() ? requestedPose : referenceOrientationPose;
  plan.start = pose(request.start, model, "start");
  plan.goal = pose(request.goal, model, "goal");
  if (!request.start_working_mode.empty()) {
    plan.start_mode = workingModeIndex(modes, request.start_working_mode, "start_working_mode");
  } else if (!request.start_inputs.empty()) {
    if (static_cast<int>(request.start_inputs.size()) != model.inputCount()) {
      throw InputError("start_inputs: expected one value per input (" + std::to_string(model.inputCount()) + ")");
    }
    const WorkingModeIdentification found = identifyWorkingMode(model, solveIkp(model, plan.start), request.start_inputs);
    if (!found.found) throw InputError("start_inputs: " + found.reason);
    if (!found.coupled) throw InputError("start_inputs: chains " + found.uncoupled.name + " are not a working mode of the robot");
    plan.start_mode = workingModeIndex(modes, found.working_mode.name, "start_inputs");
  } else {
    plan.start_mode = resolveStartMode(model, modes, plan.start, "");
  }
  if (!request.goal_working_mode.empty()) plan.goal_mode = workingModeIndex(modes, request.goal_working_mode, "goal_working_mode");
  if (!(request.clearance >= 0.0 && request.clearance < 1.0)) throw InputError("clearance must be in [0, 1)");
  if (request.assembly_mode < -1 || request.assembly_mode > 1) throw InputError("assembly_mode must be 0, 1 or -1");
  if (!(request.time_limit >= 0.0 && request.time_limit <= 3600.0)) throw InputError("time_limit must be in [0, 3600] s");
  // 0, a message's default: the planner's own.
  plan.clearance = request.clearance > 0.0 ? request.clearance : kDefaultPlanClearance;
  plan.time_limit = request.time_limit > 0.0 ? request.time_limit : kDefaultPlanTimeLimit;
  if (request.single_working_mode) plan.allowed_modes = {plan.start_mode};
  return plan;
}

}  // namespace maximal_workspace
