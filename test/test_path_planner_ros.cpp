// path_planner through ROS, on the delta-like robot at 10 mm from its reference
// configuration (working mode npn): the chapter's Fig. 14 situation, a path inside one
// region, refusals with their reasons, the published path and markers, and a planner
// without a workspace server or with a lying one. Started by test/path_planner.test. The poses below were
// picked for their properties, which test_planner checks in general: (0.775, 0.455,
// 0.075) is reached from the start through transitions only; (0.075, -0.065, 0.755) lies
// only in the other assembly mode; (0.065, -0.025, 0.725) is in the singular band of npn.

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

#include <gtest/gtest.h>
#include <nav_msgs/Path.h>
#include <ros/package.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <unistd.h>
#include <visualization_msgs/MarkerArray.h>

#include "maximal_workspace/ComputeWorkspace.h"
#include "maximal_workspace/PlanPath.h"
#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "cli_support.h"
#include "ros_test_support.h"

namespace maximal_workspace {
namespace {

using test::pose;

PlanPath::Request request(const geometry_msgs::Pose& start, const geometry_msgs::Pose& goal) {
  PlanPath::Request r;
  r.start = start;
  r.goal = goal;
  return r;
}

const geometry_msgs::Pose kReference = pose(0.15, 0.15, 0.75);
const geometry_msgs::Pose kFig14Goal = pose(0.775, 0.455, 0.075);

PlanPath::Response call(const PlanPath::Request& r, const std::string& service = "plan_path") {
  PlanPath srv;
  srv.request = r;
  EXPECT_TRUE(ros::service::call(service, srv)) << "the service call itself failed";
  return srv.response;
}

void expectRefused(const PlanPath::Request& r, const std::string& reason) {
  const PlanPath::Response response = call(r);
  EXPECT_FALSE(response.success) << reason;
  EXPECT_NE(response.message.find(reason), std::string::npos) << "expected '" << reason << "' in: " << response.message;
  EXPECT_TRUE(response.path.poses.empty());
}

TEST(PathPlanner, Fig14GoalIsReachedThroughTransitionsWithAVerifiedContinuousTrajectory) {
  const PlanPath::Response response = call(request(kReference, kFig14Goal));
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_TRUE(response.verified) << response.verification;
  ASSERT_GE(response.transitions.size(), 1u);
  const std::size_t samples = response.path.poses.size();
  ASSERT_GT(samples, 2u);
  ASSERT_EQ(response.working_modes.size(), samples);
  ASSERT_EQ(response.trajectory.points.size(), samples);
  EXPECT_EQ(response.trajectory.joint_names, (std::vector<std::string>{"KC1", "KC2", "KC3"}));
  EXPECT_NEAR(response.path.poses.front().pose.position.z, 0.75, 1e-12);
  EXPECT_NEAR(response.path.poses.back().pose.position.x, 0.775, 1e-12);
  EXPECT_EQ(response.working_modes.front(), "npn");
  for (const PathTransition& t : response.transitions) {
    ASSERT_GT(t.pose_index, 0u);
    ASSERT_LT(t.pose_index, samples);
    EXPECT_EQ(response.working_modes[t.pose_index], t.to_working_mode);
    EXPECT_EQ(response.working_modes[t.pose_index - 1], t.from_working_mode);
    EXPECT_EQ(t.chains.size(), 2u);  // a couple of the 4-PSS-2-RSS auxiliary
    EXPECT_EQ(t.label.substr(0, t.input.size()), t.input);
  }
  // Within the limits of config/path_planner.yaml, and no jump between samples.
  const std::vector<double> velocity = {1.0, 0.5, 0.5}, acceleration = {2.0, 1.0, 1.0};
  for (std::size_t k = 0; k < samples; ++k) {
    const auto& point = response.trajectory.points[k];
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_LE(std::abs(point.velocities[i]), velocity[i] * 1.0001);
      EXPECT_LE(std::abs(point.accelerations[i]), acceleration[i] * 1.0001);
      if (k == 0) continue;
      const auto& previous = response.trajectory.points[k - 1];
      const double dt = (point.time_from_start - previous.time_from_start).toSec();
      EXPECT_GT(dt, 0.0);
      EXPECT_LE(std::abs(point.positions[i] - previous.positions[i]), velocity[i] * dt * 1.5 + 1e-9) << "sample " << k;
    }
  }
  EXPECT_GT(response.length, 0.9);  // at least the straight distance
  EXPECT_GE(response.min_measure, 1e-3);
}

TEST(PathPlanner, OneWorkingModeAloneCannotJoinTheFig14Goal) {
  PlanPath::Request r = request(kReference, kFig14Goal);
  r.single_working_mode = true;
  expectRefused(r, "DKP singularity");
}

// One core function answers both: /plan_path and `mow plan` with the same request (the
// defaults of config/path_planner.yaml are mow's) give the same plan and the same refusal.
TEST(PathPlanner, GivesTheAnswerMowPlanGives) {
  const test::TempDir dir;
  auto mowPlan = [&](const std::string& goal) {
    return test::runMow({"plan", "--robot", ros::package::getPath("maximal_workspace") + "/config/delta_like.yaml",
                         "--step", "0.01", "--goal", goal, "--cache", dir.file("cache"), "--quiet"},
                        dir);
  };
  const PlanPath::Response planned = call(request(kReference, kFig14Goal));
  ASSERT_TRUE(planned.success) << planned.message;
  const test::RunResult mow = mowPlan("0.775,0.455,0.075");
  ASSERT_EQ(mow.exit_code, 0) << mow.out << mow.err;
  char length[32], measure[32];
  std::snprintf(length, sizeof length, "length %.4f m", planned.length);
  std::snprintf(measure, sizeof measure, "min |measure| %.4g", planned.min_measure);
  EXPECT_NE(mow.out.find(std::to_string(planned.transitions.size()) + " transitions, " + length), std::string::npos)
      << mow.out << " against " << length;
  EXPECT_NE(mow.out.find(measure), std::string::npos) << mow.out << " against " << measure;
  for (const PathTransition& t : planned.transitions) {
    EXPECT_NE(mow.out.find(t.label + " (" + t.from_working_mode + " -> " + t.to_working_mode + ")"), std::string::npos)
        << mow.out;
  }
  const PlanPath::Response refused = call(request(kReference, pose(0.075, -0.065, 0.755)));
  ASSERT_FALSE(refused.success);
  const test::RunResult no_plan = mowPlan("0.075,-0.065,0.755");
  EXPECT_EQ(no_plan.exit_code, 3);
  EXPECT_NE(no_plan.out.find("no plan: " + refused.message), std::string::npos) << no_plan.out << " against " << refused.message;
}

// Parameters out of their ranges (transition_cost -1, heuristic_weight 0,
// samples_per_segment 0, time_limit -5, service_timeout 1e9): the defaults, and the same plan.
TEST(PathPlanner, ParametersOutOfTheirRangesGiveWayToTheDefaults) {
  ASSERT_TRUE(ros::service::waitForService("/odd/plan_path", ros::Duration(30)));
  const PlanPath::Response odd = call(request(kReference, kFig14Goal), "/odd/plan_path");
  ASSERT_TRUE(odd.success) << odd.message;
  const PlanPath::Response usual = call(request(kReference, kFig14Goal));
  ASSERT_TRUE(usual.success) << usual.message;
  EXPECT_EQ(odd.length, usual.length);
  EXPECT_EQ(odd.trajectory.points.size(), usual.trajectory.points.size());
}

TEST(PathPlanner, GoalInTheStartRegionNeedsNoTransition) {
  const PlanPath::Response response = call(request(kReference, pose(0.25, 0.2, 0.65)));
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_TRUE(response.verified);
  EXPECT_TRUE(response.transitions.empty());
}

// As a user writes it: no start (no robot display runs here) and no orientation.
TEST(PathPlanner, WithoutAStartOrARobotDisplayItStartsAtTheReferenceConfiguration) {
  PlanPath::Request r;
  r.goal.position = pose(0.25, 0.2, 0.65).position;
  const PlanPath::Response response = call(r);
  ASSERT_TRUE(response.success) << response.message;
  const geometry_msgs::Point& start = response.path.poses.front().pose.position;
  EXPECT_DOUBLE_EQ(start.x, 0.15);
  EXPECT_DOUBLE_EQ(start.y, 0.15);
  EXPECT_DOUBLE_EQ(start.z, 0.75);
  EXPECT_EQ(response.working_modes.front(), "npn");  // the reference inputs' working mode
  EXPECT_NE(response.message.find("from the reference configuration"), std::string::npos) << response.message;
}

TEST(PathPlanner, StartInputsTellTheStartWorkingMode) {
  PlanPath::Request r = request(kReference, pose(0.25, 0.2, 0.65));
  r.start_inputs = {-2.1286070350306852, 0.6231, 0.4};  // the robot file's reference inputs
  const PlanPath::Response response = call(r);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.working_modes.front(), "npn");
  r.start_inputs = {0.2179737988, 0.6231, 0.4};  // the other root of KC1 (mow info): working mode ppn
  const PlanPath::Response other = call(r);
  ASSERT_TRUE(other.success) << other.message;
  EXPECT_EQ(other.working_modes.front(), "ppn");
  r.start_inputs = {0.0, 0.6231};
  expectRefused(r, "start_inputs: expected one value per input");
}

