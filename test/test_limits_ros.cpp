// workspace_server and path_planner through ROS on a robot with limits (issue 16): the two
// delta examples, config/linear_delta.yaml and config/rotary_delta.yaml. One binary for both,
// started by test/limits_linear_delta.test and test/limits_rotary_delta.test, which give
// ~robot (the name of the robot the launch file selected), ~start and ~goal (the demo's
// path, config/demo/ROBOT.yaml) and ~cache_directory (removed at the end).
//
// Checked: /compute_workspace at 10 mm against the summary file it names, whose singularity
// map counts actuator-limit and cone walls; the latched /singularity_map has wall points
// (kinds 2 and 3) with their chains; the demo's path is planned and verified against the
// limits; a goal that needs an actuator outside its range is refused with the reason, and
// the planner stays up.

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "maximal_workspace/ComputeWorkspace.h"
#include "maximal_workspace/PlanPath.h"
#include "ros_test_support.h"

namespace maximal_workspace {
namespace {

using test::Latest;
using test::pose;

constexpr double kStep = 0.01;  // the step of the .test files' planner.launch
constexpr int kChains = 6;      // both deltas: three parallelograms of two chains

std::string g_robot;
std::vector<double> g_start, g_goal;

struct OutOfRange {
  std::array<double, 3> goal;
  std::string reason;  // the input and its range, as the planner names them
};

// A goal per robot that some actuator cannot reach within its range, whatever the working
// mode (as `mow plan --robot config/ROBOT.yaml --step 0.01 --goal X,Y,Z` answers, exit 3).
const std::map<std::string, OutOfRange> kOutOfRange = {
    // 0.65 m below the reference: every carriage would sit some 0.27 m below its rail's 0.
    {"linear_delta", {{0.0, 0.0, -0.5}, "is outside its limits [0, 0.531]"}},
    // Reachable by the leg lengths, but crank M1 would turn to 2.15 rad, past its 1.5708.
    {"rotary_delta", {{0.05, 0.05, -0.4}, "is outside its limits [-0.5978, 1.5708]"}},
};

ComputeWorkspace::Response computeWorkspace() {
  ComputeWorkspace srv;
  srv.request.step = kStep;  // no bounds: the safety box comes from the limits
  EXPECT_TRUE(ros::service::call("compute_workspace", srv)) << "the service call itself failed";
  return srv.response;
}

geometry_msgs::Pose at(const std::vector<double>& xyz) { return pose(xyz.at(0), xyz.at(1), xyz.at(2)); }

PlanPath::Response plan(const geometry_msgs::Pose& start, const geometry_msgs::Pose& goal) {
  PlanPath srv;
  srv.request.start = start;  // the robot file's reference position: its working mode is known
  srv.request.goal = goal;
  srv.request.step = kStep;
  EXPECT_TRUE(ros::service::call("plan_path", srv)) << "the service call itself failed";
  return srv.response;
}

bool endsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

TEST(Limits, LaunchFileSelectedTheNamedRobot) {
  for (const char* node : {"workspace_server", "path_planner"}) {
    std::string file;
    ASSERT_TRUE(ros::param::get(std::string("/") + node + "/robot_file", file)) << node;
    EXPECT_TRUE(endsWith(file, "/config/" + g_robot + ".yaml")) << node << ": " << file;
  }
}

TEST(Limits, WorkspaceWithoutBoundsEqualsItsSummaryAndCountsTheWalls) {
  const ComputeWorkspace::Response response = computeWorkspace();
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_GT(response.workspace_volume, 0.0);
  EXPECT_EQ(response.volume_unit, "m^3");
  std::ifstream file(response.summary_file);
  ASSERT_TRUE(file) << "cannot read " << response.summary_file;
  const nlohmann::json summary = nlohmann::json::parse(file);
  const double volume = summary.at("workspace").at("volume").get<double>();
  EXPECT_NEAR(response.workspace_volume, volume, 1e-9 * volume);
  const nlohmann::json& map = summary.at("singularity_map");
  const auto limit = map.at("actuator_limit_entries").get<unsigned long long>();
  const auto cone = map.at("joint_cone_entries").get<unsigned long long>();
  EXPECT_GT(limit + cone, 0u) << map.dump();
  std::printf("[limits] %s: workspace %.9g %s (%s), singularity map of the summary: %s\n", g_robot.c_str(),
              response.workspace_volume, response.volume_unit.c_str(), response.message.c_str(), map.dump().c_str());
}

TEST(Limits, SingularityMapHasActuatorAndConeWallsWithTheirChains) {
  ros::NodeHandle node;
  Latest<sensor_msgs::PointCloud2> clouds(node, "singularity_map");
  // The latched map of the one workspace this test asks for (the planner's is the same).
  const ComputeWorkspace::Response response = computeWorkspace();
  ASSERT_TRUE(response.success) << response.message;
  const auto cloud = clouds.waitFor([](const sensor_msgs::PointCloud2& c) { return c.width > 0; });
  ASSERT_TRUE(cloud) << "no /singularity_map";
  std::map<std::string, std::uint8_t> fields;
  for (const auto& field : cloud->fields) fields[field.name] = field.datatype;
  ASSERT_EQ(fields.count("kind"), 1u);
  ASSERT_EQ(fields.count("chain"), 1u);
  EXPECT_EQ(fields["kind"], sensor_msgs::PointField::UINT8);
  EXPECT_EQ(fields["chain"], sensor_msgs::PointField::INT8);
  std::array<std::size_t, 5> kinds{};  // DKP, IKP, actuator limit, joint cone, interference
  std::size_t bad_chains = 0;
  sensor_msgs::PointCloud2ConstIterator<std::uint8_t> kind(*cloud, "kind");
  sensor_msgs::PointCloud2ConstIterator<std::int8_t> chain(*cloud, "chain");
  for (; kind != kind.end(); ++kind, ++chain) {
    ASSERT_LE(*kind, 4) << "unknown kind";
    ++kinds[*kind];
    if (*kind >= 1 && (*chain < 0 || *chain >= kChains)) {
      if (bad_chains++ < 5) ADD_FAILURE() << "kind " << int(*kind) << " with chain " << int(*chain);
    }
  }
  EXPECT_EQ(bad_chains, 0u);
  EXPECT_GT(kinds[2], 0u) << "no actuator-limit point";
  EXPECT_GT(kinds[3], 0u) << "no joint-cone point";
  std::printf("[limits] %s: /singularity_map of %u points: DKP %zu, IKP %zu, actuator limit %zu, joint cone %zu, "
              "interference %zu\n",
              g_robot.c_str(), cloud->width * cloud->height, kinds[0], kinds[1], kinds[2], kinds[3], kinds[4]);
}

TEST(Limits, DemoPathIsPlannedAndVerifiedWithinTheLimits) {
  const PlanPath::Response response = plan(at(g_start), at(g_goal));
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_TRUE(response.verified) << response.verification;
  EXPECT_NE(response.verification.find("smallest margins to the robot's limits"), std::string::npos)
      << response.verification;
  ASSERT_GE(response.path.poses.size(), 2u);
  EXPECT_NEAR(response.path.poses.front().pose.position.x, g_start[0], 1e-12);
  EXPECT_NEAR(response.path.poses.back().pose.position.y, g_goal[1], 1e-12);
  EXPECT_NEAR(response.path.poses.back().pose.position.z, g_goal[2], 1e-12);
  EXPECT_EQ(response.trajectory.points.size(), response.path.poses.size());
  std::printf("[limits] %s: demo plan: %s\n[limits] %s: verification: %s\n", g_robot.c_str(), response.message.c_str(),
              g_robot.c_str(), response.verification.c_str());
}

TEST(Limits, GoalNeedingAnActuatorOutOfRangeIsRefusedAndThePlannerStaysUp) {
  const auto known = kOutOfRange.find(g_robot);
  ASSERT_NE(known, kOutOfRange.end()) << "no out-of-range goal for robot '" << g_robot << "'";
  const auto& [xyz, reason] = known->second;
  const PlanPath::Response refused = plan(at(g_start), pose(xyz[0], xyz[1], xyz[2]));
  EXPECT_FALSE(refused.success);
  EXPECT_NE(refused.message.find("breaks a limit of the robot"), std::string::npos) << refused.message;
  EXPECT_NE(refused.message.find(reason), std::string::npos) << "expected '" << reason << "' in: " << refused.message;
  EXPECT_TRUE(refused.path.poses.empty());
  std::printf("[limits] %s: refused: %s\n", g_robot.c_str(), refused.message.c_str());
  // Still up, and still right.
  const PlanPath::Response good = plan(at(g_start), at(g_goal));
  EXPECT_TRUE(good.success) << good.message;
  EXPECT_TRUE(good.verified) << good.verification;
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "limits_test");
  ros::NodeHandle private_node("~");
  std::string cache;
  private_node.getParam("cache_directory", cache);
  if (!private_node.getParam("robot", maximal_workspace::g_robot) ||
      !private_node.getParam("start", maximal_workspace::g_start) ||
      !private_node.getParam("goal", maximal_workspace::g_goal) || maximal_workspace::g_start.size() != 3 ||
      maximal_workspace::g_goal.size() != 3) {
    std::fprintf(stderr, "give ~robot, and ~start and ~goal of 3 values each (config/demo/ROBOT.yaml)\n");
    return 1;
  }
  ros::AsyncSpinner spinner(2);
  spinner.start();
  for (const char* service : {"compute_workspace", "plan_path"}) {
    if (!ros::service::waitForService(service, ros::Duration(60))) {
      std::fprintf(stderr, "no /%s service\n", service);
      return 1;
    }
  }
  const int result = RUN_ALL_TESTS();
  std::error_code ignored;
  if (!cache.empty()) std::filesystem::remove_all(cache, ignored);
  return result;
}
