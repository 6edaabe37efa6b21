#include "maximal_workspace/description/robot_description.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/workspace/grid.h"

namespace maximal_workspace {

namespace {

// Limits for what the robot file leaves unbounded (URDF needs them on prismatic joints).
constexpr double kOpenLimit = 10.0;
// Drawn sizes (m): the base plate (a square under the origin), a slider's block (along its
// rail first), and the largest half-width of any part, which fixedGeometryBox adds all round.
constexpr double kBasePlateSide = 0.1, kBasePlateThickness = 0.02;
const Eigen::Vector3d kSliderBlock(0.08, 0.06, 0.06);
constexpr double kThickestHalfWidth = 0.04;

std::string text(double value) { return exactText(std::abs(value) < 1e-15 ? 0.0 : value); }

std::string triple(const Eigen::Vector3d& v) { return text(v.x()) + " " + text(v.y()) + " " + text(v.z()); }

// URDF's rpy: R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Vector3d rollPitchYaw(const Eigen::Matrix3d& r) {
  const double pitch = std::asin(std::max(-1.0, std::min(1.0, -r(2, 0))));
  if (std::abs(r(2, 0)) > 1.0 - 1e-12) return Eigen::Vector3d(0.0, pitch, std::atan2(-r(0, 1), r(1, 1)));
  return Eigen::Vector3d(std::atan2(r(2, 1), r(2, 2)), pitch, std::atan2(r(1, 0), r(0, 0)));
}

std::string origin(const Eigen::Vector3d& xyz, const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity()) {
  return "<origin xyz=\"" + triple(xyz) + "\" rpy=\"" + triple(rollPitchYaw(rotation)) + "\"/>";
}

// A cylinder of `radius` from `from` to `to` (link frame), as a visual and a collision.
std::string rod(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double radius, const char* material) {
  const Eigen::Vector3d along = to - from;
  const double length = along.norm();
  if (length < 1e-9) return "";
  // URDF cylinders lie along their z: turn z onto the segment.
  const Eigen::Matrix3d turn = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), along).toRotationMatrix();
  const std::string place = origin(0.5 * (from + to), turn);
  const std::string shape = "<geometry><cylinder radius=\"" + text(radius) + "\" length=\"" + text(length) + "\"/></geometry>";
  return "    <visual>" + place + shape + "<material name=\"" + material + "\"/></visual>\n    <collision>" + place + shape +
         "</collision>\n";
}

std::string sphere(const Eigen::Vector3d& at, double radius, const char* material) {
  return "    <visual>" + origin(at) + "<geometry><sphere radius=\"" + text(radius) + "\"/></geometry><material name=\"" +
         material + "\"/></visual>\n";
}

std::string link(const std::string& name, const std::string& body = "") {
  return "  <link name=\"" + name + "\">\n" + body + "  </link>\n";
}

std::string joint(const std::string& name, const std::string& type, const std::string& parent, const std::string& child,
                  const std::string& placement, const std::string& extra = "") {
  return "  <joint name=\"" + name + "\" type=\"" + type + "\">\n    <parent link=\"" + parent + "\"/>\n    <child link=\"" +
         child + "\"/>\n    " + placement + "\n" + extra + "  </joint>\n";
}

// The robot file's name inside an XML comment, which may not hold "--"; printable ASCII
// only, so that no file name can make the document other than ASCII.
std::string commentText(const std::string& text) {
  std::string kept;
  for (const char c : text) {
    const bool safe = c >= 0x20 && c < 0x7f && !(c == '-' && !kept.empty() && kept.back() == '-');
    kept += safe ? c : '_';
  }
  return kept;
}

std::string axis(const Eigen::Vector3d& a) { return "    <axis xyz=\"" + triple(a) + "\"/>\n"; }

std::string limits(double lower, double upper) {
  return "    <limit lower=\"" + text(lower) + "\" upper=\"" + text(upper) + "\" effort=\"100\" velocity=\"1\"/>\n";
}

// The fixed line chain c's actuator is drawn along (base frame): a rail over the slider's
// stroke where the file gives one, else 1 m each way; a crank's axis 5 cm each way.
std::array<Eigen::Vector3d, 2> actuatorSupport(const RobotModel& model, int c) {
  const Chain& chain = *model.chains[c];
  const Eigen::Isometry3d frame = chain.actuatorFrame();
  const bool revolute = chain.inputKind() == InputKind::Revolute;
  const Eigen::Vector3d along = frame.linear().col(revolute ? 2 : 0);
  const auto& stroke = model.inputs[model.chain_input[c]].limits;
  const double first = revolute ? -0.05 : stroke ? (*stroke)[0] : -1.0;
  const double last = revolute ? 0.05 : stroke ? (*stroke)[1] : 1.0;
  return {frame.translation() + first * along, frame.translation() + last * along};
}

