// The planner on the delta-like robot: a path inside one region, the chapter's Fig. 14
// situation (a goal no single working mode joins to the start), a goal only in the other
// assembly mode, bad starts and goals; the actuator trajectory's continuity and limits;
// and the DKP-continuation verification, including a plan it must reject.

#include <cmath>

#include <gtest/gtest.h>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/planner/path_planner.h"
#include "maximal_workspace/planner/trajectory.h"
#include "maximal_workspace/planner/verification.h"
#include "fig14_goal.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

constexpr double kThreshold = 1e-3;

const WorkspaceAnalysis& analysis() {
  static const WorkspaceAnalysis result = [] {
    GridSpec spec;
    spec.variables = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
    spec.steps = {0.01};
    spec.start = test::deltaLike().reference.pose;
    return analyseWorkspace(test::deltaLike(), spec, {});
  }();
  return result;
}

const PathPlanner& planner() {
  static const PathPlanner result(test::deltaLike(), analysis(), kThreshold);
  return result;
}

Pose at(const Eigen::Vector3d& position) {
  Pose pose = test::deltaLike().reference.pose;
  pose.position = position;
  return pose;
}

Pose voxelPose(std::uint32_t voxel) { return analysis().grid.pose(analysis().map.voxel_cell[voxel]); }

PlanRequest fromReference(const Pose& goal) {
  PlanRequest request;
  request.start = test::deltaLike().reference.pose;
  request.start_mode = analysis().start_mode;
  request.goal = goal;
  return request;
}

const InputLimits kLimits{{1.0, 0.5, 0.5}, {2.0, 1.0, 1.0}};

std::uint32_t fig14Goal() { return test::fig14Goal(analysis()); }

void expectVerified(const Plan& plan) {
  const InputTrajectory trajectory = inputTrajectory(test::deltaLike(), analysis(), plan, kLimits);
  const Verification verification = verifyByDkpContinuation(test::deltaLike(), trajectory, plan.sign);
  EXPECT_TRUE(verification.passed) << verification.message;
  EXPECT_LT(verification.max_waypoint_deviation, 1e-6);
  EXPECT_LT(verification.max_rotation, 1e-6);
}

TEST(Planner, PathInsideOneRegionNeedsNoTransition) {
  const Pose goal = at(test::deltaLike().reference.pose.position + Eigen::Vector3d(0.1, 0.05, -0.1));
  std::uint64_t cell = 0;
  ASSERT_TRUE(analysis().grid.cellOf(goal, &cell));
  ASSERT_EQ(analysis().regions.label(analysis().map.cell_voxel[cell], analysis().start_mode),
            analysis().regions.label(0, analysis().start_mode));
  const Plan plan = planner().plan(fromReference(goal));
  ASSERT_TRUE(plan.success) << plan.message;
  EXPECT_TRUE(plan.transitions.empty());
  EXPECT_EQ(plan.waypoints.front().pose.position, test::deltaLike().reference.pose.position);
  EXPECT_EQ(plan.waypoints.back().pose.position, goal.position);
  EXPECT_GE(plan.length, (goal.position - test::deltaLike().reference.pose.position).norm() - 1e-12);
  EXPECT_GE(plan.min_measure, kThreshold);
  expectVerified(plan);
}

