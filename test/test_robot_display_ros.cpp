// robot_pose_publisher through ROS (test/robot_display.test): /joint_states covers every
// joint of the robot_description URDF, and forward kinematics over that URDF (urdfdom, not
// the kinematics core) closes every rod on its platform node, at the reference
// configuration, at poses set through the service and the topic in every working mode, and
// all along the playback of a plan, which must follow the plan's actuator trajectory and so
// change branch where the plan does.

#include <cmath>
#include <limits>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_srvs/Trigger.h>
#include <urdf_parser/urdf_parser.h>

#include "maximal_workspace/PlanPath.h"
#include "maximal_workspace/PlannedPath.h"
#include "maximal_workspace/RobotPose.h"
#include "maximal_workspace/SetRobotPose.h"
#include "maximal_workspace/model/robot_file.h"
#include "ros_test_support.h"
#include "urdf_kinematics.h"

namespace maximal_workspace {
namespace {

using test::Latest;
using test::pose;

RobotModel g_model;
urdf::ModelInterfaceSharedPtr g_urdf;

JointPositions positionsOf(const sensor_msgs::JointState& state) { return {state.name, state.position}; }

double value(const sensor_msgs::JointState& state, const std::string& name) {
  for (std::size_t j = 0; j < state.name.size(); ++j) {
    if (state.name[j] == name) return state.position[j];
  }
  ADD_FAILURE() << "no joint " << name << " in /joint_states";
  return std::numeric_limits<double>::quiet_NaN();
}

Eigen::Vector3d platformPosition(const sensor_msgs::JointState& state) {
  return Eigen::Vector3d(value(state, "platform_x"), value(state, "platform_y"), value(state, "platform_z"));
}

// The largest distance between a rod's far end and its platform node, by forward
// kinematics over the URDF tree.
double closureError(const sensor_msgs::JointState& state) {
  const auto frames = test::linkFrames(*g_urdf, positionsOf(state));
  const Eigen::Isometry3d& platform = frames.at(kPlatformLink);
  double worst = 0.0;
  for (const ChainPtr& chain : g_model.chains) {
    const Eigen::Vector3d rod_end = frames.at(rodLinkName(*chain)) * Eigen::Vector3d(chain->rodLength(), 0, 0);
    worst = std::max(worst, (rod_end - platform * chain->platformNode()).norm());
  }
  return worst;
}

bool near(const sensor_msgs::JointState& state, const Eigen::Vector3d& position) {
  for (const char* name : {"platform_x", "platform_y", "platform_z"}) {
    if (std::find(state.name.begin(), state.name.end(), name) == state.name.end()) return false;
  }
  return (platformPosition(state) - position).norm() < 1e-9;
}

// The first joint state published a timer period after `since` at `position`: it shows
// what was asked before `since`.
boost::shared_ptr<const sensor_msgs::JointState> shownAfter(Latest<sensor_msgs::JointState>& states, const ros::Time& since,
                                                            const Eigen::Vector3d& position) {
  const ros::Time after = since + ros::Duration(0.1);
  return states.waitFor([&](const sensor_msgs::JointState& s) { return s.header.stamp > after && near(s, position); });
}

SetRobotPose::Response setPose(const geometry_msgs::Pose& where, const std::string& working_mode) {
  SetRobotPose srv;
  srv.request.pose = where;
  srv.request.working_mode = working_mode;
  EXPECT_TRUE(ros::service::call("robot_pose_publisher/set_pose", srv)) << "the service call itself failed";
  return srv.response;
}

TEST(RobotDisplay, PublishesEveryUrdfJointAtTheReferenceConfigurationClosed) {
  ros::NodeHandle node;
  Latest<sensor_msgs::JointState> states(node, "joint_states");
  const auto state = states.waitFor([](const sensor_msgs::JointState&) { return true; });
  ASSERT_TRUE(state);
  const std::set<std::string> published(state->name.begin(), state->name.end());
  int movable = 0;
  for (const auto& [name, joint] : g_urdf->joints_) {
    if (joint->type == urdf::Joint::FIXED) continue;
    ++movable;
    EXPECT_TRUE(published.count(name)) << "URDF joint " << name << " missing from /joint_states";
  }
  EXPECT_EQ(published.size(), static_cast<std::size_t>(movable));
  // Nothing asked yet: the robot file's reference configuration (its pose and inputs).
  EXPECT_LT((platformPosition(*state) - g_model.reference.pose.position).norm(), 1e-12);
  for (std::size_t i = 0; i < g_model.inputs.size(); ++i) {
    for (int c : g_model.inputs[i].chains) {
      EXPECT_NEAR(value(*state, actuatorJointName(*g_model.chains[c])), g_model.reference.inputs[i], 1e-9);
    }
  }
  EXPECT_LT(closureError(*state), 1e-6);
}

TEST(RobotDisplay, SetPoseShowsEveryWorkingModeClosedOnItsOwnBranches) {
  ros::NodeHandle node;
  Latest<sensor_msgs::JointState> states(node, "joint_states");
  for (const geometry_msgs::Pose& where : {pose(0.2, 0.1, 0.7), pose(0.3, 0.3, 0.6)}) {
    const Eigen::Vector3d position(where.position.x, where.position.y, where.position.z);
    // Per input, the actuator value seen with each branch letter.
    std::vector<std::map<char, std::set<double>>> seen(g_model.inputs.size());
    for (const WorkingMode& mode : coupledWorkingModes(g_model)) {
      const SetRobotPose::Response response = setPose(where, mode.name);
      ASSERT_TRUE(response.success) << mode.name << ": " << response.message;
      const auto state = shownAfter(states, ros::Time::now(), position);
      ASSERT_TRUE(state) << mode.name;
      EXPECT_LT(closureError(*state), 1e-6) << mode.name;
      for (std::size_t i = 0; i < g_model.inputs.size(); ++i) {
        const std::vector<int>& chains = g_model.inputs[i].chains;
        const double leader = value(*state, actuatorJointName(*g_model.chains[chains.front()]));
        for (int c : chains) EXPECT_NEAR(value(*state, actuatorJointName(*g_model.chains[c])), leader, 1e-9);
        seen[i][mode.name[i]].insert(std::round(leader * 1e9) / 1e9);
      }
    }
    // Each letter is one IKP root of its input, the same in every working mode, and the two
    // roots differ away from the boundary; a slider's p root is the farther along its axis.
    for (std::size_t i = 0; i < g_model.inputs.size(); ++i) {
      ASSERT_EQ(seen[i]['p'].size(), 1u) << g_model.inputs[i].name;
      ASSERT_EQ(seen[i]['n'].size(), 1u) << g_model.inputs[i].name;
      const double p = *seen[i]['p'].begin(), n = *seen[i]['n'].begin();
      EXPECT_GT(std::abs(p - n), 1e-3) << g_model.inputs[i].name;
      if (g_model.chains[g_model.inputs[i].chains.front()]->inputKind() == InputKind::Prismatic) {
        EXPECT_GT(p, n) << g_model.inputs[i].name;
      }
    }
  }
}

TEST(RobotDisplay, RobotPoseTopicMovesTheRobot) {
  ros::NodeHandle node;
  Latest<sensor_msgs::JointState> states(node, "joint_states");
  ros::Publisher publisher = node.advertise<RobotPose>("robot_pose", 1, true);
  RobotPose message;
  message.pose = pose(0.1, 0.25, 0.8);
  message.working_mode = "ppn";
  publisher.publish(message);
  const auto state = states.waitFor([](const sensor_msgs::JointState& s) { return near(s, Eigen::Vector3d(0.1, 0.25, 0.8)); });
  ASSERT_TRUE(state);
  EXPECT_LT(closureError(*state), 1e-6);
}

TEST(RobotDisplay, BadPosesAreRefusedWithTheReasonAndTheNodeStaysUp) {
  struct Case {
    geometry_msgs::Pose where;
    std::string working_mode;
    std::string reason;
  };
  geometry_msgs::Pose turned = pose(0.2, 0.1, 0.7);
  turned.orientation.w = std::sqrt(0.5);
  turned.orientation.z = std::sqrt(0.5);
  geometry_msgs::Pose not_unit = pose(0.2, 0.1, 0.7);
  not_unit.orientation.w = 0.5;  // (0, 0, 0, 0) would be the orientation left out: the reference one
  const Case cases[] = {
      {pose(0.2, 0.1, 0.7), "pxp", "unknown working mode 'pxp'"},
      {pose(0.2, 0.1, 0.7), "", "unknown working mode ''"},
      {pose(0.15, 0.15, 2.0), "npn", "(0.15, 0.15, 2) is outside the workspace: chains "},
      {pose(std::nan(""), 0.1, 0.7), "npn", "position must be finite"},
      {turned, "npn", "reference orientation"},
      {not_unit, "npn", "unit quaternion"},
  };
  for (const Case& c : cases) {
    const SetRobotPose::Response response = setPose(c.where, c.working_mode);
    EXPECT_FALSE(response.success) << c.reason;
    EXPECT_NE(response.message.find(c.reason), std::string::npos) << "expected '" << c.reason << "' in: " << response.message;
  }
  EXPECT_TRUE(setPose(pose(0.2, 0.1, 0.7), "npn").success);
}

TEST(RobotDisplay, PlaybackFollowsThePlannedActuatorTrajectoryThroughItsTransitions) {
  std_srvs::Trigger play;
  ASSERT_TRUE(ros::service::call("robot_pose_publisher/play", play));
  EXPECT_FALSE(play.response.success);
  EXPECT_NE(play.response.message.find("no plan to play"), std::string::npos) << play.response.message;

  PlanPath plan;
  plan.request.start = pose(0.15, 0.15, 0.75);
  plan.request.goal = pose(0.775, 0.455, 0.075);  // the Fig. 14 situation: two transitions
  ASSERT_TRUE(ros::service::call("plan_path", plan));
  ASSERT_TRUE(plan.response.success) << plan.response.message;
  ASSERT_GE(plan.response.transitions.size(), 1u);

  ros::NodeHandle node;
  Latest<sensor_msgs::JointState> states(node, "joint_states");
  // The plan reaches the display on a latched topic: retry until it has it.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
  do {
    ASSERT_TRUE(ros::service::call("robot_pose_publisher/play", play));
    if (!play.response.success) ros::WallDuration(0.2).sleep();
  } while (!play.response.success && ros::WallTime::now() < deadline);
  ASSERT_TRUE(play.response.success) << play.response.message;
  const ros::Time started = ros::Time::now();
  const geometry_msgs::Point& goal = plan.response.path.poses.back().pose.position;
  ASSERT_TRUE(states.waitFor([&](const sensor_msgs::JointState& s) { return near(s, Eigen::Vector3d(goal.x, goal.y, goal.z)); }, 60.0));

  const auto& poses = plan.response.path.poses;
  const auto& trajectory = plan.response.trajectory;
  int samples = 0;
  double worst_closure = 0.0, worst_input = 0.0;
  for (const auto& state : states.all()) {
    if (state->header.stamp < started) continue;
    ++samples;
    worst_closure = std::max(worst_closure, closureError(*state));
    // The plan's sample nearest to the platform: the actuators must be near its inputs. A
    // wrong branch is off by the distance between the two IKP roots (0.6 m or 2.3 rad
    // here), except next to a transition, where the roots meet.
    const Eigen::Vector3d at = platformPosition(*state);
    std::size_t nearest = 0;
    double best = INFINITY;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const auto& p = poses[k].pose.position;
      const double d = (Eigen::Vector3d(p.x, p.y, p.z) - at).norm();
      if (d < best) best = d, nearest = k;
    }
    EXPECT_LT(best, 0.01);
    for (std::size_t i = 0; i < g_model.inputs.size(); ++i) {
      for (int c : g_model.inputs[i].chains) {
        const double q = value(*state, actuatorJointName(*g_model.chains[c]));
        worst_input = std::max(worst_input, std::abs(q - trajectory.points[nearest].positions[i]));
      }
    }
  }
  RecordProperty("playback_joint_states", samples);
  RecordProperty("playback_worst_closure_m", std::to_string(worst_closure));
  RecordProperty("playback_worst_actuator_deviation", std::to_string(worst_input));
  EXPECT_GT(samples, 10);
  EXPECT_LT(worst_closure, 1e-6);
  EXPECT_LT(worst_input, 0.05);
}

// Any node may publish on /path_planner/plan: a plan with unknown working-mode names or
// arrays of the wrong length, arriving during a playback, is refused with a log line and the
// display keeps running (it used to read past the arrays and crash).
TEST(RobotDisplay, ABadPlanDuringAPlaybackIsRefusedAndTheDisplayRuns) {
  PlanPath plan;
  plan.request.start = pose(0.15, 0.15, 0.75);
  plan.request.goal = pose(0.775, 0.455, 0.075);
  ASSERT_TRUE(ros::service::call("plan_path", plan));
  ASSERT_TRUE(plan.response.success) << plan.response.message;
  ros::NodeHandle node;
  ros::Publisher intruder = node.advertise<PlannedPath>("path_planner/plan", 1);
  for (int tries = 0; tries < 100 && intruder.getNumSubscribers() == 0; ++tries) ros::WallDuration(0.1).sleep();
  PlannedPath good;
  good.path = plan.response.path;
  good.working_modes = plan.response.working_modes;
  good.transitions = plan.response.transitions;
  good.trajectory = plan.response.trajectory;
  good.play = true;
  intruder.publish(good);
  ros::WallDuration(0.5).sleep();  // playing now

  PlannedPath unknown_modes = good;
  unknown_modes.working_modes.assign(good.working_modes.size(), "zzz");
  PlannedPath short_arrays = good;
  short_arrays.working_modes.resize(3);
  short_arrays.trajectory.points.resize(2);
  for (const PlannedPath& bad : {unknown_modes, short_arrays}) {
    intruder.publish(bad);
    ros::WallDuration(0.3).sleep();
  }
  // Still publishing, closed, and playing the good plan to its end.
  Latest<sensor_msgs::JointState> states(node, "joint_states");
  const geometry_msgs::Point& goal = good.path.poses.back().pose.position;
  const auto at_goal = states.waitFor(
      [&](const sensor_msgs::JointState& s) { return near(s, Eigen::Vector3d(goal.x, goal.y, goal.z)); }, 30.0);
  ASSERT_TRUE(at_goal) << "the display stopped, or stopped playing the good plan";
  EXPECT_LT(closureError(*at_goal), 1e-6);
  // And it still plays the good plan on request: the bad ones did not replace it.
  std_srvs::Trigger play;
  ASSERT_TRUE(ros::service::call("robot_pose_publisher/play", play));
  EXPECT_TRUE(play.response.success) << play.response.message;
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "robot_display_test");
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  std::string robot_file, description;
  private_node.getParam("robot_file", robot_file);
  if (!node.getParam("robot_description", description)) {
    std::fprintf(stderr, "no /robot_description parameter\n");
    return 1;
  }
  maximal_workspace::g_model = maximal_workspace::loadRobotFile(robot_file);
  maximal_workspace::g_urdf = urdf::parseURDF(description);
  if (!maximal_workspace::g_urdf) {
    std::fprintf(stderr, "/robot_description is not a URDF\n");
    return 1;
  }
  ros::AsyncSpinner spinner(2);
  spinner.start();
  if (!ros::service::waitForService("robot_pose_publisher/set_pose", ros::Duration(60)) ||
      !ros::service::waitForService("plan_path", ros::Duration(60))) {
    std::fprintf(stderr, "no robot_pose_publisher/set_pose or /plan_path service\n");
    return 1;
  }
  return RUN_ALL_TESTS();
}
