#include "maximal_workspace/planner/trajectory.h"

#include <algorithm>
#include <cmath>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

// The input of each input of the robot at a pose in a working mode. Chains of a couple
// share their input: the first chain's is taken. At a transition point the two branches
// meet; there the mean of both roots is taken for every chain whose branch is about to
// change or has just changed, so the input does not jump by what the bisection left.
std::vector<double> inputsAt(const RobotModel& model, const Pose& pose, const std::vector<WorkingMode>& modes, int mode_index,
                             std::uint32_t meet_mask) {
  const WorkingMode& mode = modes[mode_index];
  const IkpResult ikp = solveIkp(model, pose);
  if (!ikp.assembled) throw UnassembledPose(pose, mode_index);
  std::vector<double> q(model.inputCount());
  for (int i = 0; i < model.inputCount(); ++i) {
    const int c = model.inputs[i].chains.front();
    const ChainSolution& chain = ikp.chains[c];
    if ((meet_mask >> c) & 1u) {
      const double p = chain.branch(Branch::Positive).q, n = chain.branch(Branch::Negative).q;
      // Revolute roots may straddle +/-pi: average along the short way round.
      const double gap = model.inputs[i].kind == InputKind::Revolute ? std::remainder(p - n, 2.0 * M_PI) : p - n;
      q[i] = n + 0.5 * gap;
    } else {
      q[i] = chain.branch(mode.branch(c)).q;
    }
  }
  return q;
}

std::vector<std::vector<double>> differences(const InputTrajectory& trajectory, bool second) {
  const std::size_t n = trajectory.time.size();
  std::vector<std::vector<double>> result(n, std::vector<double>(trajectory.inputs.size(), 0.0));
  for (std::size_t k = 1; k + 1 < n; ++k) {
    const double h1 = trajectory.time[k] - trajectory.time[k - 1], h2 = trajectory.time[k + 1] - trajectory.time[k];
    if (h1 <= 0.0 || h2 <= 0.0) continue;  // a transition: the same instant twice
    for (std::size_t i = 0; i < trajectory.inputs.size(); ++i) {
      const double d1 = (trajectory.q[k][i] - trajectory.q[k - 1][i]) / h1;
      const double d2 = (trajectory.q[k + 1][i] - trajectory.q[k][i]) / h2;
      result[k][i] = second ? 2.0 * (d2 - d1) / (h1 + h2) : (h1 * d2 + h2 * d1) / (h1 + h2);
    }
  }
  return result;
}

}  // namespace

UnassembledPose::UnassembledPose(const Pose& at, int in_mode)
    : InputError("the planned pose " + vectorText(at.position) + " cannot be assembled: the plan is broken"),
      pose(at),
      mode(in_mode) {}

void checkInputLimits(const RobotModel& model, const InputLimits& limits) {
  const int inputs = model.inputCount();
  if (static_cast<int>(limits.velocity.size()) != inputs || static_cast<int>(limits.acceleration.size()) != inputs) {
    throw InputError("input limits: one velocity and one acceleration limit per input are needed");
  }
  for (int i = 0; i < inputs; ++i) {
    if (!(limits.velocity[i] > 0.0) || !(limits.acceleration[i] > 0.0)) {
      throw InputError("input limits of " + model.inputs[i].name + " must be > 0");
    }
  }
}

double septic(double tau) {
  const double t2 = tau * tau, t4 = t2 * t2;
  return t4 * (35.0 - 84.0 * tau + 70.0 * t2 - 20.0 * t2 * tau);
}

