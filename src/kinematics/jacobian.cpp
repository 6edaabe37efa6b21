#include "maximal_workspace/kinematics/jacobian.h"

#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/LU>

namespace maximal_workspace {

Eigen::Matrix3d eulerRateMatrix(double phi, double theta) {
  Eigen::Matrix3d rates;
  rates.col(0) = Eigen::Vector3d::UnitZ();
  rates.col(1) = Eigen::Vector3d(-std::sin(phi), std::cos(phi), 0.0);
  rates.col(2) = Eigen::Vector3d(std::cos(phi) * std::sin(theta), std::sin(phi) * std::sin(theta), std::cos(theta));
  return rates;
}

// A rotational column takes all three angular components (wx wy wz) for a spatial
// platform, wz alone for a planar one (output_variables are in canonical order, so phi
// comes first).
int twistComponent(const RobotModel& model, int column) {
  const OutputVariable variable = model.output_variables[column];
  if (!isRotational(variable)) return static_cast<int>(variable);
  return model.hasOutputVariable(OutputVariable::Theta) ? static_cast<int>(variable) : 5;
}

DkpRow dkpTwistRow(const RobotModel& model, const Eigen::Vector3d& g, const Eigen::Vector3d& r) {
  Eigen::Matrix<double, 6, 1> twist;
  twist << g, r.cross(g);
  DkpRow row(model.dof());
  for (int j = 0; j < model.dof(); ++j) row[j] = twist[twistComponent(model, j)];
  return row;
}

DkpJacobian dkpJacobianTwist(const RobotModel& model, const Configuration& configuration) {
  DkpJacobian jacobian(configuration.chain_count, model.dof());
  for (int i = 0; i < configuration.chain_count; ++i) {
    jacobian.row(i) = dkpTwistRow(model, configuration.p[i] - configuration.a[i],
                                  configuration.p[i] - configuration.pose.position);
  }
  return jacobian;
}

DkpJacobian dkpJacobianEuler(const RobotModel& model, const Configuration& configuration) {
  const int n = model.dof();
  const Eigen::Vector3d& euler = configuration.pose.euler_zyz;
  const Eigen::Matrix3d rates = eulerRateMatrix(euler[0], euler[1]);
  DkpJacobian jacobian(configuration.chain_count, n);
  for (int i = 0; i < configuration.chain_count; ++i) {
    const Eigen::Vector3d g = configuration.p[i] - configuration.a[i];
    const Eigen::Vector3d r = configuration.p[i] - configuration.pose.position;
    for (int j = 0; j < n; ++j) {
      const int v = static_cast<int>(model.output_variables[j]);
      // d p_i / d(angle) = (angular velocity per unit rate) x (p_i - TCP): Eqs. 14-22.
      jacobian(i, j) = v < 3 ? g[v] : g.dot(rates.col(v - 3).cross(r));
    }
  }
  return jacobian;
}

IkpJacobian ikpJacobian(const RobotModel& model, const Configuration& configuration) {
  IkpJacobian diagonal(configuration.chain_count);
  for (int i = 0; i < configuration.chain_count; ++i) {
    const Eigen::Vector3d g = configuration.p[i] - configuration.a[i];
    diagonal[i] = -g.dot(model.chains[i]->intermediateNodeRate(configuration.q[i]));
  }
  return diagonal;
}

DkpSingularity dkpSingularity(const RobotModel& model, const Configuration& configuration) {
  return dkpSingularity(model, dkpJacobianTwist(model, configuration));
}

DkpSingularity dkpSingularity(const RobotModel& model, DkpJacobian jacobian) {
  DkpSingularity result;
  result.det = jacobian.partialPivLu().determinant();
  int rotational_columns = 0;
  for (int j = 0; j < jacobian.cols(); ++j) {
    if (!isRotational(model.output_variables[j])) continue;
    jacobian.col(j) /= model.characteristic_length;
    ++rotational_columns;
  }
  const double scaled_det = result.det / std::pow(model.characteristic_length, rotational_columns);
  double row_norms = 1.0;
  for (int i = 0; i < jacobian.rows(); ++i) row_norms *= jacobian.row(i).norm();
  result.measure = row_norms > 0.0 ? scaled_det / row_norms : 0.0;
  return result;
}

}  // namespace maximal_workspace
