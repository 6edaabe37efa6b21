// The planner on the delta-like robot: a path inside one region, the chapter's Fig. 14
// situation (a goal no single working mode joins to the start), a goal only in the other
// assembly mode, bad starts and goals; the actuator trajectory's continuity and limits;
// and the DKP-continuation verification, including a plan it must reject; on the linear
// delta, plans that keep the robot's limits and a verification that holds them to them.

#include <algorithm>
#include <cmath>
#include <optional>
#include <regex>

#include <gtest/gtest.h>

#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/planner/path_planner.h"
#include "maximal_workspace/planner/path_request.h"
#include "maximal_workspace/planner/trajectory.h"
#include "maximal_workspace/planner/verification.h"
#include "fig14_goal.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

// With this margin the delta-like robot's regions have the chapter's Fig. 14 situation:
// goals that transitions reach and no single working mode does (the exact regions are
// larger, and join more in one working mode).
constexpr double kThreshold = 1e-3;

const WorkspaceAnalysis& analysis() {
  static const WorkspaceAnalysis result = [] {
    const GridSpec spec = test::referenceGrid(test::deltaLike(), 0.01);
    AnalysisOptions options;
    options.margin = kThreshold;
    return analyseWorkspace(test::deltaLike(), spec, options);
  }();
  return result;
}

const PathPlanner& planner() {
  static const PathPlanner result(test::deltaLike(), analysis());
  return result;
}

Pose at(const Eigen::Vector3d& position) {
  Pose pose = test::deltaLike().reference.pose;
  pose.position = position;
  return pose;
}

Pose cellPose(std::uint64_t cell) { return analysis().grid().pose(cell); }

// The grid cell of the reference pose, where the analysis starts.
std::uint64_t startCell() {
  std::uint64_t cell = 0;
  EXPECT_TRUE(analysis().grid().cellOf(test::deltaLike().reference.pose, &cell));
  return cell;
}

// The assembly mode of working mode `mode` at a cell (its region's sign); 0 in the
// singular band or outside the workspace.
std::int8_t signAt(std::uint64_t cell, int mode) {
  const std::int32_t label = analysis().label(cell, mode);
  return label < 0 ? 0 : analysis().regions()[label].sign;
}

PlanRequest fromReference(const Pose& goal) {
  PlanRequest request;
  request.start = test::deltaLike().reference.pose;
  request.start_mode = analysis().startMode();
  request.goal = goal;
  return request;
}

const InputLimits kLimits{{1.0, 0.5, 0.5}, {2.0, 1.0, 1.0}};

std::uint64_t fig14Goal() { return test::fig14Goal(analysis()); }

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
  ASSERT_TRUE(analysis().grid().cellOf(goal, &cell));
  ASSERT_GE(analysis().label(startCell(), analysis().startMode()), 0);
  ASSERT_EQ(analysis().label(cell, analysis().startMode()), analysis().label(startCell(), analysis().startMode()));
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
  const std::uint64_t goal_cell = fig14Goal();
  ASSERT_NE(goal_cell, 0u) << "no goal that only transitions reach: the premise of the test";
  const Pose goal = cellPose(goal_cell);
  // The traditional way, one working mode: no path.
  PlanRequest single = fromReference(goal);
  single.allowed_modes = {analysis().startMode()};
  const Plan traditional = planner().plan(single);
  EXPECT_FALSE(traditional.success);
  EXPECT_NE(traditional.message.find("DKP singularity"), std::string::npos) << traditional.message;
  // Through the maximal workspace: a path with at least one transition.
  const Plan plan = planner().plan(fromReference(goal));
  ASSERT_TRUE(plan.success) << plan.message;
  ASSERT_FALSE(plan.transitions.empty());
  for (const PlanTransition& t : plan.transitions) {
    const std::string& from = analysis().modes()[t.from_mode].name;
    const std::string& to = analysis().modes()[t.to_mode].name;
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
  const Plan plan = planner().plan(fromReference(cellPose(fig14Goal())));
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
  const std::int8_t sign = signAt(startCell(), a.startMode());
  ASSERT_NE(sign, 0);
  for (std::uint64_t cell = 0; cell < a.grid().cellCount(); ++cell) {
    bool same = false, other = false;
    for (int m = 0; m < static_cast<int>(a.modes().size()); ++m) {
      same = same || signAt(cell, m) == sign;
      other = other || signAt(cell, m) == -sign;
    }
    if (same || !other) continue;
    const Plan plan = planner().plan(fromReference(cellPose(cell)));
    EXPECT_FALSE(plan.success);
    EXPECT_NE(plan.message.find("requires crossing a DKP singularity"), std::string::npos) << plan.message;
    return;
  }
  FAIL() << "no cell only in the other assembly mode: the premise of the test";
}

