// Planning over a tilt-and-torsion orientation set (the hexaglide, 10 deg): a goal that
// only transitions between working modes reach is planned in position and orientation
// together and verified by DKP continuation, rotation included; a move across the
// azimuth's seam takes the short way round.

#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/planner/path_planner.h"
#include "maximal_workspace/planner/trajectory.h"
#include "maximal_workspace/planner/verification.h"
#include "fig14_goal.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

constexpr double kEnvelope = 10.0 * M_PI / 180.0;

const RobotModel& hexaglide() {
  static const RobotModel model = loadRobotFile(test::sourcePath("config/hexaglide_6pss.yaml"));
  return model;
}

// Positions from the rails' middle to where the start's region ends along x (x > 0.19 m is
// reached only through transitions, docs/results.md) at 20 mm, every orientation of the
// 10 deg envelope at 5 deg; the start's working mode and the six one branch away.
const WorkspaceAnalysis& analysis() {
  static const WorkspaceAnalysis result = [] {
    GridSpec spec;
    spec.variables = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
    spec.steps = {0.02};
    spec.start = hexaglide().reference.pose;
    spec.bounds = {{-0.02, 0.4}, {-0.1, 0.1}, {0.2, 0.36}};
    addOrientationSet(hexaglide(), OrientationSet{kEnvelope, {-kEnvelope, kEnvelope}, kEnvelope / 2.0}, &spec);
    AnalysisOptions options;
    options.threads = 2;
    options.margin = 1e-3;
    options.working_modes = {"ppnnpp", "npnnpp", "pnnnpp", "pppnpp", "ppnppp", "ppnnnp", "ppnnpn"};
    return analyseWorkspace(hexaglide(), spec, options);
  }();
  return result;
}

const PathPlanner& planner() {
  static const PathPlanner result(hexaglide(), analysis());
  return result;
}

const InputLimits kLimits{std::vector<double>(6, 0.5), std::vector<double>(6, 1.0)};

Verification verified(const Plan& plan) {
  const InputTrajectory trajectory = inputTrajectory(hexaglide(), analysis(), plan, kLimits);
  return verifyByDkpContinuation(hexaglide(), trajectory, plan.sign);
}

// The pose at a position and azimuth, tilt and torsion (rad), by the grid's definition.
Pose tiltTorsionPose(const Eigen::Vector3d& position, double a, double t, double s) {
  const double values[6] = {position.x(), position.y(), position.z(), a, t, s};
  return analysis().grid().poseAt(values);
}

// A cell outside the start's region that transitions reach (another working mode's region
// joined to the start's in the transition graph), every face neighbour alike so that its
// centre is clear of the region's boundary; 0 when there is none.
std::uint64_t goalOnlyTransitionsReach() {
  const WorkspaceAnalysis& a = analysis();
  const Grid& grid = a.grid();
  const test::StartGroup group(a);
  auto outsideTheStartRegion = [&](std::uint64_t cell) { return a.label(cell, a.startMode()) != group.startRegion(); };
  for (std::uint64_t cell = 0; cell < grid.cellCount(); cell += 7) {
    const std::int32_t region = group.reachedIn(cell);
    if (region < 0 || !outsideTheStartRegion(cell)) continue;
    bool interior = true;
    for (int d = 0; d < grid.dims() && interior; ++d) {
      for (int direction : {-1, 1}) {
        std::uint64_t next = 0;
        if (!grid.neighbour(cell, d, direction, &next)) continue;  // the pole, or the set's edge
        interior = interior && group.reachedIn(next) == region && outsideTheStartRegion(next);
      }
    }
    if (interior) return cell;
  }
  return 0;
}

std::string gridPointText(const Pose& pose) {
  std::string text;
  for (int d = 0; d < 6; ++d) text += (d ? "," : "") + std::to_string(analysis().grid().coordinate(pose, d));
  return text;
}

PlanRequest fromReference(const Pose& goal) {
  PlanRequest request;
  request.start = hexaglide().reference.pose;
  request.start_mode = analysis().startMode();
  request.goal = goal;
  return request;
}

