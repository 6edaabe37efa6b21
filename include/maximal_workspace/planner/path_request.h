#pragma once
// A /plan_path request in plain types, checked and resolved without ROS into the planner's
// PlanRequest. path_planner translates its service request into this; the fuzz target
// test/fuzz/fuzz_path_request.cpp feeds it arbitrary fields.

#include <array>
#include <string>
#include <vector>

#include "maximal_workspace/planner/path_planner.h"

namespace maximal_workspace {

// A TCP pose of a request: position (m) and orientation as a quaternion (w, x, y, z).
struct RequestPose {
  std::array<double, 3> position{};
  std::array<double, 4> orientation{1.0, 0.0, 0.0, 0.0};
};

// The request fields that decide a plan (PlanPath.srv documents each).
struct PathRequest {
  RequestPose start, goal;
  std::vector<double> start_inputs;
  std::string start_working_mode;
  std::string goal_working_mode;
  double clearance = 0.0;
  double time_limit = 0.0;  // s; 0: the planner's default
  int assembly_mode = 0;
  bool single_working_mode = false;
  // An orientation set (WorkspaceRequest's fields): any orientation of it may be asked.
  double tilt_max = 0.0;
  std::vector<double> torsion;
  double angle_step = 0.0;

  bool orientationSet() const { return tilt_max != 0.0 || !torsion.empty() || angle_step != 0.0; }
};

// The start was left out: its pose all zeros (position and quaternion, what a message holds
// when the field is not given), with no start inputs and no start working mode. The caller
// puts the robot's current configuration there, or the reference one.
bool startLeftOut(const PathRequest& request);

// The pose in ZYZ angles (Pose::setRotation), which must be finite with a unit quaternion;
// a zero quaternion, what a message holds when its orientation is left out, stands for the
// robot's reference orientation. Throws InputError naming `what`.
Pose requestedPose(const RequestPose& pose, const RobotModel& model, const std::string& what);

// The same, and the orientation must be the robot's reference one (the planner and the
// display work on the constant-orientation workspace).
Pose referenceOrientationPose(const RequestPose& pose, const RobotModel& model, const std::string& what);

// Throws InputError naming the field and the reason. `modes`: the analysis's working modes.
// The assembly mode is checked against the plan by the caller. Start and goal keep the
// reference orientation unless the request asks for an orientation set.
PlanRequest resolvePathRequest(const RobotModel& model, const std::vector<WorkingMode>& modes, const PathRequest& request);

}  // namespace maximal_workspace