// The chain driven with `chain`'s input ahead of it: its actuator joint is the one that
// moves, the others mimic it (robot) or move alone (auxiliary).
int leader(const RobotModel& model, int chain) { return model.inputs[model.chain_input[chain]].chains.front(); }

// The platform's joint variables, in order: translations of the mechanism's DOF, then
// rotations for the auxiliary.
std::vector<OutputVariable> platformVariables(const RobotModel& model, Mechanism mechanism) {
  std::vector<OutputVariable> variables;
  for (OutputVariable v : model.output_variables) {
    if (!isRotational(v) || mechanism == Mechanism::Auxiliary) variables.push_back(v);
  }
  return variables;
}

Eigen::Matrix3d actuatorMotion(const Chain& chain, double q) {
  return chain.inputKind() == InputKind::Revolute ? Eigen::AngleAxisd(q, Eigen::Vector3d::UnitZ()).toRotationMatrix()
                                                   : Eigen::Matrix3d::Identity();
}

// The actuator joint's position for input value q. A crank angle comes from the
// kinematics in (-pi, pi]; where the file's range is written in another turn (one that
// crosses pi, [2.5, 4.0]), the angle of that range's turn is given instead, so a joint
// state within the robot's limits is within the URDF joint's <limit>. Values already
// within the range as written, and those no turn brings into it, are kept as they are.
double actuatorPosition(const Chain& chain, const Input& input, double q) {
  if (chain.inputKind() != InputKind::Revolute || !input.limits) return q;
  const double lower = (*input.limits)[0], upper = (*input.limits)[1];
  if (q >= lower && q <= upper) return q;
  const double turns = std::round((0.5 * (lower + upper) - q) / (2.0 * M_PI));
  const double turned = q + 2.0 * M_PI * turns;
  return turned >= lower && turned <= upper ? turned : q;
}

// Base: a plate at the origin, slider rails and crank axes where the actuators are.
void writeBase(std::ostringstream& out, const RobotModel& model) {
  std::string base = "    <visual>" + origin(Eigen::Vector3d(0, 0, -0.5 * kBasePlateThickness)) + "<geometry><box size=\"" +
                     triple(Eigen::Vector3d(kBasePlateSide, kBasePlateSide, kBasePlateThickness)) +
                     "\"/></geometry><material name=\"base\"/></visual>\n";
  for (int c = 0; c < model.chainCount(); ++c) {
    const std::array<Eigen::Vector3d, 2> support = actuatorSupport(model, c);
    base += rod(support[0], support[1], 0.012, "base");
  }
  out << link(kBaseLink, base);
}

