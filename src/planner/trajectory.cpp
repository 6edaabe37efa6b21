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

// The pose at s of the straight segment from a to b (Euler angles interpolated).
Pose along(const Pose& a, const Pose& b, double s) {
  Pose pose;
  pose.position = a.position + s * (b.position - a.position);
  pose.euler_zyz = a.euler_zyz + s * (b.euler_zyz - a.euler_zyz);
  return pose;
}

// Revolute inputs taken next to the previous sample's.
void unwrapNextTo(const RobotModel& model, const std::vector<double>& previous, std::vector<double>& q) {
  for (int i = 0; i < model.inputCount(); ++i) {
    if (model.inputs[i].kind == InputKind::Revolute) q[i] = previous[i] + std::remainder(q[i] - previous[i], 2.0 * M_PI);
  }
}

// The samples of one straight segment in one working mode: tau in [0, 1], the planned
// pose at septic(tau), and its inputs.
struct SegmentSamples {
  std::vector<double> tau;
  std::vector<Pose> poses;
  std::vector<std::vector<double>> q;
};

// Between two samples a controller moves the inputs linearly, and the platform follows the
// inputs' chord, not the planned segment: where the mechanism is poorly conditioned (a
// measure of a few 1e-3), a chord of a few mrad can take it through a DKP singularity
// that the planned segment keeps clear of (measured on the planar 3-RRR at 5 mm). So the
// chord is refined where it strays from the inputs of the planned poses: a sample is added
// at the middle until the chord passes within kChordTolerance of them, down to 1/256 of
// the interval. Not next to a transition point, where a chain's two roots meet and the
// sample there takes their mean: its inputs go like a square root, and the chord strays
// by what the bisection left.
constexpr double kChordTolerance = 1e-6;  // m or rad
constexpr int kMaxChordDepth = 8;

class SegmentSampler {
 public:
  SegmentSampler(const RobotModel& model, const std::vector<WorkingMode>& modes, const PlanWaypoint& a, const PlanWaypoint& b)
      : model_(model), modes_(modes), a_(a), b_(b) {}

  // `samples` intervals uniform in tau, each refined unless it ends at a meeting point.
  SegmentSamples take(const std::vector<double>& first_q, int samples, std::uint32_t start_meet, std::uint32_t end_meet) const {
    SegmentSamples out{{0.0}, {a_.pose}, {first_q}};
    for (int k = 1; k <= samples; ++k) {
      const double tau = static_cast<double>(k) / samples;
      const Pose pose = k == samples ? b_.pose : along(a_.pose, b_.pose, septic(tau));
      std::vector<double> q = inputsAt(model_, pose, modes_, a_.mode, k == samples ? end_meet : 0u);
      unwrapNextTo(model_, out.q.back(), q);
      const bool meeting = (k == 1 && start_meet != 0u) || (k == samples && end_meet != 0u);
      if (!meeting) refine(out.tau.back(), tau, std::vector<double>(out.q.back()), q, 0, out);
      out.tau.push_back(tau);
      out.poses.push_back(pose);
      out.q.push_back(std::move(q));
    }
    return out;
  }

 private:
  void refine(double tau0, double tau1, const std::vector<double>& q0, const std::vector<double>& q1, int depth,
              SegmentSamples& out) const {
    if (depth == kMaxChordDepth) return;
    const double middle = 0.5 * (tau0 + tau1);
    const Pose pose = along(a_.pose, b_.pose, septic(middle));
    std::vector<double> q = inputsAt(model_, pose, modes_, a_.mode, 0u);
    unwrapNextTo(model_, q0, q);
    double stray = 0.0;
    for (std::size_t i = 0; i < q.size(); ++i) stray = std::max(stray, std::abs(q[i] - 0.5 * (q0[i] + q1[i])));
    if (stray <= kChordTolerance) return;
    refine(tau0, middle, q0, q, depth + 1, out);
    out.tau.push_back(middle);
    out.poses.push_back(pose);
    out.q.push_back(q);
    refine(middle, tau1, q, q1, depth + 1, out);
  }

  const RobotModel& model_;
  const std::vector<WorkingMode>& modes_;
  const PlanWaypoint& a_;
  const PlanWaypoint& b_;
};

// The duration of a segment: the largest of what each input's velocity and acceleration
// limits ask, from finite differences over its samples (tau need not be uniform).
double segmentDuration(const SegmentSamples& segment, const InputLimits& limits) {
  double duration = 1e-3;
  const std::vector<double>& tau = segment.tau;
  for (std::size_t k = 1; k + 1 < tau.size(); ++k) {
    const double h1 = tau[k] - tau[k - 1], h2 = tau[k + 1] - tau[k];
    for (std::size_t i = 0; i < segment.q[k].size(); ++i) {
      const double d1 = (segment.q[k][i] - segment.q[k - 1][i]) / h1, d2 = (segment.q[k + 1][i] - segment.q[k][i]) / h2;
      const double velocity = (h1 * d2 + h2 * d1) / (h1 + h2), acceleration = 2.0 * (d2 - d1) / (h1 + h2);
      duration = std::max({duration, std::abs(velocity) / limits.velocity[i],
                           std::sqrt(std::abs(acceleration) / limits.acceleration[i])});
    }
  }
  return duration;
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
    // most half a grid step apart where the profile is fastest (ds/dtau peaks at 35/16),
    // turns counted as arcs at the characteristic length; time it with tau in [0, 1] first.
    const double length = std::max((b.pose.position - a.pose.position).norm(),
                                   model.characteristic_length * (b.pose.euler_zyz - a.pose.euler_zyz).norm());
    const int samples = std::max(samples_per_segment,
                                 static_cast<int>(std::ceil(35.0 / 16.0 * length / (0.5 * grid_step))));
    const SegmentSamples segment =
        SegmentSampler(model, modes, a, b).take(trajectory.q.back(), samples, meetMask(w), meetMask(w + 1));
    const double duration = segmentDuration(segment, limits);
    for (std::size_t k = 1; k < segment.tau.size(); ++k) {
      trajectory.time.push_back(clock + duration * segment.tau[k]);
      trajectory.poses.push_back(segment.poses[k]);
      trajectory.modes.push_back(a.mode);
      trajectory.q.push_back(segment.q[k]);
    }
    clock += duration;
    trajectory.waypoint_samples.push_back(trajectory.time.size() - 1);
  }
  return trajectory;
}

std::vector<std::vector<double>> inputVelocities(const InputTrajectory& trajectory) { return differences(trajectory, false); }

std::vector<std::vector<double>> inputAccelerations(const InputTrajectory& trajectory) { return differences(trajectory, true); }

}  // namespace maximal_workspace
