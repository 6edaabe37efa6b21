// PoseClassifier's generic path (shared-minor expansion over the working modes' branches)
// against an independent evaluation: per working mode, the twist-form J_DKP from
// jacobian.h, its rotational columns divided by the characteristic length, and Eigen's
// full-pivot LU determinant over the product of its row norms (docs/kinematics.md). On the
// delta-like robot (8 modes and its uncoupled auxiliary's 64), the 6-RSS hexapod (64), the
// planar 5R and a planar 3-RRR (rotation about z), at random positions and orientations.

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/LU>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/robot_file.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

// A planar 3-RRR: base joints 0.3 m from the origin at 90, 210 and 330 deg, cranks and
// distal links 0.2 m, platform joints 0.05 m from the TCP in the same directions.
const RobotModel& threeRrr() {
  static const RobotModel model = parseRobotFile(R"(
name: three_rrr
output_variables: [x, y, phi]
inputs: [{name: q1}, {name: q2}, {name: q3}]
chains:
  - {name: l1, type: RSS, input: q1, fixed_node: [0, 0.3, 0], axis: [0, 0, 1], crank_length: 0.2, rod_length: 0.2,
     platform_node: [0, 0.05, 0]}
  - {name: l2, type: RSS, input: q2, fixed_node: [-0.25980762113533160, -0.15, 0], axis: [0, 0, 1], crank_length: 0.2,
     rod_length: 0.2, platform_node: [-0.043301270189221933, -0.025, 0]}
  - {name: l3, type: RSS, input: q3, fixed_node: [0.25980762113533160, -0.15, 0], axis: [0, 0, 1], crank_length: 0.2,
     rod_length: 0.2, platform_node: [0.043301270189221933, -0.025, 0]}
reference:
  position: [0, 0, 0]
)",
                                                 "three_rrr.yaml");
  return model;
}

// The independent evaluation; false when the pose is not assembled.
bool fullPivotMeasures(const RobotModel& model, const std::vector<WorkingMode>& modes, const Pose& pose,
                       std::vector<double>& measures) {
  const IkpResult ikp = solveIkp(model, pose);
  if (!ikp.assembled) return false;
  measures.clear();
  for (const WorkingMode& mode : modes) {
    DkpJacobian jacobian = dkpJacobianTwist(model, configurationOf(pose, ikp, mode));
    for (int j = 0; j < model.dof(); ++j) {
      if (isRotational(model.output_variables[j])) jacobian.col(j) /= model.characteristic_length;
    }
    const double norms = jacobian.rowwise().norm().prod();
    measures.push_back(Eigen::FullPivLU<Eigen::MatrixXd>(jacobian).determinant() / norms);
  }
  return true;
}

// Poses within `spread` (m) of the reference position and `turn` (rad) of its orientation,
// in the robot's DOF only.
std::vector<Pose> randomPoses(const RobotModel& model, int count, double spread, double turn) {
  std::vector<Pose> poses;
  for (int k = 0; k < count; ++k) {
    Pose pose = model.reference.pose;
    for (OutputVariable variable : model.output_variables) {
      const double half = isRotational(variable) ? turn : spread;
      pose.setValue(variable, pose.value(variable) + test::uniform(-half, half));
    }
    poses.push_back(pose);
  }
  return poses;
}

