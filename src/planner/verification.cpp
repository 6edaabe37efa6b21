#include "maximal_workspace/planner/verification.h"

#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

// The platform as the continuation carries it: position and rotation matrix (no angles,
// so no representation singularity).
struct PlatformState {
  Eigen::Vector3d position;
  Eigen::Matrix3d rotation;
};

// Eq. 1 for every chain with its input fixed, halved (like the Jacobians), and the
// configuration it describes.
Eigen::VectorXd residuals(const RobotModel& model, const PlatformState& state, const std::vector<double>& inputs,
                          Configuration* configuration) {
  Eigen::VectorXd f(model.chainCount());
  configuration->chain_count = model.chainCount();
  configuration->pose.position = state.position;
  for (int c = 0; c < model.chainCount(); ++c) {
    const Chain& chain = *model.chains[c];
    const double q = inputs[model.chain_input[c]];
    configuration->p[c] = state.position + state.rotation * chain.platformNode();
    configuration->a[c] = chain.intermediateNode(q);
    configuration->q[c] = q;
    f[c] = 0.5 * ((configuration->p[c] - configuration->a[c]).squaredNorm() - chain.rodLength() * chain.rodLength());
  }
  return f;
}

// Newton on the platform's DOF from the previous state; false when it does not converge.
bool solveDkp(const RobotModel& model, const std::vector<double>& inputs, PlatformState& state, Configuration* configuration) {
  for (int iteration = 0; iteration < 30; ++iteration) {
    const Eigen::VectorXd f = residuals(model, state, inputs, configuration);
    if (f.cwiseAbs().maxCoeff() < 1e-15) return true;
    // Twist form: J [v; w] = -f, rotational DOF as small rotations about base axes.
    const DkpJacobian jacobian = dkpJacobianTwist(model, *configuration);
    const Eigen::VectorXd step = jacobian.fullPivLu().solve(-f);
    Eigen::Vector3d translation = Eigen::Vector3d::Zero(), rotation = Eigen::Vector3d::Zero();
    for (int j = 0; j < model.dof(); ++j) {
      const OutputVariable variable = model.output_variables[j];
      if (!isRotational(variable)) {
        translation[static_cast<int>(variable)] = step[j];
      } else if (model.hasOutputVariable(OutputVariable::Theta)) {
        rotation[static_cast<int>(variable) - 3] = step[j];
      } else {
        rotation.z() = step[j];  // planar: rotation about z only
      }
    }
    state.position += translation;
    if (rotation.norm() > 0.0) state.rotation = Eigen::AngleAxisd(rotation.norm(), rotation.normalized()) * state.rotation;
    if (step.norm() < 1e-14) return residuals(model, state, inputs, configuration).cwiseAbs().maxCoeff() < 1e-12;
  }
  return false;
}

std::string figure(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

}  // namespace

Verification verifyByDkpContinuation(const RobotModel& model, const InputTrajectory& trajectory, std::int8_t sign,
                                     double tolerance) {
  Verification result;
  if (trajectory.time.empty()) {
    result.message = "empty trajectory";
    return result;
  }
  PlatformState state{trajectory.poses.front().position, trajectory.poses.front().rotation()};
  const Eigen::Matrix3d start_rotation = state.rotation;
  result.min_abs_measure = INFINITY;
  std::size_t next_waypoint = 0;
  Configuration configuration;
  const RobotConstraints constraints(model);
  for (std::size_t k = 0; k < trajectory.time.size(); ++k) {
    // Between samples the inputs move as an executing controller moves them, linearly, in
    // steps small enough (1 mm or 1 mrad) that Newton stays on the solution it follows.
    const std::vector<double>& to = trajectory.q[k];
    const std::vector<double>& from = trajectory.q[k > 0 ? k - 1 : 0];
    double largest = 0.0;
    for (std::size_t i = 0; i < to.size(); ++i) largest = std::max(largest, std::abs(to[i] - from[i]));
    const int substeps = std::max(1, static_cast<int>(std::ceil(largest / 1e-3)));
    std::vector<double> inputs(to.size());
    for (int s = 1; s <= substeps; ++s) {
      for (std::size_t i = 0; i < to.size(); ++i) inputs[i] = from[i] + (to[i] - from[i]) * s / substeps;
      if (!solveDkp(model, inputs, state, &configuration)) {
        result.failed_sample = k;
        result.message = "DKP continuation lost at t = " + figure(trajectory.time[k]) + " s (sample " + std::to_string(k) +
                         ", at " + vectorText(trajectory.poses[k].position) + ")";
        return result;
      }
    }
    ++result.samples;
    const double deviation = (state.position - trajectory.poses[k].position).norm();
    const double rotation = Eigen::AngleAxisd(state.rotation * trajectory.poses[k].rotation().transpose()).angle();
    result.max_deviation = std::max(result.max_deviation, deviation);
    result.max_rotation = std::max(result.max_rotation, Eigen::AngleAxisd(state.rotation * start_rotation.transpose()).angle());
    while (next_waypoint < trajectory.waypoint_samples.size() && trajectory.waypoint_samples[next_waypoint] == k) {
      result.max_waypoint_deviation = std::max(result.max_waypoint_deviation, deviation);
      ++next_waypoint;
    }
    const DkpSingularity singularity = dkpSingularity(model, configuration);
    result.min_abs_measure = std::min(result.min_abs_measure, std::abs(singularity.measure));
    if ((singularity.det > 0 ? 1 : -1) != sign || singularity.det == 0.0) {
      result.failed_sample = k;
      result.message = "det J_DKP changes sign at t = " + figure(trajectory.time[k]) + " s, at " +
                       vectorText(trajectory.poses[k].position) + ": the plan crosses a DKP singularity";
      return result;
    }
    const ConstraintMargins limits = constraints.margins(configuration, state.rotation);
    result.min_input_margin = std::min(result.min_input_margin, limits.min_input);
    result.min_cone_margin = std::min(result.min_cone_margin, limits.min_cone);
    result.min_rod_margin = std::min(result.min_rod_margin, limits.min_rod_distance);
    if (std::min({limits.min_input, limits.min_cone, limits.min_rod_distance}) < -tolerance) {
      result.failed_sample = k;
      result.message = "the robot breaks a limit at t = " + figure(trajectory.time[k]) + " s: " +
                       constraints.violationText(configuration, limits);
      return result;
    }
    if (deviation > tolerance || rotation > tolerance) {
      result.failed_sample = k;
      result.message = "the platform leaves the planned path at t = " + figure(trajectory.time[k]) + " s, at " +
                       vectorText(trajectory.poses[k].position) + " (" +
                       figure(deviation) + " m, " + figure(rotation) + " rad from the plan)";
      return result;
    }
  }
  result.passed = true;
  result.message = "DKP continuation over " + std::to_string(result.samples) + " samples: max deviation " +
                   figure(result.max_deviation) + " m (" + figure(result.max_waypoint_deviation) + " m at waypoints), max rotation " +
                   figure(result.max_rotation) + " rad, det J_DKP kept its sign (min |measure| " +
                   figure(result.min_abs_measure) + ")";
  if (constraints.active()) {
    result.message += "; smallest margins to the robot's limits: input " + figure(result.min_input_margin) + ", cone " +
                      figure(result.min_cone_margin) + " rad, rods " + figure(result.min_rod_margin) + " m";
  }
  return result;
}

}  // namespace maximal_workspace