TEST(PathPlanner, RefusesWithTheReasonAndStaysUp) {
  expectRefused(request(kReference, pose(0.075, -0.065, 0.755)), "requires crossing a DKP singularity");
  PlanPath::Request outside = request(pose(0.9, 0.9, 0.7), kReference);
  outside.start_working_mode = "ppp";
  expectRefused(outside, "the start (0.9, 0.9, 0.7) is outside the workspace");
  expectRefused(request(kReference, pose(0.9, 0.9, 0.7)), "the goal (0.9, 0.9, 0.7) is outside the workspace");
  PlanPath::Request band = request(pose(0.065, -0.025, 0.725), kReference);
  band.start_working_mode = "npn";
  expectRefused(band, "closer to a DKP singularity of working mode npn than the clearance");
  PlanPath::Request unknown = request(kReference, kFig14Goal);
  unknown.start_working_mode = "pxp";
  expectRefused(unknown, "unknown working mode 'pxp'");
  PlanPath::Request goal_unknown = request(kReference, kFig14Goal);
  goal_unknown.goal_working_mode = "nnq";
  expectRefused(goal_unknown, "unknown working mode 'nnq'");
  PlanPath::Request turned = request(kReference, kFig14Goal);
  turned.goal.orientation.w = std::sqrt(0.5);
  turned.goal.orientation.z = std::sqrt(0.5);
  expectRefused(turned, "reference orientation");
  PlanPath::Request elsewhere = request(pose(0.2, 0.1, 0.7), kReference);
  expectRefused(elsewhere, "give the start working mode");
  PlanPath::Request bad_step = request(kReference, kFig14Goal);
  bad_step.step = -1.0;
  expectRefused(bad_step, "step of x");
  for (const double limit : {-1.0, 3601.0, std::nan("")}) {
    PlanPath::Request bad_limit = request(kReference, kFig14Goal);
    bad_limit.time_limit = limit;
    expectRefused(bad_limit, "time_limit must be in [0, 3600] s");
  }
  PlanPath::Request hurried = request(kReference, kFig14Goal);
  hurried.time_limit = 1e-9;
  expectRefused(hurried, "the time limit of 1e-09 s ran out");
  // Still up, and still right.
  const PlanPath::Response good = call(request(kReference, pose(0.25, 0.2, 0.65)));
  EXPECT_TRUE(good.success) << good.message;
}