// Classifies the poses as one batch (several blocks and a partial one) and checks every
// pose against the independent evaluation: the same assembly verdict, and measures within
// 1e-12 (absolute: they lie in [-1, 1]) with the same sign. Returns how many were assembled and how many measures were
// under 1e-3 in magnitude (near a DKP singularity, where the sign is hardest).
std::array<int, 2> expectFullPivotMeasures(const RobotModel& model, const std::vector<WorkingMode>& modes,
                                           const std::vector<Pose>& poses) {
  const PoseClassifier classifier(model, modes, model.reference.pose, /*orientation_fixed=*/false);
  EXPECT_FALSE(classifier.factorised());
  const std::size_t count = modes.size();
  std::vector<std::uint8_t> inside(poses.size());
  std::vector<double> batch(poses.size() * count), expected;
  classifier.classify(poses.data(), poses.size(), inside.data(), batch.data());
  std::array<int, 2> tally{0, 0};
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const bool assembled = fullPivotMeasures(model, modes, poses[i], expected);
    EXPECT_EQ(inside[i] == 1, assembled) << model.name << " pose " << i;
    if (!assembled || inside[i] == 0) continue;
    ++tally[0];
    for (std::size_t m = 0; m < count; ++m) {
      const double actual = batch[i * count + m];
      EXPECT_NEAR(actual, expected[m], 1e-12) << model.name << " pose " << i << " mode " << modes[m].name;
      // Implied by the line above, but the sign is what names the assembly mode.
      if (std::abs(expected[m]) > 1e-12) {
        EXPECT_EQ(actual > 0.0, expected[m] > 0.0) << modes[m].name;
      }
      tally[1] += std::abs(expected[m]) < 1e-3;
    }
  }
  return tally;
}

// Poses next to DKP singularities: between consecutive assembled poses where some mode's
// measure changes sign, bisection along the straight segment (on the independent
// evaluation) until that measure is under 1e-8 in magnitude; a segment that leaves the
// workspace is dropped.
std::vector<Pose> posesNextToSingularities(const RobotModel& model, const std::vector<WorkingMode>& modes,
                                           const std::vector<Pose>& poses) {
  std::vector<Pose> found;
  std::vector<double> at_from, at_to, at_middle;
  for (std::size_t i = 0; i + 1 < poses.size(); ++i) {
    Pose from = poses[i], to = poses[i + 1];
    if (!fullPivotMeasures(model, modes, from, at_from) || !fullPivotMeasures(model, modes, to, at_to)) continue;
    std::size_t m = 0;
    while (m < modes.size() && (at_from[m] > 0.0) == (at_to[m] > 0.0)) ++m;
    if (m == modes.size()) continue;
    for (int step = 0; step < 100; ++step) {
      Pose middle = from;
      middle.position = 0.5 * (from.position + to.position);
      middle.euler_zyz = 0.5 * (from.euler_zyz + to.euler_zyz);
      if (!fullPivotMeasures(model, modes, middle, at_middle)) break;
      if (std::abs(at_middle[m]) < 1e-8) {
        found.push_back(middle);
        break;
      }
      ((at_middle[m] > 0.0) == (at_from[m] > 0.0) ? from : to) = middle;
    }
  }
  return found;
}

// The batch kernels' AVX2 clone runs wherever the CPU has its instructions. Named by CPU
// model (arch=haswell), it was dispatched to the baseline on every AMD core.
TEST(VectorKernels, TheAvx2CloneRunsWhereTheCpuHasItsInstructions) {
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
  __builtin_cpu_init();
  const bool level_v3 = __builtin_cpu_supports("x86-64-v3");
  EXPECT_STREQ(vectorKernelsInUse(), level_v3 ? "AVX2 (x86-64-v3)" : "x86-64 baseline");
#else
  EXPECT_STREQ(vectorKernelsInUse(), "as compiled");
#endif
}

TEST(PoseClassifierGeneric, DeltaLikeModesMatchFullPivotLu) {
  const RobotModel& model = test::deltaLike();
  for (const std::vector<WorkingMode>& modes : {coupledWorkingModes(model), uncoupledWorkingModes(model)}) {
    const std::array<int, 2> tally = expectFullPivotMeasures(model, modes, randomPoses(model, 1500, 0.4, 0.5));
    EXPECT_GT(tally[0], 300) << modes.size() << " modes";
    EXPECT_GT(tally[1], 0) << modes.size() << " modes: no pose near a singularity";
    EXPECT_LT(tally[0], 1500) << modes.size() << " modes: every pose assembled";
  }
}