TEST(Planner, StartOrGoalOutsideOrOnASingularityIsRefusedWithTheReason) {
  const Pose far = at(Eigen::Vector3d(0.9, 0.9, 0.7));
  PlanRequest outside_start = fromReference(test::deltaLike().reference.pose);
  outside_start.start = far;
  EXPECT_NE(planner().plan(outside_start).message.find("the start (0.9, 0.9, 0.7) is outside the workspace"),
            std::string::npos);
  EXPECT_NE(planner().plan(fromReference(far)).message.find("the goal (0.9, 0.9, 0.7) is outside the workspace"),
            std::string::npos);
  // A start in the singular band of its working mode: a workspace cell that the mode
  // labels with no region.
  const WorkspaceAnalysis& a = analysis();
  for (std::uint64_t cell = 0; cell < a.grid().cellCount(); ++cell) {
    if (!a.inside(cell)) continue;
    for (int mode = 0; mode < static_cast<int>(a.modes().size()); ++mode) {
      if (a.label(cell, mode) >= 0) continue;
      PlanRequest request = fromReference(test::deltaLike().reference.pose);
      request.start = cellPose(cell);
      request.start_mode = mode;
      const Plan plan = planner().plan(request);
      EXPECT_FALSE(plan.success);
      EXPECT_EQ(plan.refusal, PlanRefusal::Start);
      // In the analysis's band: under the clearance, or under the sign's tolerance.
      const std::string name = a.modes()[mode].name;
      EXPECT_TRUE(plan.message.find("closer to a DKP singularity of working mode " + name + " than the clearance") !=
                      std::string::npos ||
                  plan.message.find("on a DKP singularity of working mode " + name) != std::string::npos)
          << plan.message;
      return;
    }
  }
  FAIL() << "no cell in the singular band";
}

// The analysis varies x y z at the reference orientation: a goal or start turned away
// from it is not on its grid (it used to be planned as if it were, or refused with a
// witness of nothing).
TEST(Planner, AStartOrGoalOffTheAnalysisFixedVariablesIsRefusedNamingIt) {
  Pose turned = test::deltaLike().reference.pose;
  turned.euler_zyz[0] += 0.1;
  const Plan goal = planner().plan(fromReference(turned));
  EXPECT_FALSE(goal.success);
  EXPECT_EQ(goal.refusal, PlanRefusal::Request);
  EXPECT_NE(goal.message.find("the goal's phi is 0.1 but the analysis fixes it at 0 (it varies x y z only)"), std::string::npos)
      << goal.message;
  PlanRequest start = fromReference(test::deltaLike().reference.pose);
  start.start = turned;
  EXPECT_NE(planner().plan(start).message.find("the start's phi is 0.1"), std::string::npos);
}

