#pragma once
// Velocity problem (chapter section 4): J_DKP Xdot = -J_IKP qdot, from Eq. 1 with the
// common factor 2 dropped on both sides.
//
// Twist form (used to classify): row i = [g_i^T, ((p_i - TCP) x g_i)^T] with
// g_i = p_i - a_i, columns restricted to the mechanism's DOF (vx vy vz for X Y Z; wx wy wz
// when all of phi theta psi are DOF; wz alone for a planar mechanism with phi).
// Euler form (the chapter's Eqs. 4-22, cross-check only): columns d f_i / d X_j over the
// output variables themselves; equals twist form x blockdiag(I, E(phi, theta)) and is
// singular at theta = 0 whatever the robot, which is why it does not classify.

#include <Eigen/Core>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

using DkpJacobian =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxChains, kMaxChains>;
using IkpJacobian = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxChains, 1>;
using DkpRow = Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, kMaxChains>;

// Which twist component column j of the twist form holds: 0-2 for vx vy vz (g), 3-5 for
// wx wy wz ((p - TCP) x g).
int twistComponent(const RobotModel& model, int column);
// One twist-form row: g = p - a (rod), r = p - TCP (platform node from the TCP).
DkpRow dkpTwistRow(const RobotModel& model, const Eigen::Vector3d& g, const Eigen::Vector3d& r);

DkpJacobian dkpJacobianTwist(const RobotModel& model, const Configuration& configuration);
DkpJacobian dkpJacobianEuler(const RobotModel& model, const Configuration& configuration);
// Diagonal of J_IKP: -g_i . da_i/dq_i; zero exactly on the chain's IKP singularity.
IkpJacobian ikpJacobian(const RobotModel& model, const Configuration& configuration);
// Columns: angular velocity per unit rate of phi, theta, psi (ZYZ). det E = -sin(theta).
Eigen::Matrix3d eulerRateMatrix(double phi, double theta);

// det J_DKP (twist form) and its scale-free companion (docs/kinematics.md):
// the Hadamard ratio det / prod(row norms) of the twist form whose rotational columns are
// divided by the robot's characteristic length. In [-1, 1], same sign as det, 0 on a DKP
// singularity, +/-1 when the rows are orthogonal; unchanged by the choice of units, by
// scaling the whole robot, and by the rod lengths (row scaling).
struct DkpSingularity {
  double det = 0.0;
  double measure = 0.0;
};

DkpSingularity dkpSingularity(const RobotModel& model, const Configuration& configuration);
// The same from a twist-form J_DKP already built.
DkpSingularity dkpSingularity(const RobotModel& model, DkpJacobian twist);

}  // namespace maximal_workspace
