#include "maximal_workspace/model/pose.h"

#include <cmath>

namespace maximal_workspace {

namespace {
constexpr const char* kNames[kOutputVariableCount] = {"x", "y", "z", "phi", "theta", "psi"};
}

const char* outputVariableName(OutputVariable variable) { return kNames[static_cast<int>(variable)]; }

std::optional<OutputVariable> parseOutputVariable(const std::string& name) {
  for (int i = 0; i < kOutputVariableCount; ++i) {
    if (name == kNames[i]) return static_cast<OutputVariable>(i);
  }
  return std::nullopt;
}

bool isRotational(OutputVariable variable) { return static_cast<int>(variable) >= 3; }

double Pose::value(OutputVariable variable) const {
  const int i = static_cast<int>(variable);
  return i < 3 ? position[i] : euler_zyz[i - 3];
}

void Pose::setValue(OutputVariable variable, double value) {
  const int i = static_cast<int>(variable);
  (i < 3 ? position[i] : euler_zyz[i - 3]) = value;
}

Eigen::Matrix3d Pose::rotation() const {
  const double cf = std::cos(euler_zyz[0]), sf = std::sin(euler_zyz[0]);
  const double ct = std::cos(euler_zyz[1]), st = std::sin(euler_zyz[1]);
  const double cp = std::cos(euler_zyz[2]), sp = std::sin(euler_zyz[2]);
  Eigen::Matrix3d rz_phi, ry_theta, rz_psi;
  rz_phi << cf, -sf, 0, sf, cf, 0, 0, 0, 1;
  ry_theta << ct, 0, st, 0, 1, 0, -st, 0, ct;
  rz_psi << cp, -sp, 0, sp, cp, 0, 0, 0, 1;
  return rz_phi * ry_theta * rz_psi;
}

void Pose::setRotation(const Eigen::Matrix3d& r) {
  // phi is the angle that zeroes entry (1, 2) of Rz(-phi) r = Ry(theta) Rz(psi); theta and
  // psi are then read from that product, so the three reproduce r also where phi is kept.
  constexpr double kDegenerate = 1e-9;  // sin(theta) under which phi is kept
  if (std::hypot(r(0, 2), r(1, 2)) >= kDegenerate) euler_zyz[0] = std::atan2(r(1, 2), r(0, 2));
  const double c = std::cos(euler_zyz[0]), s = std::sin(euler_zyz[0]);
  const Eigen::Vector3d row0 = (c * r.row(0) + s * r.row(1)).transpose();  // of Rz(-phi) r
  const Eigen::Vector3d row1 = (-s * r.row(0) + c * r.row(1)).transpose();
  euler_zyz[1] = std::atan2(row0.z(), r(2, 2));
  euler_zyz[2] = std::atan2(row1.x(), row1.y());
}

Eigen::Vector3d Pose::toBase(const Eigen::Vector3d& platform_point) const {
  if (euler_zyz.isZero(0.0)) return position + platform_point;  // translational robots
  return position + rotation() * platform_point;
}

}  // namespace maximal_workspace