TEST(PathPlanner, PublishesThePathAndItsMarkers) {
  ros::NodeHandle node;
  std::mutex mutex;
  std::condition_variable wake;
  nav_msgs::PathConstPtr path;
  visualization_msgs::MarkerArrayConstPtr markers;
  const ros::Subscriber path_subscriber = node.subscribe<nav_msgs::Path>("path_planner/path", 1, [&](const nav_msgs::PathConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    path = m;
    wake.notify_all();
  });
  const ros::Subscriber marker_subscriber =
      node.subscribe<visualization_msgs::MarkerArray>("path_planner/markers", 1, [&](const visualization_msgs::MarkerArrayConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        markers = m;
        wake.notify_all();
      });
  const PlanPath::Response response = call(request(kReference, kFig14Goal));
  ASSERT_TRUE(response.success) << response.message;
  std::unique_lock<std::mutex> lock(mutex);
  ASSERT_TRUE(wake.wait_for(lock, std::chrono::seconds(30), [&] {
    return path && markers && path->poses.size() == response.path.poses.size();
  }));
  EXPECT_EQ(path->header.frame_id, "base_link");
  int strips = 0;
  std::size_t spheres = 0, leader_ends = 0;
  std::vector<std::string> named, expected;
  for (const auto& m : markers->markers) {
    strips += m.ns == "path" && m.type == visualization_msgs::Marker::LINE_STRIP;
    spheres += m.ns == "transitions" && m.type == visualization_msgs::Marker::SPHERE;
    if (m.ns == "transition_leaders") leader_ends += m.points.size();
    // Labels of close transitions are merged, one line each.
    std::istringstream lines(m.text);
    for (std::string line; m.ns == "transition_labels" && std::getline(lines, line);) named.push_back(line);
  }
  EXPECT_EQ(strips, static_cast<int>(response.transitions.size()) + 1);  // one stretch per working mode used
  EXPECT_EQ(spheres, response.transitions.size());
  EXPECT_EQ(leader_ends, 2 * response.transitions.size()) << "a leader from its label to every sphere";
  for (const PathTransition& transition : response.transitions) expected.push_back(transition.label);
  std::sort(named.begin(), named.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(named, expected) << "every transition named once";
}

TEST(PathPlanner, WithoutAWorkspaceServerItSaysSoAfterItsTimeout) {
  const PlanPath::Response response = call(request(kReference, kFig14Goal), "lonely/plan_path");
  EXPECT_FALSE(response.success);
  EXPECT_NE(response.message.find("/lonely/compute_workspace is not available after 1 s"), std::string::npos)
      << response.message;
}

// Any process can answer /compute_workspace (issue 18): a reply naming a `mow workspace
// --out` folder of the same robot (a summary, no manifest) must not make the planner read
// it, or remove it as a broken cache entry; the planner looks up its own key in its
// server's cache.
TEST(PathPlanner, TakesNoPathFromTheWorkspaceServiceReply) {
  char pattern[] = "/tmp/mow_decoy_XXXXXX";
  ASSERT_NE(::mkdtemp(pattern), nullptr);
  const std::string decoy = pattern;
  const std::string robot = ros::package::getPath("maximal_workspace") + "/config/delta_like.yaml";
  const std::string hash = hex64(fnv1a64(readTextFile(robot, "robot file")));
  std::ofstream(decoy + "/summary.json") << R"({"robot": {"file": ")" << robot << R"(", "hash": ")" << hash
                                         << R"("}, "options": {"margin": 0.0}})" << "\n";
  ros::NodeHandle node;
  const ros::ServiceServer liar = node.advertiseService<ComputeWorkspace::Request, ComputeWorkspace::Response>(
      "liar/compute_workspace", [&decoy](ComputeWorkspace::Request&, ComputeWorkspace::Response& reply) {
        reply.success = true;
        reply.summary_file = decoy + "/summary.json";
        return true;
      });
  const PlanPath::Response response = call(request(kReference, kFig14Goal), "liar/plan_path");
  EXPECT_FALSE(response.success);
  EXPECT_NE(response.message.find("is not in the cache"), std::string::npos) << response.message;
  EXPECT_EQ(response.message.find(decoy), std::string::npos) << response.message;
  EXPECT_TRUE(std::filesystem::is_regular_file(decoy + "/summary.json"));
  std::filesystem::remove_all(decoy);
}

