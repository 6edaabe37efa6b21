// queryPose (regions/pose_query.h) against independent checks: the reference pose is in the
// start's region; det J_DKP's sign against a Jacobian of finite differences of the chains'
// equations; the nearest point of a maximal workspace against every cell of the grid, on
// the delta-like robot's x y z grid and on a periodic grid over an angle; and the request
// poses' quaternions against the ZYZ angles they were made from.

#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/planner/path_request.h"
#include "maximal_workspace/regions/pose_query.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

constexpr double kStep = 0.02;

const WorkspaceAnalysis& deltaAnalysis() {
  static const WorkspaceAnalysis analysis =
      analyseWorkspace(test::deltaLike(), test::referenceGrid(test::deltaLike(), kStep), AnalysisOptions{});
  return analysis;
}

Pose at(const Eigen::Vector3d& position) {
  Pose pose = test::deltaLike().reference.pose;
  pose.position = position;
  return pose;
}

int signOf(double value) { return (value > 0) - (value < 0); }

// Every cell of the grid: none of the maximal workspace of `sign` is nearer than the one
// found, and among as near ones it has the smallest index.
void expectNearestByBruteForce(const RobotModel& model, const WorkspaceAnalysis& analysis, const Pose& pose) {
  const PoseQuery query = queryPose(model, analysis, pose);
  const Grid& grid = analysis.grid();
  for (const AssemblyModeAtPose& at : query.assembly_modes) {
    SCOPED_TRACE(testing::Message() << "assembly mode " << int(at.sign) << ", pose " << pose.position.transpose() << " / "
                                    << pose.euler_zyz.transpose());
    ASSERT_TRUE(at.has_nearest);
    double nearest = INFINITY;
    std::uint64_t nearest_cell = 0;
    for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
      if (!analysis.inMaximalWorkspace(cell, at.sign)) continue;
      const double distance = gridDistance(model, grid, pose, grid.pose(cell));
      if (distance < nearest) {
        nearest = distance;
        nearest_cell = cell;
      }
    }
    if (at.in_maximal) {
      EXPECT_EQ(at.distance, 0.0);
      EXPECT_TRUE(analysis.inMaximalWorkspace(query.cell, at.sign));
      continue;
    }
    EXPECT_EQ(at.distance, nearest);
    EXPECT_EQ(at.nearest_cell, nearest_cell);
    EXPECT_TRUE(analysis.inMaximalWorkspace(at.nearest_cell, at.sign));
    EXPECT_EQ(at.nearest.position, grid.pose(at.nearest_cell).position);
  }
}

TEST(PoseQuery, TheReferencePoseIsInTheStartRegion) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis& analysis = deltaAnalysis();
  const PoseQuery query = queryPose(model, analysis, model.reference.pose);
  ASSERT_TRUE(query.kinematics.ikp.assembled);
  ASSERT_TRUE(query.on_grid);
  EXPECT_TRUE(query.in_workspace);
  std::uint64_t start_cell = 0;
  ASSERT_TRUE(analysis.grid().cellOf(model.reference.pose, &start_cell));
  EXPECT_EQ(query.cell, start_cell);
  // The reference configuration is npn, det J_DKP > 0 there (mow info): assembly mode +.
  const int start = analysis.startMode();
  EXPECT_EQ(analysis.modes()[start].name, "npn");
  EXPECT_GT(query.kinematics.modes[start].singularity.det, 0.0);
  const AssemblyModeAtPose& positive = query.assembly_modes[0];
  ASSERT_EQ(positive.sign, 1);
  EXPECT_EQ(query.regions[start], analysis.assemblyModes()[0].traditional_region);
  EXPECT_TRUE(positive.in_maximal);
  EXPECT_TRUE(positive.reachable);
  EXPECT_NE(std::find(positive.modes.begin(), positive.modes.end(), start), positive.modes.end());
  EXPECT_EQ(positive.distance, 0.0);
  EXPECT_EQ(positive.nearest.position, model.reference.pose.position);
  // Regions listed per assembly mode are those of the cell with that sign, not debris.
  for (const AssemblyModeAtPose& am : query.assembly_modes) {
    ASSERT_EQ(am.modes.size(), am.regions.size());
    for (std::size_t k = 0; k < am.modes.size(); ++k) {
      EXPECT_EQ(am.regions[k], query.regions[am.modes[k]]);
      EXPECT_EQ(analysis.regions()[am.regions[k]].sign, am.sign);
      EXPECT_FALSE(analysis.regions()[am.regions[k]].debris);
    }
  }
}

