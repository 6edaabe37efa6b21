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
  // Sets the ZYZ angles of `rotation` (orthonormal), theta in [0, pi]. Where theta is 0
  // or pi only phi + psi (or phi - psi) is defined: phi keeps its value then, so the
  // reference orientation given as a rotation comes back as the reference's angles. Exact
  // to rounding, except within 1e-9 rad of theta = 0 or pi, where it is within 1e-9 rad.
  void setRotation(const Eigen::Matrix3d& rotation);
  // Base-frame position of a point given in platform coordinates (Eq. 2).
  Eigen::Vector3d toBase(const Eigen::Vector3d& platform_point) const;
};

// The poses whose position lies within `position_half_width` of the centre's and whose ZYZ
// angles lie within `angle_half_width` of its angles, coordinate by coordinate: a grid
// cell, or a block of cells.
struct PoseBox {
  Pose centre;
  Eigen::Vector3d position_half_width = Eigen::Vector3d::Zero();
  Eigen::Vector3d angle_half_width = Eigen::Vector3d::Zero();
  // How far phi + psi moves, where phi and psi move together (a tilt-and-torsion grid:
  // psi = s - a, so phi + psi moves with the torsion alone). Unset: the two half widths'
  // sum.
  std::optional<double> angle_sum_half_width;
};

}  // namespace maximal_workspace