TEST(Verification, RejectsAPlanThroughADkpSingularity) {
  // A straight line from the start in its working mode to the nearest cell where that
  // mode has the other sign: assembled all along, but through det J_DKP = 0.
  const WorkspaceAnalysis& a = analysis();
  const int mode = a.startMode();
  const Pose start = test::deltaLike().reference.pose;
  const std::int8_t sign = signAt(startCell(), mode);
  ASSERT_NE(sign, 0);
  std::uint64_t across = 0;
  double nearest = INFINITY;
  for (std::uint64_t cell = 0; cell < a.grid().cellCount(); ++cell) {
    const Eigen::Vector3d end = cellPose(cell).position;
    const double distance = (end - start.position).norm();
    if (signAt(cell, mode) != -sign || distance >= nearest) continue;
    bool assembled = true;
    for (int k = 0; k <= 200 && assembled; ++k) {
      assembled = solveIkp(test::deltaLike(), at(start.position + k / 200.0 * (end - start.position))).assembled;
    }
    if (assembled) {
      nearest = distance;
      across = cell;
    }
  }
  ASSERT_LT(nearest, INFINITY);
  Plan crossing;
  crossing.success = true;
  crossing.sign = sign;
  crossing.waypoints = {{start, mode}, {cellPose(across), mode}};
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
  // Its end: an entry of the singularity map where the start's working mode is
  // DKP-singular beside the start's sign, and itself has the other sign.
  const WorkspaceAnalysis& a = analysis();
  const int mode = a.startMode();
  const std::int8_t sign = signAt(startCell(), mode);
  ASSERT_NE(sign, 0);
  std::optional<std::uint64_t> across;
  a.forEachSingularity([&](const SingularityEntry& entry) {
    if (across || entry.kind != SingularityEntry::Kind::Dkp || !(entry.modes >> mode & 1u)) return;
    if (signAt(entry.cell, mode) == -sign) across = entry.cell;
  });
  ASSERT_TRUE(across) << "no DKP-singular cell of the start's working mode";
  EXPECT_LT(planner().checkSegment(test::deltaLike().reference.pose, cellPose(*across), mode, sign, kThreshold), 0.0);
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

// The linear delta (rails at stroke [0, 0.531] m): a plan to a goal inside its limits, whose
// verification reports the smallest input margin; the same trajectory checked against a
// stroke that its own inputs leave must fail; a goal below the stroke gets no plan.
TEST(PlannerLimits, PlansKeepTheStrokeAndTheVerificationHoldsThemToIt) {
  const std::string text = readTextFile(test::sourcePath("config/linear_delta.yaml"), "robot file");
  const RobotModel model = parseRobotFile(text, "linear_delta.yaml");
  AnalysisOptions at_clearance;  // plans are made on the analysis whose margin is their clearance
  at_clearance.margin = kDefaultPlanClearance;
  const WorkspaceAnalysis workspace = analyseWorkspace(model, test::referenceGrid(model, 0.01), at_clearance);
  const PathPlanner linear(model, workspace);
  PlanRequest request;
  request.start = model.reference.pose;
  request.start_mode = workspace.startMode();
  request.goal = request.start;
  request.goal.position = Eigen::Vector3d(0.08, -0.06, 0.05);
  const Plan plan = linear.plan(request);
  ASSERT_TRUE(plan.success) << plan.message;
  const InputLimits speeds{{0.5, 0.5, 0.5}, {1.0, 1.0, 1.0}};
  const InputTrajectory trajectory = inputTrajectory(model, workspace, plan, speeds);
  // The smallest margin to [0, 0.531] over the samples, from the trajectory's own inputs.
  double expected = INFINITY, lowest = INFINITY;
  for (const std::vector<double>& q : trajectory.q) {
    for (double value : q) {
      expected = std::min({expected, value - 0.0, 0.531 - value});
      lowest = std::min(lowest, value);
    }
  }
  const Verification verification = verifyByDkpContinuation(model, trajectory, plan.sign);
  ASSERT_TRUE(verification.passed) << verification.message;
  EXPECT_NEAR(verification.min_input_margin, expected, 1e-12);
  EXPECT_GT(verification.min_input_margin, 0.0);
  EXPECT_NE(verification.message.find("smallest margins to the robot's limits"), std::string::npos);

  // A stroke starting 1 mm over the lowest input the trajectory uses (the path goes down
  // from the reference, whose inputs stay inside).
  const std::string shorter = std::regex_replace(text, std::regex(R"(limits: \[0(\.0)?, 0\.531\])"),
                                                 "limits: [" + std::to_string(lowest + 1e-3) + ", 0.531]");
  ASSERT_NE(shorter, text);
  const Verification refused = verifyByDkpContinuation(parseRobotFile(shorter, "shorter.yaml"), trajectory, plan.sign);
  EXPECT_FALSE(refused.passed);
  EXPECT_NE(refused.message.find("breaks a limit"), std::string::npos) << refused.message;
  EXPECT_NE(refused.message.find("is outside its limits"), std::string::npos) << refused.message;

  // On the axis a carriage sits 0.2307 m above the TCP (0.3807 m at the reference, z = 0.15):
  // at z = -0.5 it would be at -0.269 m, under its stroke in every working mode.
  request.goal.position = Eigen::Vector3d(0.0, 0.0, -0.5);
  const Plan below = linear.plan(request);
  EXPECT_FALSE(below.success);
  EXPECT_NE(below.message.find("breaks a limit of the robot"), std::string::npos) << below.message;
}

// A request pose whose orientation was left out holds a zero quaternion: it stands for the
// reference orientation; any other quaternion must be a unit one.
TEST(PathRequests, AnOrientationLeftOutIsTheReferenceOne) {
  RequestPose left_out;
  left_out.position = {0.2, 0.1, 0.7};
  left_out.orientation = {0.0, 0.0, 0.0, 0.0};
  const Pose pose = referenceOrientationPose(left_out, test::deltaLike(), "goal");
  EXPECT_EQ(pose.position, Eigen::Vector3d(0.2, 0.1, 0.7));
  EXPECT_EQ(pose.euler_zyz, test::deltaLike().reference.pose.euler_zyz);
  RequestPose half = left_out;
  half.orientation = {0.5, 0.0, 0.0, 0.0};
  try {
    referenceOrientationPose(half, test::deltaLike(), "goal");
    ADD_FAILURE() << "a quaternion of norm 0.5 was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("goal: orientation must be a unit quaternion"), std::string::npos)
        << error.what();
  }
}

// A start is left out only when nothing of it was given: a start at the base origin in the
// reference orientation (w = 1), or one named by its inputs or working mode, is a start.
TEST(PathRequests, AStartIsLeftOutOnlyWhenNothingOfItIsGiven) {
  PathRequest request;
  request.start.orientation = {0.0, 0.0, 0.0, 0.0};
  EXPECT_TRUE(startLeftOut(request));
  PathRequest origin = request;
  origin.start.orientation = {1.0, 0.0, 0.0, 0.0};
  EXPECT_FALSE(startLeftOut(origin));
  PathRequest moved = request;
  moved.start.position[2] = 0.5;
  EXPECT_FALSE(startLeftOut(moved));
  PathRequest named = request;
  named.start_working_mode = "npn";
  EXPECT_FALSE(startLeftOut(named));
  PathRequest inputs = request;
  inputs.start_inputs = {0.0, 0.0, 0.0};
  EXPECT_FALSE(startLeftOut(inputs));
}

}  // namespace
}  // namespace maximal_workspace
