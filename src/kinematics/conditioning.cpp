#include "maximal_workspace/kinematics/conditioning.h"

#include <Eigen/SVD>

namespace maximal_workspace {

DkpJacobian scaledInputOutputJacobian(const RobotModel& model, const Configuration& configuration) {
  DkpJacobian jacobian = dkpJacobianTwist(model, configuration);
  const IkpJacobian ikp = ikpJacobian(model, configuration);
  for (int i = 0; i < jacobian.rows(); ++i) {
    const double node_speed = model.chains[i]->intermediateNodeRate(configuration.q[i]).norm();
    jacobian.row(i) *= node_speed / ikp[i];
  }
  for (int j = 0; j < jacobian.cols(); ++j) {
    if (isRotational(model.output_variables[j])) jacobian.col(j) /= model.characteristic_length;
  }
  return jacobian;
}

double conditioningIndex(const RobotModel& model, const Configuration& configuration) {
  const DkpJacobian jacobian = scaledInputOutputJacobian(model, configuration);
  // A chain on its IKP singularity: its input's rate is unbounded (its row inf or nan).
  if (!jacobian.allFinite()) return 0.0;
  const Eigen::JacobiSVD<DkpJacobian> svd(jacobian);  // singular values only, decreasing
  const auto& sigma = svd.singularValues();
  return sigma[sigma.size() - 1] / sigma[0];
}

}  // namespace maximal_workspace
