#pragma once
// Grids over positions and a tilt-and-torsion orientation set, for the orientation tests.

#include <array>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "maximal_workspace/workspace/grid.h"

namespace maximal_workspace::test {

inline Eigen::Matrix3d tiltTorsionRotation(const Eigen::Matrix3d& reference, double a, double t, double s) {
  using Eigen::AngleAxisd;
  using Eigen::Vector3d;
  return reference * (AngleAxisd(a, Vector3d::UnitZ()) * AngleAxisd(t, Vector3d::UnitY()) *
                      AngleAxisd(s - a, Vector3d::UnitZ())).toRotationMatrix();
}

inline GridSpec orientationGrid(const RobotModel& model, double step, std::vector<std::array<double, 2>> positions,
                         const OrientationSet& set) {
  GridSpec spec;
  spec.variables = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
  spec.steps = {step};
  spec.start = model.reference.pose;
  spec.bounds = std::move(positions);
  addOrientationSet(model, set, &spec);
  return spec;
}

}  // namespace maximal_workspace::test
