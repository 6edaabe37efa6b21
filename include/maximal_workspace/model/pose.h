#pragma once
// Platform pose: TCP position (m) and ZYZ Euler angles (rad), the chapter's Eq. 2.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace maximal_workspace {

// The six output variables of a platform, in the chapter's order.
enum class OutputVariable { X = 0, Y, Z, Phi, Theta, Psi };
constexpr int kOutputVariableCount = 6;

const char* outputVariableName(OutputVariable variable);
std::optional<OutputVariable> parseOutputVariable(const std::string& name);
bool isRotational(OutputVariable variable);

struct Pose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  // phi, theta, psi: R = Rz(phi) Ry(theta) Rz(psi).
  Eigen::Vector3d euler_zyz = Eigen::Vector3d::Zero();

  double value(OutputVariable variable) const;
  void setValue(OutputVariable variable, double value);
  Eigen::Matrix3d rotation() const;
  // Base-frame position of a point given in platform coordinates (Eq. 2).
  Eigen::Vector3d toBase(const Eigen::Vector3d& platform_point) const;
};

}  // namespace maximal_workspace