TEST(OrientationPlan, AGoalOnlyTransitionsReachIsPlannedInPositionAndOrientationAndVerified) {
  const std::uint64_t goal_cell = goalOnlyTransitionsReach();
  ASSERT_NE(goal_cell, 0u) << "no goal that only transitions reach: the premise of the test";
  const Pose goal = analysis().grid().pose(goal_cell);
  const double goal_tilt = analysis().grid().coordinate(goal, analysis().grid().tiltDim());
  ASSERT_GT(goal_tilt, 0.0);
  // In the start's working mode alone: no path.
  PlanRequest single = fromReference(goal);
  single.allowed_modes = {analysis().startMode()};
  const Plan traditional = planner().plan(single);
  EXPECT_FALSE(traditional.success);
  // Here the start's working mode takes a slider past its stroke: its own limits, not a
  // DKP singularity, keep it from the goal.
  EXPECT_NE(traditional.message.find(analysis().modes()[analysis().startMode()].name), std::string::npos)
      << traditional.message;

  const Plan plan = planner().plan(fromReference(goal));
  ASSERT_TRUE(plan.success) << plan.message;
  EXPECT_FALSE(plan.transitions.empty());
  EXPECT_EQ(plan.waypoints.back().pose.position, goal.position);
  const double off = Eigen::AngleAxisd(plan.waypoints.back().pose.rotation() * goal.rotation().transpose()).angle();
  EXPECT_LT(off, 1e-9);
  const Verification verification = verified(plan);
  EXPECT_TRUE(verification.passed) << verification.message;
  std::printf("goal %s: %zu waypoints, %zu transitions, length %.3f m; %s\n", gridPointText(goal).c_str(),
              plan.waypoints.size(), plan.transitions.size(), plan.length, verification.message.c_str());
  EXPECT_LT(verification.max_waypoint_deviation, 1e-6);
  // The platform really turned, to the goal's tilt at least (the angle of a rotation is at
  // least its tilt), and the continuation followed it there.
  EXPECT_GT(verification.max_rotation, goal_tilt - 1e-9);
}

TEST(OrientationPlan, AMoveAcrossTheAzimuthSeamTakesTheShortWay) {
  const Eigen::Vector3d position = hexaglide().reference.pose.position;
  PlanRequest request;
  request.start = tiltTorsionPose(position, 3.0, 0.12, 0.0);
  request.goal = tiltTorsionPose(position, -3.0, 0.12, 0.0);
  request.start_mode = analysis().startMode();
  const Plan plan = planner().plan(request);
  ASSERT_TRUE(plan.success) << plan.message;
  // The short way changes the azimuth by 2 pi - 6 rad; the long way by 6 rad.
  const double short_way = (2.0 * M_PI - 6.0) * hexaglide().characteristic_length;
  EXPECT_LT(plan.length, 2.0 * short_way);
  const Verification verification = verified(plan);
  EXPECT_TRUE(verification.passed) << verification.message;
  // The long way would swing the tilted axis through the other side, a rotation of twice
  // the tilt from the start; the short one turns it by about 0.03 rad.
  EXPECT_LT(verification.max_rotation, 0.1);
}

TEST(OrientationPlan, TheTrajectoryEndsAtTheGoalOrientationWhicheverZyzAnglesItHolds) {
  const Eigen::Vector3d position = hexaglide().reference.pose.position + Eigen::Vector3d(0.04, -0.02, 0.02);
  Pose goal = tiltTorsionPose(position, -2.5, 0.12, 0.1);
  // The same rotation by another ZYZ triple: (phi + pi, -theta, psi + pi), and turns added.
  goal.euler_zyz = Eigen::Vector3d(goal.euler_zyz[0] + M_PI + 2.0 * M_PI, -goal.euler_zyz[1], goal.euler_zyz[2] - 3.0 * M_PI);
  const Plan plan = planner().plan(fromReference(goal));
  ASSERT_TRUE(plan.success) << plan.message;
  const InputTrajectory trajectory = inputTrajectory(hexaglide(), analysis(), plan, kLimits);
  const double off = Eigen::AngleAxisd(trajectory.poses.back().rotation() * goal.rotation().transpose()).angle();
  EXPECT_LT(off, 1e-9);
  EXPECT_TRUE(verifyByDkpContinuation(hexaglide(), trajectory, plan.sign).passed);
}

}  // namespace
}  // namespace maximal_workspace
