// A plan request end to end (planner/planning.h): refusals that name their witness and are
// true (a plan at the clearance they name is made and verified, one at twice that is not),
// a time budget that runs out, the clearance and the analysis it is planned on, and a
// planar robot whose grid turns a full turn of phi.

#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>
#include <memory>

#include <gtest/gtest.h>

#include "fig14_goal.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/planner/planning.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

// A robot file at one step, planned on from its reference configuration: its analyses by
// margin, made once.
class Planning {
 public:
  Planning(const std::string& robot_file, double step)
      : model_(std::make_shared<const RobotModel>(loadRobotFile(test::sourcePath(robot_file)))), step_(step) {}

  const RobotModel& model() const { return *model_; }
  std::shared_ptr<const WorkspaceAnalysis> at(double margin) const {
    auto& analysis = (*made_)[margin];
    if (!analysis) {
      AnalysisOptions options;
      options.margin = margin;
      analysis = std::make_shared<const WorkspaceAnalysis>(analyseWorkspace(*model_, test::referenceGrid(*model_, step_), options));
    }
    return analysis;
  }
  PlanSettings settings() const {
    PlanSettings result;
    for (const Input& input : model_->inputs) {  // 1 rad/s, 2 rad/s^2 for cranks; 0.5 m/s, 1 m/s^2 for sliders
      result.limits.velocity.push_back(input.kind == InputKind::Revolute ? 1.0 : 0.5);
      result.limits.acceleration.push_back(input.kind == InputKind::Revolute ? 2.0 : 1.0);
    }
    result.request_margin = 0.0;
    result.analysis_at = [this](double margin) { return at(margin); };
    return result;
  }
  PlanRequest fromReference(const Pose& goal, double clearance) const {
    PlanRequest request;
    request.start = model_->reference.pose;
    request.start_mode = at(clearance)->startMode();
    request.goal = goal;
    request.clearance = clearance;
    return request;
  }
  PlanOutcome planAt(double clearance, const Pose& goal) const {
    const PathPlanner planner(*model_, *at(clearance));
    return planPath(*model_, planner, fromReference(goal, clearance), settings());
  }

 private:
  std::shared_ptr<const RobotModel> model_;
  double step_;
  std::shared_ptr<std::map<double, std::shared_ptr<const WorkspaceAnalysis>>> made_ =
      std::make_shared<std::map<double, std::shared_ptr<const WorkspaceAnalysis>>>();
};

const Planning& deltaLike() {
  static const Planning planning("config/delta_like.yaml", 0.01);
  return planning;
}

// The start's assembly mode and group in an analysis.
std::pair<std::int8_t, std::int32_t> startGroup(const WorkspaceAnalysis& analysis) {
  std::uint64_t start = 0;
  analysis.grid().cellOf(analysis.grid().spec().start, &start);
  const std::int32_t region = analysis.label(start, analysis.startMode());
  return {analysis.regions()[region].sign, analysis.transitions().component[region]};
}

// The group of a cell's regions of sign `sign` other than the start's, or -1 (none, or one
// of them in the start's group).
std::int32_t otherGroup(const WorkspaceAnalysis& analysis, std::uint64_t cell, std::int8_t sign, std::int32_t start_group) {
  std::int32_t group = -1;
  for (int m = 0; m < static_cast<int>(analysis.modes().size()); ++m) {
    const std::int32_t label = analysis.label(cell, m);
    if (label < 0 || analysis.regions()[label].debris || analysis.regions()[label].sign != sign) continue;
    if (analysis.transitions().component[label] == start_group) return -1;
    group = analysis.transitions().component[label];
  }
  return group;
}

