#include "maximal_workspace/kinematics/constraints.h"

#include <algorithm>
#include <cmath>

#include "kinematics/segment_distance.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

// The angle between two vectors, by atan2 (accurate near 0 and pi, unlike acos).
double angleBetween(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

// Margins where no limit is set yet: +infinity everywhere.
ConstraintMargins unlimited() {
  ConstraintMargins result;
  result.input.fill(INFINITY);
  result.fixed_cone.fill(INFINITY);
  result.platform_cone.fill(INFINITY);
  result.rod_distance.fill(INFINITY);
  return result;
}

}  // namespace

const char* constraintKindName(ConstraintKind kind) {
  switch (kind) {
    case ConstraintKind::InputRange: return "actuator limit";
    case ConstraintKind::JointCone: return "joint cone";
    case ConstraintKind::Interference: return "interference";
    case ConstraintKind::None: break;
  }
  return "none";
}

RobotConstraints::RobotConstraints(const RobotModel& model) : model_(model) {
  for (const Input& input : model.inputs) active_ = active_ || input.limits.has_value();
  for (const ChainPtr& chain : model.chains) {
    const ChainLimits& limits = chain->limits();
    active_ = active_ || limits.fixed_end || limits.platform_end;
  }
  for (int c = 0; c < model.chainCount(); ++c) {
    for (int d = c + 1; d < model.chainCount(); ++d) rods_checked_ = rods_checked_ || checksPair(c, d);
  }
  active_ = active_ || rods_checked_;
}

double RobotConstraints::pairDistance(int c, int d) const {
  const double radii = model_.chains[c]->limits().rod_radius + model_.chains[d]->limits().rod_radius;
  return radii > 0.0 ? radii + model_.rod_clearance : 0.0;
}

ConstraintMargins RobotConstraints::margins(const Configuration& configuration) const {
  return margins(configuration, configuration.pose.rotation());
}

ConstraintMargins RobotConstraints::margins(const Configuration& configuration, const Eigen::Matrix3d& rotation) const {
  ConstraintMargins result = unlimited();
  for (int c = 0; c < model_.chainCount(); ++c) chainMargins(configuration, rotation, c, result);
  settleChains(result);
  for (int c = 0; c < model_.chainCount(); ++c) {
    for (int d = c + 1; d < model_.chainCount(); ++d) {
      if (!checksPair(c, d)) continue;
      const double distance =
          std::sqrt(segmentDistanceSquared(configuration.a[c], configuration.p[c], configuration.a[d], configuration.p[d]));
      const double margin = distance - pairDistance(c, d);
      result.rod_distance[c] = std::min(result.rod_distance[c], margin);
      result.rod_distance[d] = std::min(result.rod_distance[d], margin);
      result.min_rod_distance = std::min(result.min_rod_distance, margin);
      // The rods come last: the first broken limit of all, when none of the chains' is.
      if (margin < 0.0 && result.violated == ConstraintKind::None) {
        result.violated = ConstraintKind::Interference;
        result.chain = c, result.other_chain = d, result.violation = margin;
      }
    }
  }
  return result;
}

// Chain c's own limits, which depend on its branch alone: its input's range and its cones.
void RobotConstraints::chainMargins(const Configuration& configuration, const Eigen::Matrix3d& rotation, int c,
                                    ConstraintMargins& result) const {
  const Chain& chain = *model_.chains[c];
  const auto& range = model_.inputs[model_.chain_input[c]].limits;
  result.input[c] = range ? chain.inputMargin(configuration.q[c], *range) : INFINITY;
  const Eigen::Vector3d& a = configuration.a[c];
  const Eigen::Vector3d& p = configuration.p[c];
  result.fixed_cone[c] = INFINITY, result.platform_cone[c] = INFINITY;
  if (const auto& cone = chain.limits().fixed_end) {
    const NodeAxisMap axis = chain.fixedEndAxis(cone->axis);
    result.fixed_cone[c] = cone->half_angle - angleBetween(p - a, axis.linear * a + axis.offset);
  }
  if (const auto& cone = chain.limits().platform_end) {
    result.platform_cone[c] = cone->half_angle - angleBetween(a - p, rotation * cone->axis);
  }
}

// The smallest of the chains' margins (chainMargins), and the first of their limits
// broken: inputs in chain order, then cones.
void RobotConstraints::settleChains(ConstraintMargins& result) const {
  for (int c = 0; c < model_.chainCount(); ++c) {
    result.min_input = std::min(result.min_input, result.input[c]);
    result.min_cone = std::min({result.min_cone, result.fixed_cone[c], result.platform_cone[c]});
  }
  for (int c = 0; c < model_.chainCount() && result.violated == ConstraintKind::None; ++c) {
    if (result.input[c] < 0.0) result.violated = ConstraintKind::InputRange, result.chain = c, result.violation = result.input[c];
  }
  for (int c = 0; c < model_.chainCount() && result.violated == ConstraintKind::None; ++c) {
    const double cone = std::min(result.fixed_cone[c], result.platform_cone[c]);
    if (cone >= 0.0) continue;
    result.violated = ConstraintKind::JointCone, result.chain = c, result.violation = cone;
    result.violated_fixed_end = result.fixed_cone[c] < 0.0;
  }
}