// A chain's actuator joint and link (its parallelogram bar on the leading chain of a
// couple), its spherical joint at a as three revolute joints, and its rod.
void writeChain(std::ostringstream& out, const RobotModel& model, int c, Mechanism mechanism) {
  const Chain& chain = *model.chains[c];
  const Input& input = model.inputs[model.chain_input[c]];
  const Eigen::Isometry3d frame = chain.actuatorFrame();
  const Eigen::Vector3d node = chain.intermediateNodeOnActuator();
  const bool revolute = chain.inputKind() == InputKind::Revolute;
  std::string extra = axis(revolute ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX());
  // Actuator limits are the robot file's: a crank with a range is a revolute joint with
  // that <limit>, one without turns freely (continuous); a slider is prismatic, with the
  // file's stroke or, without one, an open range. A revolute range is an angle interval
  // that may cross +/-pi ([2.5, 4.0]): no lower < upper inside (-pi, pi] expresses it, but
  // URDF takes any pair lower < upper, so it is written as given; jointPositions puts
  // the crank angle in that same turn.
  std::string type = revolute ? "continuous" : "prismatic";
  if (input.limits) {
    type = revolute ? "revolute" : "prismatic";
    extra += limits((*input.limits)[0], (*input.limits)[1]);
  } else if (!revolute) {
    extra += limits(-kOpenLimit, kOpenLimit);
  }
  const int first = leader(model, c);
  if (mechanism == Mechanism::Robot && first != c) {
    extra += "    <mimic joint=\"" + actuatorJointName(*model.chains[first]) + "\" multiplier=\"1\" offset=\"0\"/>\n";
  }
  const std::string actuator_link = chain.name() + (revolute ? "_crank" : "_slider");
  std::string body = rod(Eigen::Vector3d::Zero(), node, 0.015, "actuator");
  if (!revolute) {
    body += "    <visual><geometry><box size=\"" + triple(kSliderBlock) + "\"/></geometry><material name=\"actuator\"/></visual>\n";
  }
  // Robot: the parallelogram's bar on the leading chain's actuator, when it stays put
  // there (sliders; cranks whose centres lie along their common axis).
  if (mechanism == Mechanism::Robot && first == c) {
    for (int other : input.chains) {
      if (other == c) continue;
      const Eigen::Vector3d offset = frame.linear().transpose() *
                                     (model.chains[other]->actuatorFrame().translation() - frame.translation());
      if (!revolute || Eigen::Vector2d(offset.x(), offset.y()).norm() < 1e-9) body += rod(node, node + offset, 0.01, "actuator");
    }
  }
  out << joint(actuatorJointName(chain), type, kBaseLink, actuator_link, origin(frame.translation(), frame.linear()), extra);
  out << link(actuator_link, body);
  // The spherical joint at a as three revolute joints, then the rod along x.
  const std::string z_link = chain.name() + "_ball_z", y_link = chain.name() + "_ball_y";
  out << joint(chain.name() + "_ball_z", "continuous", actuator_link, z_link, origin(node), axis(Eigen::Vector3d::UnitZ()));
  out << link(z_link);
  out << joint(chain.name() + "_ball_y", "continuous", z_link, y_link, origin(Eigen::Vector3d::Zero()), axis(Eigen::Vector3d::UnitY()));
  out << link(y_link);
  out << joint(chain.name() + "_ball_x", "continuous", y_link, rodLinkName(chain), origin(Eigen::Vector3d::Zero()),
               axis(Eigen::Vector3d::UnitX()));
  out << link(rodLinkName(chain), rod(Eigen::Vector3d::Zero(), Eigen::Vector3d(chain.rodLength(), 0, 0), 0.01, "robot"));
}

// The platform: its joints from base_link, then the platform link with its nodes.
void writePlatform(std::ostringstream& out, const RobotModel& model, Mechanism mechanism) {
  std::string parent = kBaseLink;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // translations that are not joints
  for (int k = 0; k < 3; ++k) {
    if (!model.hasOutputVariable(static_cast<OutputVariable>(k))) offset[k] = model.reference.pose.position[k];
  }
  bool rotates = false;
  for (OutputVariable v : platformVariables(model, mechanism)) {
    const std::string name = std::string("platform_") + outputVariableName(v);
    const int index = static_cast<int>(v);
    std::string extra;
    std::string type;
    if (isRotational(v)) {
      rotates = true;
      type = "continuous";
      extra = axis(v == OutputVariable::Theta ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ());
    } else {
      type = "prismatic";
      extra = axis(Eigen::Vector3d::Unit(index));
      const std::array<double, 2> box = safetyBounds(model, model.reference.pose, v);
      extra += limits(std::isfinite(box[0]) ? box[0] : -kOpenLimit, std::isfinite(box[1]) ? box[1] : kOpenLimit);
    }
    out << joint(name, type, parent, name + "_link", origin(offset), extra);
    out << link(name + "_link");
    parent = name + "_link";
    offset.setZero();
  }
  // Without rotational joints the platform keeps the reference orientation.
  const Eigen::Matrix3d fixed = rotates ? Eigen::Matrix3d::Identity() : model.reference.pose.rotation();
  std::string body;
  for (int c = 0; c < model.chainCount(); ++c) {
    const Chain& chain = *model.chains[c];
    body += sphere(chain.platformNode(), 0.02, "robot");
    body += rod(Eigen::Vector3d::Zero(), chain.platformNode(), 0.012, "robot");
    const int first = leader(model, c);
    if (first != c) body += rod(model.chains[first]->platformNode(), chain.platformNode(), 0.012, "robot");
  }
  out << joint("platform_fixed", "fixed", parent, kPlatformLink, origin(offset, fixed));
  out << link(kPlatformLink, body);
}

}  // namespace

std::string actuatorJointName(const Chain& chain) { return chain.name() + "_actuator"; }
std::string rodLinkName(const Chain& chain) { return chain.name() + "_rod"; }