// J_DKP by central differences of f_i = |p_i - a_i(q_i)|^2 - R_i^2 over a translation and a
// rotation of the platform about the TCP (base-frame axes), the inputs held: 2 x the twist
// form, so its determinant has det J_DKP's sign for six chains.
Eigen::MatrixXd finiteDifferenceJacobian(const RobotModel& model, const Pose& pose, const WorkingModeAnalysis& mode) {
  const int n = model.chainCount();
  const auto constraints = [&](const Eigen::Vector3d& shift, const Eigen::Vector3d& turn) {
    Eigen::VectorXd f(n);
    const Eigen::Matrix3d rotation =
        (turn.norm() > 0 ? Eigen::AngleAxisd(turn.norm(), turn.normalized()).toRotationMatrix() : Eigen::Matrix3d::Identity()) *
        pose.rotation();
    for (int c = 0; c < n; ++c) {
      const Chain& chain = *model.chains[c];
      const Eigen::Vector3d p = pose.position + shift + rotation * chain.platformNode();
      f[c] = (p - chain.intermediateNode(mode.q[c])).squaredNorm() - chain.rodLength() * chain.rodLength();
    }
    return f;
  };
  constexpr double h = 1e-6;
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  Eigen::MatrixXd jacobian(n, 6);
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(j);
    jacobian.col(j) = (constraints(step, none) - constraints(-step, none)) / (2 * h);
    jacobian.col(3 + j) = (constraints(none, step) - constraints(none, -step)) / (2 * h);
  }
  return jacobian;
}

TEST(PoseQuery, DetSignsAgreeWithFiniteDifferences) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis& analysis = deltaAnalysis();
  ASSERT_EQ(model.chainCount(), 6);
  int compared = 0;
  for (int k = 0; k < 40; ++k) {
    const Pose pose = at(model.reference.pose.position + test::uniformVector(-0.35, 0.35));
    const PoseQuery query = queryPose(model, analysis, pose);
    if (!query.kinematics.ikp.assembled) continue;
    ASSERT_EQ(query.kinematics.modes.size(), analysis.modes().size());
    for (const WorkingModeAnalysis& mode : query.kinematics.modes) {
      for (int c = 0; c < model.chainCount(); ++c) {  // the inputs close the chains
        const Chain& chain = *model.chains[c];
        EXPECT_NEAR((pose.toBase(chain.platformNode()) - chain.intermediateNode(mode.q[c])).norm(), chain.rodLength(), 1e-9);
      }
      if (std::abs(mode.singularity.measure) < 1e-6) continue;  // a sign finite differences cannot settle
      EXPECT_EQ(signOf(finiteDifferenceJacobian(model, pose, mode).determinant()), signOf(mode.singularity.det))
          << pose.position.transpose();
      ++compared;
    }
  }
  EXPECT_GE(compared, 80);
}

TEST(PoseQuery, TheNearestPointIsTheNearestCellOfTheMaximalWorkspace) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis& analysis = deltaAnalysis();
  // Far outside the box on every side, just outside the workspace, and random poses over
  // and around the box.
  for (const Eigen::Vector3d& position :
       {Eigen::Vector3d(0.15, 0.15, 3.0), Eigen::Vector3d(-2.0, 0.15, 0.75), Eigen::Vector3d(0.4, -1.5, -1.0),
        Eigen::Vector3d(0.15, 0.15, 1.6)}) {
    const PoseQuery query = queryPose(model, analysis, at(position));
    EXPECT_FALSE(query.kinematics.ikp.assembled) << position.transpose();
    EXPECT_FALSE(query.assembly_modes[0].in_maximal);
    EXPECT_GT(query.assembly_modes[0].distance, 0.0);
    expectNearestByBruteForce(model, analysis, at(position));
  }
  int outside_a_maximal = 0;
  for (int k = 0; k < 12; ++k) {
    const Pose pose = at(Eigen::Vector3d(test::uniform(-0.6, 1.4), test::uniform(-1.2, 1.4), test::uniform(-0.6, 1.6)));
    const PoseQuery query = queryPose(model, analysis, pose);
    outside_a_maximal += !query.assembly_modes[0].in_maximal || !query.assembly_modes[1].in_maximal;
    expectNearestByBruteForce(model, analysis, pose);
  }
  EXPECT_GE(outside_a_maximal, 6);
}

// A grid over z and a full turn of phi (periodic) on the hexapod: the nearest point across
// the seam of the turn.
TEST(PoseQuery, TheNearestPointWrapsAroundAFullTurn) {
  const RobotModel& model = test::hexapod();
  GridSpec spec;
  spec.variables = {OutputVariable::Z, OutputVariable::Phi};
  spec.steps = {0.004, 0.05};
  spec.start = model.reference.pose;
  const WorkspaceAnalysis analysis = analyseWorkspace(model, spec, AnalysisOptions{});
  ASSERT_TRUE(analysis.grid().periodic(1));
  // Angles beyond the turn, and heights beyond the box.
  for (int k = 0; k < 40; ++k) {
    Pose pose = model.reference.pose;
    pose.position.z() = test::uniform(-0.5, 0.6);
    pose.euler_zyz[0] = test::uniform(-10.0, 10.0);
    expectNearestByBruteForce(model, analysis, pose);
  }
}

