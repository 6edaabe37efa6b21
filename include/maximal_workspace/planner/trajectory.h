#pragma once
// The planned path as actuator inputs over time. Each straight segment between waypoints
// is travelled with a rest-to-rest septic profile, s(tau) = 35 tau^4 - 84 tau^5 +
// 70 tau^6 - 20 tau^7, whose first three derivatives vanish at both ends: near a
// transition point an input behaves like the square root of the distance to it (the two
// IKP roots meet there), and with s ~ (1 - tau)^4 it becomes smooth in time, with finite
// velocity and acceleration. Each segment lasts as long as the slowest input's velocity
// and acceleration limits require.

#include <string>
#include <vector>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/planner/path_planner.h"

namespace maximal_workspace {

struct InputLimits {
  std::vector<double> velocity;      // per input, m/s or rad/s
  std::vector<double> acceleration;  // per input, m/s^2 or rad/s^2
};

struct InputTrajectory {
  std::vector<std::string> inputs;       // input names
  std::vector<double> time;              // s, per sample
  std::vector<Pose> poses;               // the planned TCP pose of each sample
  std::vector<int> modes;                // working mode of each sample
  std::vector<std::vector<double>> q;    // per sample, per input (revolute inputs unwrapped)
  std::vector<std::size_t> waypoint_samples;  // sample of each plan waypoint
};

// A plan whose pose cannot be assembled where the trajectory samples it: a segment the
// planner's checks passed leaves the workspace between their samples.
class UnassembledPose : public InputError {
 public:
  UnassembledPose(const Pose& pose, int mode);
  Pose pose;
  int mode;
};

// Throws InputError when a limit is missing or not > 0.
void checkInputLimits(const RobotModel& model, const InputLimits& limits);

// Each segment gets at least `samples_per_segment` samples, more on long segments so that
// neighbouring samples are at most half a grid step apart. Throws InputError when a limit
// is missing or not > 0, UnassembledPose when a sample cannot be assembled.
// `modes`: the analysis's working modes, which the plan's waypoints index.
InputTrajectory inputTrajectory(const RobotModel& model, const std::vector<WorkingMode>& modes, double grid_step,
                                const Plan& plan, const InputLimits& limits, int samples_per_segment = 64);
inline InputTrajectory inputTrajectory(const RobotModel& model, const WorkspaceAnalysis& analysis, const Plan& plan,
                                       const InputLimits& limits, int samples_per_segment = 64) {
  return inputTrajectory(model, analysis.modes(), analysis.grid().step(0), plan, limits, samples_per_segment);
}

// Central finite differences of q over time: per sample and input.
std::vector<std::vector<double>> inputVelocities(const InputTrajectory& trajectory);
std::vector<std::vector<double>> inputAccelerations(const InputTrajectory& trajectory);

// The septic profile and its derivative in tau.
double septic(double tau);

}  // namespace maximal_workspace