void RobotConstraints::walls(const Pose& pose, const IkpResult& ikp, const std::vector<WorkingMode>& modes,
                             std::uint64_t wanted, WallLimit* walls) const {
  if (rods_checked_) {
    for (std::size_t m = 0; m < modes.size(); ++m) {
      if (wanted >> m & 1u) walls[m] = wallLimit(margins(pose, ikp, modes[m]));
    }
    return;
  }
  // Every chain in branch p, then every chain in branch n: a mode's margins are each
  // chain's in its branch.
  const Eigen::Matrix3d rotation = pose.rotation();
  ConstraintMargins by_branch[2] = {unlimited(), unlimited()};
  for (int b = 0; b < 2; ++b) {
    const Configuration configuration = configurationOf(pose, ikp, WorkingMode{"", b == 0 ? 0u : ~0u});
    for (int c = 0; c < model_.chainCount(); ++c) chainMargins(configuration, rotation, c, by_branch[b]);
  }
  for (std::size_t m = 0; m < modes.size(); ++m) {
    if ((wanted >> m & 1u) == 0) continue;
    ConstraintMargins mode_margins = unlimited();
    for (int c = 0; c < model_.chainCount(); ++c) {
      const ConstraintMargins& own = by_branch[modes[m].branch(c) == Branch::Negative ? 1 : 0];
      mode_margins.input[c] = own.input[c];
      mode_margins.fixed_cone[c] = own.fixed_cone[c], mode_margins.platform_cone[c] = own.platform_cone[c];
    }
    settleChains(mode_margins);
    walls[m] = wallLimit(mode_margins);
  }
}

WallLimit wallLimit(const ConstraintMargins& margins) {
  if (!margins.satisfied()) return WallLimit{margins.violated, margins.chain};
  WallLimit wall;
  double smallest = INFINITY;
  for (std::size_t c = 0; c < margins.input.size(); ++c) {
    const std::pair<ConstraintKind, double> candidates[] = {
        {ConstraintKind::InputRange, margins.input[c]},
        {ConstraintKind::JointCone, std::min(margins.fixed_cone[c], margins.platform_cone[c])},
        {ConstraintKind::Interference, margins.rod_distance[c]}};
    for (const auto& [kind, margin] : candidates) {
      if (margin < smallest) smallest = margin, wall = WallLimit{kind, static_cast<int>(c)};
    }
  }
  return wall;
}

ConstraintMargins RobotConstraints::margins(const Pose& pose, const IkpResult& ikp, const WorkingMode& mode) const {
  return margins(configurationOf(pose, ikp, mode));
}

std::string RobotConstraints::violationText(const Pose& pose, const IkpResult& ikp, const WorkingMode& mode) const {
  const Configuration configuration = configurationOf(pose, ikp, mode);
  return violationText(configuration, margins(configuration));
}

std::string RobotConstraints::violationText(const Configuration& configuration, const ConstraintMargins& margins) const {
  if (margins.satisfied()) return {};
  const Chain& chain = *model_.chains[margins.chain];
  const std::string name = "chain '" + chain.name() + "'";
  switch (margins.violated) {
    case ConstraintKind::InputRange: {
      const Input& input = model_.inputs[model_.chain_input[margins.chain]];
      const std::string unit = std::string(" ") + inputUnit(input.kind);
      return name + ": input " + input.name + " = " + numberText(configuration.q[margins.chain]) + unit +
             " is outside its limits [" + numberText((*input.limits)[0]) + ", " + numberText((*input.limits)[1]) + "]";
    }
    case ConstraintKind::JointCone: {
      const bool fixed_end = margins.violated_fixed_end;
      const JointCone& cone = fixed_end ? *chain.limits().fixed_end : *chain.limits().platform_end;
      return name + ": the rod leaves its " + (fixed_end ? "fixed_end" : "platform_end") + " cone (angle " +
             numberText(cone.half_angle - margins.violation) + " rad > half_angle " + numberText(cone.half_angle) + ")";
    }
    case ConstraintKind::Interference: {
      const Chain& other = *model_.chains[margins.other_chain];
      const double distance = margins.violation + pairDistance(margins.chain, margins.other_chain);
      return "the rods of chains '" + chain.name() + "' and '" + other.name() + "' interfere (axes " +
             numberText(distance) + " m apart, under " + numberText(pairDistance(margins.chain, margins.other_chain)) +
             " m)";
    }
    case ConstraintKind::None: break;
  }
  return {};
}

}  // namespace maximal_workspace