TEST(PoseQuery, AnotherOrientationIsOffTheGrid) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis& analysis = deltaAnalysis();
  Pose turned = model.reference.pose;
  turned.euler_zyz = Eigen::Vector3d(0.1, 0.05, 0.0);
  const PoseQuery query = queryPose(model, analysis, turned);
  EXPECT_TRUE(query.kinematics.ikp.assembled);  // the auxiliary still closes
  EXPECT_FALSE(query.on_grid);
  EXPECT_FALSE(query.in_workspace);
  for (std::int32_t region : query.regions) EXPECT_EQ(region, -1);
  for (const AssemblyModeAtPose& am : query.assembly_modes) {
    EXPECT_FALSE(am.in_maximal);
    ASSERT_TRUE(am.has_nearest);
    // The nearest point is on the grid, at the grid's orientation; the distance counts
    // the grid's variables alone: here half a cell diagonal at most.
    EXPECT_EQ(am.nearest.euler_zyz, model.reference.pose.euler_zyz);
    EXPECT_LE(am.distance, 0.5 * std::sqrt(3.0) * kStep + 1e-12);
  }
  // Within rounding of the grid's orientation, the pose is on it.
  Pose rounded = model.reference.pose;
  rounded.euler_zyz = Eigen::Vector3d(1e-12, -1e-12, 0.0);
  EXPECT_TRUE(queryPose(model, analysis, rounded).on_grid);
}

// A pose farther than squares of doubles reach (issue 28: beyond some 1.3e154 m every term
// overflowed and the pose had no nearest point, which only an empty workspace may lack):
// it has one, at a finite distance. (So far away every cell is equally near in double
// precision, as from 1e100 m: the tie goes to the smallest grid index.)
TEST(PoseQuery, APoseTooFarForSquaresStillHasItsNearestPoint) {
  const WorkspaceAnalysis& analysis = deltaAnalysis();
  const PoseQuery query = queryPose(test::deltaLike(), analysis, at(Eigen::Vector3d(1e200, 0.1, 0.7)));
  for (const AssemblyModeAtPose& am : query.assembly_modes) {
    ASSERT_TRUE(am.has_nearest);
    EXPECT_EQ(am.distance, 1e200);  // the other gaps vanish beside it
  }
  const PoseQuery near = queryPose(test::deltaLike(), analysis, at(Eigen::Vector3d(1e100, 0.1, 0.7)));
  for (std::size_t a = 0; a < query.assembly_modes.size(); ++a) {
    EXPECT_EQ(query.assembly_modes[a].nearest_cell, near.assembly_modes[a].nearest_cell) << "as from 1e100 m";
  }
}

TEST(PoseQuery, ANonFinitePoseIsOffTheGridWithoutANearestPoint) {
  const PoseQuery query = queryPose(test::deltaLike(), deltaAnalysis(), at(Eigen::Vector3d(NAN, 0.1, 0.7)));
  EXPECT_FALSE(query.on_grid);
  EXPECT_FALSE(query.assembly_modes[0].has_nearest);
  EXPECT_FALSE(query.assembly_modes[1].has_nearest);
}

TEST(PoseRotation, ZyzAnglesComeBackFromTheRotation) {
  for (int k = 0; k < 200; ++k) {
    Pose pose;
    pose.euler_zyz = Eigen::Vector3d(test::uniform(-M_PI, M_PI), test::uniform(0.0, M_PI), test::uniform(-M_PI, M_PI));
    Pose back;
    back.setRotation(pose.rotation());
    EXPECT_LT((back.rotation() - pose.rotation()).norm(), 1e-14);
    EXPECT_GE(back.euler_zyz[1], 0.0);
    if (pose.euler_zyz[1] > 1e-6 && pose.euler_zyz[1] < M_PI - 1e-6) {
      EXPECT_LT((back.euler_zyz - pose.euler_zyz).norm(), 1e-12);
    }
  }
  // At theta = 0 only phi + psi is defined: phi is kept.
  Pose degenerate;
  degenerate.euler_zyz[0] = 0.2;
  degenerate.setRotation(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix());
  EXPECT_NEAR((degenerate.euler_zyz - Eigen::Vector3d(0.2, 0.0, 0.5)).norm(), 0.0, 1e-15);
}

TEST(PoseRotation, ARequestQuaternionGivesItsZyzAngles) {
  const RobotModel& model = test::deltaLike();
  const Eigen::Vector3d angles(0.3, 0.2, -0.1);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(angles[0], Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(angles[1], Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(angles[2], Eigen::Vector3d::UnitZ()));
  RequestPose request;
  request.position = {0.2, 0.1, 0.7};
  request.orientation = {q.w(), q.x(), q.y(), q.z()};
  const Pose pose = requestedPose(request, model, "pose");
  EXPECT_EQ(pose.position, Eigen::Vector3d(0.2, 0.1, 0.7));
  EXPECT_LT((pose.euler_zyz - angles).norm(), 1e-12);
  // The identity and a zero quaternion are the reference orientation, exactly.
  request.orientation = {1.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(requestedPose(request, model, "pose").euler_zyz, model.reference.pose.euler_zyz);
  request.orientation = {0.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(requestedPose(request, model, "pose").euler_zyz, model.reference.pose.euler_zyz);
  request.orientation = {0.0, 0.0, 0.0, 2.0};
  EXPECT_THROW(requestedPose(request, model, "pose"), InputError);
}

}  // namespace
}  // namespace maximal_workspace