TEST(Planner, Fig14GoalNeedsTransitionsAndTheirPlanVerifies) {
  const std::uint32_t goal_voxel = fig14Goal();
  ASSERT_NE(goal_voxel, 0u) << "no goal that only transitions reach: the premise of the test";
  const Pose goal = voxelPose(goal_voxel);
  // The traditional way, one working mode: no path.
  PlanRequest single = fromReference(goal);
  single.allowed_modes = {analysis().start_mode};
  const Plan traditional = planner().plan(single);
  EXPECT_FALSE(traditional.success);
  EXPECT_NE(traditional.message.find("DKP singularity"), std::string::npos) << traditional.message;
  // Through the maximal workspace: a path with at least one transition.
  const Plan plan = planner().plan(fromReference(goal));
  ASSERT_TRUE(plan.success) << plan.message;
  ASSERT_FALSE(plan.transitions.empty());
  for (const PlanTransition& t : plan.transitions) {
    const std::string& from = analysis().modes[t.from_mode].name;
    const std::string& to = analysis().modes[t.to_mode].name;
    int differences = 0;
    for (std::size_t k = 0; k < from.size(); ++k) differences += from[k] != to[k];
    EXPECT_EQ(differences, 1) << from << " -> " << to;
    EXPECT_NE(from[t.input], to[t.input]);
    // The transition point is on the IKP boundary of the couple that changes branch.
    const IkpResult ikp = solveIkp(test::deltaLike(), plan.waypoints[t.waypoint].pose);
    const int chain = test::deltaLike().inputs[t.input].chains.front();
    EXPECT_LT(std::abs(ikp.chains[chain].discriminant), 1e-6);
  }
  expectVerified(plan);
}

TEST(Planner, TrajectoryIsContinuousThroughTransitionsAndWithinItsLimits) {
  const Plan plan = planner().plan(fromReference(voxelPose(fig14Goal())));
  ASSERT_TRUE(plan.success) << plan.message;
  const InputTrajectory trajectory = inputTrajectory(test::deltaLike(), analysis(), plan, kLimits);
  ASSERT_EQ(trajectory.waypoint_samples.size(), plan.waypoints.size());
  // No jump anywhere: neighbouring samples are close, and at a transition the sample
  // ending the arrival is the one starting the departure.
  for (const PlanTransition& t : plan.transitions) {
    EXPECT_EQ(trajectory.waypoint_samples[t.waypoint - 1], trajectory.waypoint_samples[t.waypoint]);
  }
  const auto velocity = inputVelocities(trajectory);
  const auto acceleration = inputAccelerations(trajectory);
  for (std::size_t k = 0; k < trajectory.time.size(); ++k) {
    for (std::size_t i = 0; i < trajectory.inputs.size(); ++i) {
      EXPECT_LE(std::abs(velocity[k][i]), kLimits.velocity[i] * 1.0001) << "sample " << k << " input " << i;
      EXPECT_LE(std::abs(acceleration[k][i]), kLimits.acceleration[i] * 1.0001) << "sample " << k << " input " << i;
    }
    if (k > 0) {
      EXPECT_GT(trajectory.time[k], trajectory.time[k - 1]);
      for (std::size_t i = 0; i < trajectory.inputs.size(); ++i) {
        // A jump would show as a step far beyond what the limits allow in one sample.
        EXPECT_LE(std::abs(trajectory.q[k][i] - trajectory.q[k - 1][i]),
                  kLimits.velocity[i] * (trajectory.time[k] - trajectory.time[k - 1]) * 1.5 + 1e-9);
      }
    }
  }
}

TEST(Planner, GoalOnlyInTheOtherAssemblyModeIsRefused) {
  const WorkspaceAnalysis& a = analysis();
  const std::int8_t sign = a.regions.regions[a.regions.label(0, a.start_mode)].sign;
  for (std::uint32_t v = 0; v < a.map.voxelCount(); ++v) {
    bool same = false, other = false;
    for (int m = 0; m < a.map.mode_count; ++m) {
      same = same || a.map.sign(v, m) == sign;
      other = other || a.map.sign(v, m) == -sign;
    }
    if (same || !other) continue;
    const Plan plan = planner().plan(fromReference(voxelPose(v)));
    EXPECT_FALSE(plan.success);
    EXPECT_NE(plan.message.find("requires crossing a DKP singularity"), std::string::npos) << plan.message;
    return;
  }
  FAIL() << "no voxel only in the other assembly mode: the premise of the test";
}