std::string urdfDescription(const RobotModel& model, Mechanism mechanism) {
  std::ostringstream out;
  // XML comments may not hold "--": the command line is described, not quoted.
  out << "<?xml version=\"1.0\"?>\n<!-- Generated by mow urdf from the robot file "
      << commentText(std::filesystem::path(model.source).filename().string())
      << (mechanism == Mechanism::Auxiliary ? " (auxiliary option)" : "")
      << "; do not edit: regenerate.\n     Rods end free at the platform nodes: the joint positions "
         "(robot_pose_publisher) close the loops. -->\n";
  out << "<robot name=\"" << model.name << (mechanism == Mechanism::Auxiliary ? "_auxiliary" : "") << "\">\n";
  out << "  <material name=\"base\"><color rgba=\"0.45 0.45 0.45 1\"/></material>\n"
         "  <material name=\"actuator\"><color rgba=\"0.2 0.25 0.35 1\"/></material>\n"
         "  <material name=\"robot\"><color rgba=\"0.75 1 0 1\"/></material>\n";
  writeBase(out, model);
  for (int c = 0; c < model.chainCount(); ++c) writeChain(out, model, c, mechanism);
  writePlatform(out, model, mechanism);
  out << "</robot>\n";
  return out.str();
}

Eigen::AlignedBox3d fixedGeometryBox(const RobotModel& model, const Eigen::Matrix3d& axes) {
  const Eigen::Matrix3d to_axes = axes.transpose();
  Eigen::AlignedBox3d box;
  const double half_plate = 0.5 * kBasePlateSide;
  for (const double x : {-half_plate, half_plate}) {
    for (const double y : {-half_plate, half_plate}) {
      for (const double z : {-kBasePlateThickness, 0.0}) box.extend(to_axes * Eigen::Vector3d(x, y, z));
    }
  }
  for (int c = 0; c < model.chainCount(); ++c) {
    for (const Eigen::Vector3d& end : actuatorSupport(model, c)) box.extend(to_axes * end);
    const Chain& chain = *model.chains[c];
    if (chain.inputKind() != InputKind::Revolute) continue;  // a slider's block stays on its rail
    // A crank turns its node about the frame's z: a circle of radius r, which spans
    // r sqrt(1 - (d . z)^2) either side of its centre along a unit direction d.
    const Eigen::Isometry3d frame = chain.actuatorFrame();
    const Eigen::Vector3d node = chain.intermediateNodeOnActuator();
    const double radius = std::hypot(node.x(), node.y());
    const Eigen::Vector3d along = to_axes * frame.linear().col(2);
    const Eigen::Vector3d half = (Eigen::Vector3d::Ones() - along.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt() * radius;
    const Eigen::Vector3d centre = to_axes * (frame * Eigen::Vector3d(0.0, 0.0, node.z()));
    box.extend(centre - half);
    box.extend(centre + half);
  }
  return Eigen::AlignedBox3d(box.min() - Eigen::Vector3d::Constant(kThickestHalfWidth),
                             box.max() + Eigen::Vector3d::Constant(kThickestHalfWidth));
}

Eigen::AlignedBox3d drawnRobotBox(const RobotModel& model, const Eigen::AlignedBox3d& tcp_box, const Eigen::Matrix3d& axes) {
  // The platform is drawn as its nodes (spheres) and bars to the TCP: within the farthest
  // node's distance of it at any orientation, along any axes.
  double reach = 0.0;
  for (const ChainPtr& chain : model.chains) reach = std::max(reach, chain->platformNode().norm());
  reach += kThickestHalfWidth;
  Eigen::AlignedBox3d box = fixedGeometryBox(model, axes);
  box.extend(tcp_box.min() - Eigen::Vector3d::Constant(reach));
  box.extend(tcp_box.max() + Eigen::Vector3d::Constant(reach));
  return box;
}

JointPositions jointPositions(const RobotModel& model, Mechanism mechanism, const Configuration& configuration) {
  JointPositions joints;
  auto add = [&joints](const std::string& name, double value) {
    joints.names.push_back(name);
    joints.positions.push_back(value);
  };
  for (int c = 0; c < model.chainCount(); ++c) {
    const Chain& chain = *model.chains[c];
    const double q = configuration.q[c];
    add(actuatorJointName(chain), actuatorPosition(chain, model.inputs[model.chain_input[c]], q));
    // The rod's direction in the actuator link's frame gives the ball's z and y angles.
    const Eigen::Matrix3d parent = chain.actuatorFrame().linear() * actuatorMotion(chain, q);
    const Eigen::Vector3d u = parent.transpose() * (configuration.p[c] - configuration.a[c]).normalized();
    add(chain.name() + "_ball_z", std::atan2(u.y(), u.x()));
    add(chain.name() + "_ball_y", std::atan2(-u.z(), std::hypot(u.x(), u.y())));
    add(chain.name() + "_ball_x", 0.0);
  }
  for (OutputVariable v : platformVariables(model, mechanism)) {
    add(std::string("platform_") + outputVariableName(v), configuration.pose.value(v));
  }
  return joints;
}

}  // namespace maximal_workspace