InputTrajectory inputTrajectory(const RobotModel& model, const std::vector<WorkingMode>& modes, double grid_step,
                                const Plan& plan, const InputLimits& limits, int samples_per_segment) {
  const int inputs = model.inputCount();
  checkInputLimits(model, limits);
  InputTrajectory trajectory;
  for (const Input& input : model.inputs) trajectory.inputs.push_back(input.name);
  // Chains whose branch changes at waypoint w: those of the transition's couple.
  auto meetMask = [&](std::size_t w) {
    std::uint32_t mask = 0;
    for (const PlanTransition& t : plan.transitions) {
      if (t.waypoint == w || t.waypoint == w + 1) mask |= modes[t.from_mode].negative_chains ^ modes[t.to_mode].negative_chains;
    }
    return mask;
  };
  double clock = 0.0;
  for (std::size_t w = 0; w + 1 < plan.waypoints.size(); ++w) {
    const PlanWaypoint& a = plan.waypoints[w];
    const PlanWaypoint& b = plan.waypoints[w + 1];
    if (w == 0) {
      trajectory.waypoint_samples.push_back(0);
      trajectory.time.push_back(0.0);
      trajectory.poses.push_back(a.pose);
      trajectory.modes.push_back(a.mode);
      trajectory.q.push_back(inputsAt(model, a.pose, modes, a.mode, meetMask(0)));
    }
    if (a.mode != b.mode) {  // the transition: no motion, the next segment leaves in the new mode
      trajectory.waypoint_samples.push_back(trajectory.time.size() - 1);
      trajectory.modes.back() = b.mode;
      continue;
    }
    // Sample the segment uniformly in tau, densely enough that neighbouring samples are at
    // most half a grid step apart where the profile is fastest (ds/dtau peaks at 35/16);
    // time it with tau in [0, 1] first.
    const double length = (b.pose.position - a.pose.position).norm();
    const int samples = std::max(samples_per_segment,
                                 static_cast<int>(std::ceil(35.0 / 16.0 * length / (0.5 * grid_step))));
    std::vector<std::vector<double>> q = {trajectory.q.back()};
    std::vector<Pose> poses = {a.pose};
    for (int k = 1; k <= samples; ++k) {
      const double s = septic(static_cast<double>(k) / samples);
      Pose pose;
      pose.position = a.pose.position + s * (b.pose.position - a.pose.position);
      pose.euler_zyz = a.pose.euler_zyz + s * (b.pose.euler_zyz - a.pose.euler_zyz);
      if (k == samples) pose = b.pose;
      std::vector<double> sample = inputsAt(model, pose, modes, a.mode, k == samples ? meetMask(w + 1) : 0u);
      for (int i = 0; i < inputs; ++i) {  // unwrap revolute inputs next to the previous sample
        if (model.inputs[i].kind == InputKind::Revolute) sample[i] = q.back()[i] + std::remainder(sample[i] - q.back()[i], 2.0 * M_PI);
      }
      q.push_back(sample);
      poses.push_back(pose);
    }
    // Duration: the largest of what each input's velocity and acceleration limits ask.
    const double h = 1.0 / samples;
    double duration = 1e-3;
    for (int i = 0; i < inputs; ++i) {
      for (int k = 1; k < samples; ++k) {
        const double velocity = (q[k + 1][i] - q[k - 1][i]) / (2.0 * h);
        const double acceleration = (q[k + 1][i] - 2.0 * q[k][i] + q[k - 1][i]) / (h * h);
        duration = std::max({duration, std::abs(velocity) / limits.velocity[i],
                             std::sqrt(std::abs(acceleration) / limits.acceleration[i])});
      }
    }
    for (int k = 1; k <= samples; ++k) {
      trajectory.time.push_back(clock + duration * k * h);
      trajectory.poses.push_back(poses[k]);
      trajectory.modes.push_back(a.mode);
      trajectory.q.push_back(q[k]);
    }
    clock += duration;
    trajectory.waypoint_samples.push_back(trajectory.time.size() - 1);
  }
  return trajectory;
}

std::vector<std::vector<double>> inputVelocities(const InputTrajectory& trajectory) { return differences(trajectory, false); }

std::vector<std::vector<double>> inputAccelerations(const InputTrajectory& trajectory) { return differences(trajectory, true); }

}  // namespace maximal_workspace