// Goals the analysis at the default clearance does not join to the start are refused with
// the narrowest place of the widest exact route. Each refusal is true: where it names a
// clearance, a plan at it is made and verified and one at twice it is not; where the step
// does not resolve the neck (the analysis joins two cells across a thin singular layer), it
// names none (the delta-like robot's necks at 10 mm are such). Some goal of the Clavel
// delta has a neck that plans.
TEST(Planning, AGoalNotJoinedAtTheClearanceNamesTheNeckAndTheClearanceThatPlans) {
  int named = 0, unresolved = 0;
  const std::vector<std::tuple<std::string, double, double>> cases = {
      {"config/delta_like.yaml", 0.01, kDefaultPlanClearance}, {"config/clavel_delta.yaml", 0.01, 0.005}};
  for (const auto& [robot, step, clearance] : cases) {
    const Planning planning(robot, step);
    const WorkspaceAnalysis& at_clearance = *planning.at(clearance);
    const auto [sign, start_group] = startGroup(at_clearance);
    const Grid& grid = at_clearance.grid();
    std::set<std::int32_t> groups_tried;
    for (std::uint64_t cell = 0; cell < grid.cellCount(); cell += 7) {
      const std::int32_t group = otherGroup(at_clearance, cell, sign, start_group);
      // One goal per group, two groups per case: each branch is seen, in seconds.
      if (group < 0 || !groups_tried.insert(group).second) continue;
      if (groups_tried.size() > 2) break;
      const PlanOutcome refused = planning.planAt(clearance, grid.pose(cell));
      ASSERT_FALSE(refused.success) << robot;
      ASSERT_EQ(refused.plan.refusal, PlanRefusal::NotJoined) << robot << ": " << refused.message;
      if (std::isnan(refused.workable_clearance)) {
        EXPECT_NE(refused.message.find("the step does not resolve the place"), std::string::npos) << refused.message;
        ++unresolved;
        continue;
      }
      if (refused.workable_clearance == 0.0) continue;  // not joined exactly either
      ++named;
      EXPECT_LT(refused.workable_clearance, clearance);
      EXPECT_NE(refused.message.find("the widest route of the exact analysis narrows to |measure| "), std::string::npos)
          << refused.message;
      EXPECT_NE(refused.message.find("a clearance of at most " + numberText(refused.workable_clearance) + " plans"),
                std::string::npos)
          << refused.message;
      const PlanOutcome planned = planning.planAt(refused.workable_clearance, grid.pose(cell));
      EXPECT_TRUE(planned.success) << robot << ": " << planned.message;
      EXPECT_TRUE(planned.verification.passed) << planned.verification.message;
      const PlanOutcome twice = planning.planAt(2.0 * refused.workable_clearance, grid.pose(cell));
      EXPECT_FALSE(twice.success) << robot << ": a clearance of twice the one named still plans: it was not the largest";
      std::printf("%s at %g m, clearance %g, goal %s: %s\n", robot.c_str(), step, clearance, vectorText(grid.pose(cell).position).c_str(), refused.message.c_str());
    }
  }
  std::printf("necks named with the clearance that plans: %d; necks the step does not resolve: %d\n", named, unresolved);
  EXPECT_GT(named, 0) << "no goal whose neck plans: the premise of the test";
}

// A goal whose every working mode of the start's sign is closer to a DKP singularity than
// the clearance: refused with its own |measure|.
TEST(Planning, AGoalCloserThanTheClearanceIsRefusedWithItsOwnMeasure) {
  const WorkspaceAnalysis& exact = *deltaLike().at(0.0);
  const auto [sign, start_group] = startGroup(exact);
  const PoseClassifier classifier(test::deltaLike(), exact.modes(), exact.grid().spec().start, true);
  std::vector<double> measures(exact.modes().size());
  for (std::uint64_t cell = 0; cell < exact.grid().cellCount(); cell += 3) {
    if (!exact.inside(cell) || !classifier.classify(exact.grid().pose(cell), measures.data())) continue;
    double largest = 0.0;
    for (double measure : measures) {
      if (bandedSign(measure, 0.0) == sign) largest = std::max(largest, std::abs(measure));
    }
    if (!(largest > 0.0 && largest < 0.5 * kDefaultPlanClearance)) continue;
    const PlanOutcome refused = deltaLike().planAt(kDefaultPlanClearance, exact.grid().pose(cell));
    EXPECT_FALSE(refused.success);
    EXPECT_EQ(refused.plan.refusal, PlanRefusal::GoalClearance) << refused.message;
    EXPECT_NEAR(refused.plan.goal_measure, largest, 1e-12);
    EXPECT_NE(refused.message.find("closer to a DKP singularity than the clearance"), std::string::npos) << refused.message;
    EXPECT_NE(refused.message.find("no clearance above " + numberText(largest)), std::string::npos) << refused.message;
    return;
  }
  FAIL() << "no cell nearer than half the clearance to a singularity in every mode of the start's sign";
}