TEST(PoseClassifierGeneric, HexapodModesMatchFullPivotLu) {
  const RobotModel& model = test::hexapod();
  const std::vector<WorkingMode> modes = coupledWorkingModes(model);
  ASSERT_EQ(modes.size(), 64u);
  const std::array<int, 2> tally = expectFullPivotMeasures(model, modes, randomPoses(model, 1500, 0.05, 0.4));
  EXPECT_GT(tally[0], 300);
  EXPECT_LT(tally[0], 1500) << "every pose assembled";
}

TEST(PoseClassifierGeneric, PlanarRobotsMatchFullPivotLu) {
  for (const RobotModel* model : {&test::fiveBar(), &threeRrr()}) {
    const std::array<int, 2> tally =
        expectFullPivotMeasures(*model, coupledWorkingModes(*model), randomPoses(*model, 1500, 0.2, 1.0));
    EXPECT_GT(tally[0], 300) << model->name;
    EXPECT_LT(tally[0], 1500) << model->name;
  }
}

// Where a pivot-free elimination would lose the sign: every pose has a mode within 1e-8 of
// a DKP singularity.
TEST(PoseClassifierGeneric, NextToDkpSingularitiesMatchesFullPivotLu) {
  const RobotModel& model = test::deltaLike();
  const std::vector<WorkingMode> modes = uncoupledWorkingModes(model);
  std::vector<Pose> candidates;
  std::vector<double> scratch;
  while (candidates.size() < 300) {
    const Pose pose = randomPoses(model, 1, 0.4, 0.5).front();
    if (fullPivotMeasures(model, modes, pose, scratch)) candidates.push_back(pose);
  }
  const std::vector<Pose> poses = posesNextToSingularities(model, modes, candidates);
  ASSERT_GT(poses.size(), 100u);
  const std::array<int, 2> tally = expectFullPivotMeasures(model, modes, poses);
  EXPECT_EQ(tally[0], static_cast<int>(poses.size()));
  EXPECT_GE(tally[1], tally[0]);
}

// A list of some modes in any order, one of them twice, as a working-mode filter makes:
// each gets its own measure, and the pruned branch tree still reaches every one.
TEST(PoseClassifierGeneric, SubsetOfModesInAnyOrderMatchesFullPivotLu) {
  const RobotModel& model = test::hexapod();
  const std::vector<WorkingMode> all = coupledWorkingModes(model);
  const std::vector<WorkingMode> some = {all[63], all[5], all[40], all[5], all[0], all[22]};
  const std::array<int, 2> tally = expectFullPivotMeasures(model, some, randomPoses(model, 500, 0.05, 0.4));
  EXPECT_GT(tally[0], 100);
}

// The batch of poses against pose-by-pose classification on both paths (the factorised
// one gathers the positions into its own batch form).
TEST(PoseClassifier, PoseBatchAgreesWithPoseByPose) {
  const RobotModel& model = test::deltaLike();
  const std::vector<WorkingMode> modes = coupledWorkingModes(model);
  for (bool fixed : {true, false}) {
    const PoseClassifier classifier(model, modes, model.reference.pose, fixed);
    ASSERT_EQ(classifier.factorised(), fixed);
    const std::vector<Pose> poses = randomPoses(model, 1000, 0.4, fixed ? 0.0 : 0.5);
    std::vector<std::uint8_t> inside(poses.size());
    std::vector<double> batch(poses.size() * modes.size()), one(modes.size());
    classifier.classify(poses.data(), poses.size(), inside.data(), batch.data());
    int assembled = 0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      ASSERT_EQ(inside[i] == 1, classifier.classify(poses[i], one.data())) << "pose " << i;
      if (inside[i] == 0) continue;
      ++assembled;
      for (std::size_t m = 0; m < modes.size(); ++m) EXPECT_NEAR(batch[i * modes.size() + m], one[m], 1e-12);
    }
    EXPECT_GT(assembled, 100);
  }
}

}  // namespace
}  // namespace maximal_workspace
