// J_DKP (twist and Euler forms) and J_IKP against central finite differences of Eq. 1,
// the relation between the two forms, and the singularity measure's invariances.

#include <cmath>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/robot_file.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

// Random assembled configurations near the reference, in random uncoupled working modes
// (the Jacobians do not care whether couples share a branch).
std::vector<Configuration> randomConfigurations(const RobotModel& model, int count, bool rotate) {
  const std::vector<WorkingMode> modes = uncoupledWorkingModes(model);
  std::vector<Configuration> configurations;
  while (static_cast<int>(configurations.size()) < count) {
    Pose pose = model.reference.pose;
    for (OutputVariable variable : model.output_variables) {
      const double spread = isRotational(variable) ? (rotate ? 0.6 : 0.0) : 0.15;
      pose.setValue(variable, pose.value(variable) + test::uniform(-spread, spread));
    }
    const IkpResult ikp = solveIkp(model, pose);
    if (!ikp.assembled) continue;
    const WorkingMode& mode = modes[std::uniform_int_distribution<std::size_t>(0, modes.size() - 1)(test::rng())];
    configurations.push_back(configurationOf(pose, ikp, mode));
  }
  return configurations;
}

// Half of Eq. 1 for chain i with its intermediate node held where it is (q fixed).
double halfF(const RobotModel& model, const Configuration& configuration, int i, const Eigen::Vector3d& p) {
  const double rod = model.chains[i]->rodLength();
  return 0.5 * ((p - configuration.a[i]).squaredNorm() - rod * rod);
}

Eigen::Vector3d platformNode(const RobotModel& model, const Pose& pose, int i) {
  return pose.position + pose.rotation() * model.chains[i]->platformNode();
}

double relativeError(const DkpJacobian& analytic, const DkpJacobian& numeric) {
  return (analytic - numeric).cwiseAbs().maxCoeff() / analytic.cwiseAbs().maxCoeff();
}

// d f_i / d X_j over the output variables themselves (what the Euler form claims to be).
DkpJacobian eulerByDifferences(const RobotModel& model, const Configuration& configuration) {
  const double h = 1e-6;
  DkpJacobian numeric(configuration.chain_count, model.dof());
  for (int j = 0; j < model.dof(); ++j) {
    Pose plus = configuration.pose, minus = configuration.pose;
    const OutputVariable variable = model.output_variables[j];
    plus.setValue(variable, plus.value(variable) + h);
    minus.setValue(variable, minus.value(variable) - h);
    for (int i = 0; i < configuration.chain_count; ++i) {
      numeric(i, j) = (halfF(model, configuration, i, platformNode(model, plus, i)) -
                       halfF(model, configuration, i, platformNode(model, minus, i))) / (2 * h);
    }
  }
  return numeric;
}

// d f_i along a translation of the platform or a small rotation about a base axis
// through the TCP (what the twist form claims to be).
DkpJacobian twistByDifferences(const RobotModel& model, const Configuration& configuration) {
  const double h = 1e-6;
  const bool spatial = model.hasOutputVariable(OutputVariable::Theta);
  DkpJacobian numeric(configuration.chain_count, model.dof());
  for (int j = 0; j < model.dof(); ++j) {
    const int v = static_cast<int>(model.output_variables[j]);
    for (int i = 0; i < configuration.chain_count; ++i) {
      auto moved = [&](double step) {
        const Eigen::Vector3d r = configuration.p[i] - configuration.pose.position;
        if (v < 3) return Eigen::Vector3d(configuration.p[i] + step * Eigen::Vector3d::Unit(v));
        const Eigen::Vector3d axis = Eigen::Vector3d::Unit(spatial ? v - 3 : 2);
        return Eigen::Vector3d(configuration.pose.position + Eigen::AngleAxisd(step, axis) * r);
      };
      numeric(i, j) = (halfF(model, configuration, i, moved(h)) - halfF(model, configuration, i, moved(-h))) / (2 * h);
    }
  }
  return numeric;
}

TEST(DkpJacobian, TwistFormMatchesFiniteDifferences) {
  for (const RobotModel* model : {&test::deltaLike(), &test::fiveBar()}) {
    for (const Configuration& configuration : randomConfigurations(*model, 200, true)) {
      EXPECT_LT(relativeError(dkpJacobianTwist(*model, configuration), twistByDifferences(*model, configuration)), 1e-6)
          << model->name;
    }
  }
}

TEST(DkpJacobian, EulerFormMatchesFiniteDifferences) {
  for (const RobotModel* model : {&test::deltaLike(), &test::fiveBar()}) {
    for (const Configuration& configuration : randomConfigurations(*model, 200, true)) {
      EXPECT_LT(relativeError(dkpJacobianEuler(*model, configuration), eulerByDifferences(*model, configuration)), 1e-6)
          << model->name;
    }
  }
}