// A client that sets the server's cache_directory before a planner's first request (issue
// 28) must not move the planner's cache: it keeps the one it was started with, plans, and
// makes no directory where the parameter points.
TEST(PathPlanner, KeepsItsOwnCacheWhenAClientSetsTheServersCacheDirectory) {
  std::string server_cache;
  ASSERT_TRUE(ros::param::get("/workspace_server/cache_directory", server_cache));
  char pattern[] = "/tmp/mow_redirect_XXXXXX";
  ASSERT_NE(::mkdtemp(pattern), nullptr);
  const std::string elsewhere = std::string(pattern) + "/planted";
  ros::param::set("/workspace_server/cache_directory", elsewhere);
  const PlanPath::Response response = call(request(kReference, pose(0.2, 0.15, 0.75)), "redirected/plan_path");
  ros::param::set("/workspace_server/cache_directory", server_cache);
  EXPECT_TRUE(response.success) << response.message;
  EXPECT_FALSE(std::filesystem::exists(elsewhere));
  std::filesystem::remove_all(pattern);
}

// The workspaces a planner holds fit its memory_bytes: with a cap of one byte, going back
// to a step planned on before reads that workspace again; with the default cap it is held.
TEST(PathPlanner, HoldsTheWorkspacesItPlannedOnWithinItsMemoryCap) {
  ros::NodeHandle node;
  test::Latest<rosgraph_msgs::Log> log(node, "/rosout");
  const auto reads = [&log](const std::string& planner, const std::string& step) {
    int count = 0;
    for (const auto& line : log.all()) {
      count += line->name == planner && line->msg.find("workspace of delta_like, step " + step) != std::string::npos &&
               line->msg.find(" read from ") != std::string::npos;
    }
    return count;
  };
  ros::Duration(1.0).sleep();  // subscribed before the first plan
  for (const std::string planner : {"/small/path_planner", "/path_planner"}) {
    const std::string service = planner.substr(0, planner.size() - std::string("path_planner").size()) + "plan_path";
    for (double step : {0.03, 0.04, 0.03}) {
      PlanPath::Request r = request(kReference, pose(0.2, 0.15, 0.75));
      r.step = step;
      const PlanPath::Response response = call(r, service);
      EXPECT_TRUE(response.success) << planner << ", step " << step << ": " << response.message;
    }
  }
  ros::Duration(1.0).sleep();  // the last log lines through rosout
  EXPECT_EQ(reads("/small/path_planner", "0.03"), 2);
  EXPECT_EQ(reads("/small/path_planner", "0.04"), 1);
  EXPECT_EQ(reads("/path_planner", "0.03"), 1);
  EXPECT_EQ(reads("/path_planner", "0.04"), 1);
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "path_planner_test");
  ros::NodeHandle private_node("~");
  std::string cache;
  private_node.getParam("cache_directory", cache);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  if (!ros::service::waitForService("plan_path", ros::Duration(60))) {
    std::fprintf(stderr, "no /plan_path service\n");
    return 1;
  }
  const int result = RUN_ALL_TESTS();
  std::error_code ignored;
  std::filesystem::remove_all(cache, ignored);
  std::filesystem::remove_all(cache + "_liar", ignored);
  return result;
}