TEST(Planner, StartOrGoalOutsideOrOnASingularityIsRefusedWithTheReason) {
  const Pose far = at(Eigen::Vector3d(0.9, 0.9, 0.7));
  PlanRequest outside_start = fromReference(voxelPose(100));
  outside_start.start = far;
  EXPECT_NE(planner().plan(outside_start).message.find("the start (0.9, 0.9, 0.7) is outside the workspace"),
            std::string::npos);
  EXPECT_NE(planner().plan(fromReference(far)).message.find("the goal (0.9, 0.9, 0.7) is outside the workspace"),
            std::string::npos);
  // A start in the singular band of its working mode.
  const WorkspaceAnalysis& a = analysis();
  for (const DkpSingularVoxel& s : a.singularities.dkp) {
    if (std::abs(s.measure) >= kThreshold) continue;
    PlanRequest request = fromReference(test::deltaLike().reference.pose);
    request.start = voxelPose(s.voxel);
    request.start_mode = s.mode;
    const Plan plan = planner().plan(request);
    EXPECT_FALSE(plan.success);
    EXPECT_NE(plan.message.find("on a DKP singularity of working mode " + a.modes[s.mode].name), std::string::npos)
        << plan.message;
    return;
  }
  FAIL() << "no voxel in the singular band";
}

TEST(Verification, RejectsAPlanThroughADkpSingularity) {
  // A straight line from the start in its working mode to the nearest voxel where that
  // mode has the other sign: assembled all along, but through det J_DKP = 0.
  const WorkspaceAnalysis& a = analysis();
  const int mode = a.start_mode;
  const Pose start = test::deltaLike().reference.pose;
  const std::int8_t sign = a.map.sign(0, mode);
  std::uint32_t across = 0;
  double nearest = INFINITY;
  for (std::uint32_t v = 0; v < a.map.voxelCount(); ++v) {
    const double distance = (voxelPose(v).position - start.position).norm();
    if (a.map.sign(v, mode) != -sign || distance >= nearest) continue;
    bool assembled = true;
    for (int k = 0; k <= 200 && assembled; ++k) {
      assembled = solveIkp(test::deltaLike(), at(start.position + k / 200.0 * (voxelPose(v).position - start.position))).assembled;
    }
    if (assembled) {
      nearest = distance;
      across = v;
    }
  }
  ASSERT_LT(nearest, INFINITY);
  Plan crossing;
  crossing.success = true;
  crossing.sign = sign;
  crossing.waypoints = {{start, mode}, {voxelPose(across), mode}};
  const InputTrajectory trajectory = inputTrajectory(test::deltaLike(), a, crossing, kLimits);
  const Verification verification = verifyByDkpContinuation(test::deltaLike(), trajectory, sign);
  EXPECT_FALSE(verification.passed);
  // Crossing det J_DKP = 0 the continuation either sees the sign change or, near the
  // singularity, slides to another assembly and leaves the planned path.
  EXPECT_TRUE(verification.message.find("det J_DKP changes sign") != std::string::npos ||
              verification.message.find("leaves the planned path") != std::string::npos)
      << verification.message;
}

TEST(Planner, CheckSegmentFindsTheSingularityTheVerificationFinds) {
  // The planner's own segment check must refuse the same straight line.
  const WorkspaceAnalysis& a = analysis();
  const int mode = a.start_mode;
  for (const DkpSingularVoxel& s : a.singularities.dkp) {
    if (s.mode != mode || a.map.sign(s.voxel, mode) != -a.map.sign(0, mode)) continue;
    EXPECT_LT(planner().checkSegment(test::deltaLike().reference.pose, voxelPose(s.voxel), mode, a.map.sign(0, mode), kThreshold), 0.0);
    return;
  }
  FAIL() << "no DKP singular voxel of the start's working mode";
}

TEST(Trajectory, SepticProfileStartsAndEndsAtRest) {
  EXPECT_EQ(septic(0.0), 0.0);
  EXPECT_NEAR(septic(1.0), 1.0, 1e-15);
  EXPECT_NEAR(septic(0.5), 0.5, 1e-15);  // symmetric
  // Near the ends it grows like tau^4: first three derivatives zero.
  for (double tau : {1e-2, 1e-3}) {
    EXPECT_NEAR(septic(tau) / std::pow(tau, 4), 35.0, 1.0);
    EXPECT_NEAR((1.0 - septic(1.0 - tau)) / std::pow(tau, 4), 35.0, 1.0);
  }
}

}  // namespace
}  // namespace maximal_workspace