TEST(Planning, ATimeBudgetThatRunsOutIsARefusalThatSaysSo) {
  const PathPlanner planner(test::deltaLike(), *deltaLike().at(kDefaultPlanClearance));
  const std::uint64_t goal = test::fig14Goal(planner.analysis());
  ASSERT_NE(goal, 0u);
  PlanRequest request = deltaLike().fromReference(planner.analysis().grid().pose(goal), kDefaultPlanClearance);
  request.time_limit = 1e-9;
  const PlanOutcome refused = planPath(test::deltaLike(), planner, request, deltaLike().settings());
  EXPECT_FALSE(refused.success);
  EXPECT_EQ(refused.plan.refusal, PlanRefusal::TimeLimit);
  EXPECT_NE(refused.message.find("the time limit of 1e-09 s ran out"), std::string::npos) << refused.message;
  request.time_limit = kDefaultPlanTimeLimit;
  EXPECT_TRUE(planPath(test::deltaLike(), planner, request, deltaLike().settings()).success);
}

// The planner is complete relative to the analysis whose margin is the clearance: asked
// for more, it says which analysis to plan on.
TEST(Planning, AClearanceAboveTheMarginOfTheAnalysisIsRefused) {
  const PathPlanner planner(test::deltaLike(), *deltaLike().at(kDefaultPlanClearance));
  const PlanRequest request = deltaLike().fromReference(test::deltaLike().reference.pose, 2.0 * kDefaultPlanClearance);
  const Plan plan = planner.plan(request);
  EXPECT_EQ(plan.refusal, PlanRefusal::Request);
  EXPECT_NE(plan.message.find("plan on the analysis at margin 0.002"), std::string::npos) << plan.message;
  EXPECT_EQ(planningMargin(0.0, 0.002), 0.002);
  EXPECT_EQ(planningMargin(0.005, 0.002), 0.005);
}

// The planar 3-RRR over x y phi (test/robots/planar_3rrr.yaml), its grid a full turn of phi:
// two cells on either side of phi = +/-pi are neighbours, and a plan between them turns
// the short way, through the seam, not a full turn back.
TEST(Planning, APlanarRobotPlansAcrossTheSeamOfAFullTurn) {
  const RobotModel robot = loadRobotFile(test::sourcePath("test/robots/planar_3rrr.yaml"));
  GridSpec spec;
  spec.variables = {OutputVariable::X, OutputVariable::Y, OutputVariable::Phi};
  spec.steps = {0.01, 0.01, 0.05};
  spec.start = robot.reference.pose;
  AnalysisOptions options;
  options.margin = kDefaultPlanClearance;
  const PathPlanner planner(robot, analyseWorkspace(robot, spec, options));
  const WorkspaceAnalysis& analysis = planner.analysis();
  const Grid& grid = analysis.grid();
  ASSERT_TRUE(grid.periodic(2));
  const std::pair<std::int8_t, std::int32_t> start = startGroup(analysis);  // clang 14 lambdas cannot take bindings
  const std::int8_t sign = start.first;
  const std::int32_t start_group = start.second;
  auto reachableMode = [&](std::uint64_t cell) {
    for (int m = 0; m < static_cast<int>(analysis.modes().size()); ++m) {
      const std::int32_t label = analysis.label(cell, m);
      if (label >= 0 && !analysis.regions()[label].debris && analysis.regions()[label].sign == sign &&
          analysis.transitions().component[label] == start_group) {
        return m;
      }
    }
    return -1;
  };
  PlanSettings planar;
  planar.limits = InputLimits{{1.0, 1.0, 1.0}, {2.0, 2.0, 2.0}};
  for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
    GridCell at = grid.cell(cell);
    if (at[2] != 0) continue;
    at[2] = grid.size(2) - 1;
    const std::uint64_t across = grid.index(at);
    const int mode = reachableMode(cell), across_mode = reachableMode(across);
    if (mode < 0 || across_mode != mode || analysis.label(cell, mode) != analysis.label(across, mode)) continue;
    PlanRequest request;
    request.start = grid.pose(cell);
    request.start_mode = mode;
    request.goal = grid.pose(across);
    request.goal_mode = mode;
    const PlanOutcome outcome = planPath(robot, planner, request, planar);
    ASSERT_TRUE(outcome.success) << outcome.message;
    // One phi step (0.05 rad, at most as long as the characteristic length makes it), not 2 pi.
    EXPECT_LT(outcome.plan.length, 0.05 * robot.characteristic_length * 1.01);
    EXPECT_LT(std::abs(outcome.trajectory.poses.back().euler_zyz[0] - outcome.trajectory.poses.front().euler_zyz[0]), 0.051);
    return;
  }
  FAIL() << "no pair of cells across the seam in one region of a reachable working mode";
}

}  // namespace
}  // namespace maximal_workspace