TEST(DkpJacobian, EulerFormIsTwistFormTimesEulerRates) {
  for (const Configuration& configuration : randomConfigurations(test::deltaLike(), 200, true)) {
    const double phi = configuration.pose.euler_zyz[0], theta = configuration.pose.euler_zyz[1];
    DkpJacobian rates = DkpJacobian::Identity(6, 6);
    rates.bottomRightCorner(3, 3) = eulerRateMatrix(phi, theta);
    const DkpJacobian twist = dkpJacobianTwist(test::deltaLike(), configuration);
    const DkpJacobian euler = dkpJacobianEuler(test::deltaLike(), configuration);
    EXPECT_LT(relativeError(euler, twist * rates), 1e-12);
    // det E = -sin(theta): the two forms share their singularities wherever theta != 0.
    EXPECT_NEAR(euler.determinant(), -std::sin(theta) * twist.determinant(), 1e-12 * std::abs(twist.determinant()));
  }
}

TEST(DkpJacobian, EulerRateMatrixDeterminantIsMinusSinTheta) {
  for (int k = 0; k < 100; ++k) {
    const double phi = test::uniform(-M_PI, M_PI), theta = test::uniform(-M_PI, M_PI);
    EXPECT_NEAR(eulerRateMatrix(phi, theta).determinant(), -std::sin(theta), 1e-14);
  }
}

TEST(DkpJacobian, EulerFormIsSingularAtThetaZeroWhereTheTwistFormIsNot) {
  for (const Configuration& configuration : randomConfigurations(test::deltaLike(), 100, false)) {
    ASSERT_EQ(configuration.pose.euler_zyz[1], 0.0);
    const DkpJacobian euler = dkpJacobianEuler(test::deltaLike(), configuration);
    // At theta = 0 phi and psi are both rotations about z: two equal columns.
    EXPECT_LT((euler.col(3) - euler.col(5)).norm(), 1e-15 * euler.norm());
    EXPECT_NEAR(euler.determinant(), 0.0, 1e-12 * std::pow(euler.norm(), 6));
  }
  // The twist form classifies the same configurations: at the reference pose no working
  // mode is singular (the file's robot is assembled there and moves).
  const IkpResult ikp = solveIkp(test::deltaLike(), test::deltaLike().reference.pose);
  for (const WorkingMode& mode : coupledWorkingModes(test::deltaLike())) {
    EXPECT_NE(dkpJacobianTwist(test::deltaLike(), configurationOf(test::deltaLike().reference.pose, ikp, mode)).determinant(), 0.0);
  }
}

TEST(IkpJacobian, MatchesFiniteDifferencesOfEquationOne) {
  const double h = 1e-6;
  for (const RobotModel* model : {&test::deltaLike(), &test::fiveBar()}) {
    for (const Configuration& configuration : randomConfigurations(*model, 200, true)) {
      const IkpJacobian analytic = ikpJacobian(*model, configuration);
      for (int i = 0; i < configuration.chain_count; ++i) {
        const Chain& chain = *model->chains[i];
        auto half_f = [&](double q) {
          return 0.5 * ((configuration.p[i] - chain.intermediateNode(q)).squaredNorm() - chain.rodLength() * chain.rodLength());
        };
        const double numeric = (half_f(configuration.q[i] + h) - half_f(configuration.q[i] - h)) / (2 * h);
        EXPECT_NEAR(analytic[i], numeric, 1e-6 * std::max(1e-3, std::abs(analytic[i])));
      }
    }
  }
}

TEST(SingularityMeasure, IsScaleFreeBoundedAndSignedLikeTheDeterminant) {
  const double scale = 1000.0;
  const RobotModel& model = test::deltaLike();
  const RobotModel model_mm = test::scaled(model, scale);
  const std::vector<WorkingMode> modes = coupledWorkingModes(model);
  for (const Configuration& configuration : randomConfigurations(model, 200, true)) {
    for (const WorkingMode& mode : modes) {
      const IkpResult ikp = solveIkp(model, configuration.pose);
      const DkpSingularity metres = dkpSingularity(model, configurationOf(configuration.pose, ikp, mode));
      Pose pose_mm = configuration.pose;
      pose_mm.position *= scale;
      const IkpResult ikp_mm = solveIkp(model_mm, pose_mm);
      ASSERT_TRUE(ikp_mm.assembled);
      const DkpSingularity millimetres = dkpSingularity(model_mm, configurationOf(pose_mm, ikp_mm, mode));
      // Three translational columns scale with the length, three rotational with its square.
      EXPECT_NEAR(millimetres.det, std::pow(scale, 9) * metres.det, 1e-9 * std::pow(scale, 9) * std::abs(metres.det) + 1e-300);
      EXPECT_NEAR(millimetres.measure, metres.measure, 1e-9);
      // Hadamard's inequality bounds the ratio; the sign is the determinant's.
      EXPECT_LE(std::abs(metres.measure), 1.0);
      EXPECT_EQ(metres.measure > 0, metres.det > 0);
    }
  }
}

TEST(SingularityMeasure, FiveBarMeasureIsTheSineBetweenTheDistalLinks) {
  const RobotModel& model = test::fiveBar();
  for (const Configuration& configuration : randomConfigurations(model, 200, false)) {
    const Eigen::Vector3d left = configuration.p[0] - configuration.a[0];
    const Eigen::Vector3d right = configuration.p[1] - configuration.a[1];
    // A 2 x 2 determinant of unit rows is the sine of the angle from the first to the second.
    const double sine = left.normalized().cross(right.normalized()).z();
    EXPECT_NEAR(dkpSingularity(model, configuration).measure, sine, 1e-12);
  }
}

}  // namespace
}  // namespace maximal_workspace
