// Goals as rviz users give them (test/goals.test): the workspace is shown at start;
// path_planner plans to a point of rviz's
// Publish Point tool (/clicked_point, in any frame tf knows) or of its goal interactive
// marker, from the robot's current configuration as robot_pose_publisher shows it, and the
// display plays the plan; /plan_path with the start left out starts there too; a goal
// outside the workspace is explained beside it in rviz.

#include <cmath>
#include <string>

#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <visualization_msgs/InteractiveMarkerFeedback.h>
#include <visualization_msgs/InteractiveMarkerInit.h>
#include <visualization_msgs/MarkerArray.h>

#include "label_layout.h"
#include "maximal_workspace/PlanPath.h"
#include "maximal_workspace/PlannedPath.h"
#include "maximal_workspace/RobotPose.h"
#include "maximal_workspace/SetRobotPose.h"
#include "ros_test_support.h"

namespace maximal_workspace {
namespace {

using test::Latest;

const geometry_msgs::Point kReference = [] {
  geometry_msgs::Point p;
  p.x = 0.15, p.y = 0.15, p.z = 0.75;  // config/delta_like.yaml's reference position
  return p;
}();
const geometry_msgs::Point kFig14Goal = [] {
  geometry_msgs::Point p;
  p.x = 0.775, p.y = 0.455, p.z = 0.075;  // the demo's goal, two transitions from the reference
  return p;
}();

double distance(const geometry_msgs::Point& a, const geometry_msgs::Point& b) {
  return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
}

class Goals : public ::testing::Test {
 protected:
  Goals()
      : paths_(node_, "path_planner/path"),
        plans_(node_, "path_planner/plan"),
        current_(node_, "robot_pose_publisher/current_pose"),
        markers_(node_, "path_planner/markers"),
        clicked_(node_.advertise<geometry_msgs::PointStamped>("clicked_point", 1)),
        feedback_(node_.advertise<visualization_msgs::InteractiveMarkerFeedback>("path_planner/goal/feedback", 1)) {}

  // Shows the robot at `where` in `working_mode` and waits until ~current_pose says so.
  void place(const geometry_msgs::Point& where, const std::string& working_mode) {
    SetRobotPose set;
    set.request.pose.position = where;
    set.request.working_mode = working_mode;
    ASSERT_TRUE(ros::service::call("robot_pose_publisher/set_pose", set));
    ASSERT_TRUE(set.response.success) << set.response.message;
    ASSERT_TRUE(current_.waitFor([&](const RobotPose& p) {
      return distance(p.pose.position, where) < 1e-9 && p.working_mode == working_mode;
    }));
  }

  // A path published after `since` from `start` to `goal`.
  boost::shared_ptr<const nav_msgs::Path> pathAfter(const ros::Time& since, const geometry_msgs::Point& start,
                                                    const geometry_msgs::Point& goal) {
    return paths_.waitFor([&](const nav_msgs::Path& path) {
      return path.header.stamp >= since && !path.poses.empty() && distance(path.poses.front().pose.position, start) < 1e-6 &&
             distance(path.poses.back().pose.position, goal) < 1e-6;
    });
  }

  // The plan reached the display, which plays it to its end.
  void expectPlayedTo(const ros::Time& since, const geometry_msgs::Point& goal) {
    EXPECT_TRUE(plans_.waitFor([&](const PlannedPath& plan) {
      return plan.play && plan.path.header.stamp >= since && distance(plan.path.poses.back().pose.position, goal) < 1e-6;
    })) << "no plan to play on /path_planner/plan";
    EXPECT_TRUE(current_.waitFor([&](const RobotPose& p) { return distance(p.pose.position, goal) < 1e-9; }, 60.0))
        << "the robot display never reached the goal";
  }

  // The path's markers with a note beside a goal, published after `since`.
  boost::shared_ptr<const visualization_msgs::MarkerArray> noteAfter(const ros::Time& since) {
    return markers_.waitFor([&](const visualization_msgs::MarkerArray& array) {
      for (const auto& marker : array.markers) {
        if (marker.ns == "goal_note" && marker.header.stamp >= since) return true;
      }
      return false;
    });
  }

  void click(const geometry_msgs::Point& point, const std::string& frame) {
    // A message sent before the planner's subscription is connected is lost.
    for (int tries = 0; tries < 100 && clicked_.getNumSubscribers() == 0; ++tries) ros::WallDuration(0.1).sleep();
    geometry_msgs::PointStamped message;
    message.header.frame_id = frame;
    message.header.stamp = ros::Time::now();
    message.point = point;
    clicked_.publish(message);
  }

  ros::NodeHandle node_;
  Latest<nav_msgs::Path> paths_;
  Latest<PlannedPath> plans_;
  Latest<RobotPose> current_;
  Latest<visualization_msgs::MarkerArray> markers_;
  ros::Publisher clicked_;
  ros::Publisher feedback_;
};

// planner.launch computes the default workspace at start (compute_at_start): a display
// shows it before anyone asks. First, before any test calls a service.
TEST_F(Goals, TheDefaultWorkspaceIsShownAtStartWithoutARequest) {
  Latest<visualization_msgs::MarkerArray> workspace(node_, "maximal_workspace/markers");
  EXPECT_TRUE(workspace.waitFor([](const visualization_msgs::MarkerArray& m) {
    for (const auto& marker : m.markers) {
      if (marker.ns == "maximal_positive" && marker.type == visualization_msgs::Marker::TRIANGLE_LIST &&
          !marker.points.empty()) {
        return true;
      }
    }
    return false;
  })) << "no workspace markers from compute_at_start";
}

TEST_F(Goals, APlanWithItsStartLeftOutStartsWhereTheRobotIs) {
  geometry_msgs::Point elsewhere;
  elsewhere.x = 0.2, elsewhere.y = 0.1, elsewhere.z = 0.7;
  place(elsewhere, "npn");
  PlanPath plan;
  plan.request.goal.position = kFig14Goal;  // orientation left out too: all zero
  ASSERT_TRUE(ros::service::call("plan_path", plan));
  ASSERT_TRUE(plan.response.success) << plan.response.message;
  EXPECT_LT(distance(plan.response.path.poses.front().pose.position, elsewhere), 1e-9);
  EXPECT_EQ(plan.response.working_modes.front(), "npn");
  EXPECT_NE(plan.response.message.find("from the robot's configuration"), std::string::npos) << plan.response.message;
}

TEST_F(Goals, AClickedPointIsPlannedFromTheRobotAndPlayed) {
  place(kReference, "npn");
  const ros::Time since = ros::Time::now();
  click(kFig14Goal, "base_link");
  const auto path = pathAfter(since, kReference, kFig14Goal);
  ASSERT_TRUE(path) << "no path from the robot to the clicked point on /path_planner/path";
  expectPlayedTo(since, kFig14Goal);
}

TEST_F(Goals, AClickedPointInAnotherFrameIsPutInTheBaseFrame) {
  // rviz's fixed frame may be any frame tf knows: here "table", 0.1 m along base x.
  tf2_ros::StaticTransformBroadcaster broadcaster;
  geometry_msgs::TransformStamped table;
  table.header.stamp = ros::Time::now();
  table.header.frame_id = "base_link";
  table.child_frame_id = "table";
  table.transform.translation.x = 0.1;
  table.transform.rotation.w = 1.0;
  broadcaster.sendTransform(table);
  ros::WallDuration(0.5).sleep();
  // From wherever the display shows the robot.
  const auto now = current_.waitFor([](const RobotPose&) { return true; });
  ASSERT_TRUE(now);
  const ros::Time since = ros::Time::now();
  geometry_msgs::Point in_table = kReference;
  in_table.x -= 0.1;
  click(in_table, "table");
  ASSERT_TRUE(pathAfter(since, now->pose.position, kReference)) << "no path to the point put in base_link";
  expectPlayedTo(since, kReference);
}

TEST_F(Goals, AGoalOutsideTheWorkspaceIsExplainedBesideIt) {
  geometry_msgs::Point outside;
  outside.x = 3.0, outside.y = 3.0, outside.z = 3.0;
  const ros::Time since = ros::Time::now();
  click(outside, "base_link");
  const auto markers = noteAfter(since);
  ASSERT_TRUE(markers) << "no note beside the goal on /path_planner/markers";
  for (const auto& marker : markers->markers) {
    if (marker.ns != "goal_note") continue;
    EXPECT_EQ(marker.type, visualization_msgs::Marker::TEXT_VIEW_FACING);
    EXPECT_NE(marker.text.find("no plan"), std::string::npos) << marker.text;
    EXPECT_NE(marker.text.find("outside"), std::string::npos) << marker.text;
    // Beside it: on the screen, its text ends a little left of the goal (the legend is on
    // the right), level with it.
    const ScreenAxes axes = ScreenAxes::defaultView();
    const Eigen::Vector2d goal = axes.project(Eigen::Vector3d(outside.x, outside.y, outside.z));
    const ScreenBox box = textBox(axes, Eigen::Vector3d(marker.pose.position.x, marker.pose.position.y, marker.pose.position.z),
                                  textSize(marker.text, marker.scale.z));
    EXPECT_LT(box.max().x(), goal.x());
    EXPECT_LT(goal.x() - box.max().x(), 0.3);
    EXPECT_LT(std::abs(box.center().y() - goal.y()), 0.5 * box.sizes().y());
  }
  // The last path stays drawn beside the note, and the planner still answers.
  bool path_kept = false;
  for (const auto& marker : markers->markers) path_kept = path_kept || marker.ns == "path";
  EXPECT_TRUE(path_kept);
  PlanPath plan;
  plan.request.goal.position = kFig14Goal;
  ASSERT_TRUE(ros::service::call("plan_path", plan));
  EXPECT_TRUE(plan.response.success) << plan.response.message;
}

// A clicked point with a NaN (issue 28): its explanation was placed at the NaN goal, where
// rviz never draws it; it stands at the base frame's origin.
TEST_F(Goals, ANonFiniteClickedPointIsExplainedWhereRvizCanShowIt) {
  geometry_msgs::Point nan_point;
  nan_point.x = std::nan(""), nan_point.y = 0.2, nan_point.z = 0.5;
  const ros::Time since = ros::Time::now();
  click(nan_point, "base_link");
  const auto markers = noteAfter(since);
  ASSERT_TRUE(markers) << "no note on /path_planner/markers";
  for (const auto& marker : markers->markers) {
    if (marker.ns != "goal_note") continue;
    EXPECT_NE(marker.text.find("must be finite"), std::string::npos) << marker.text;
    EXPECT_TRUE(std::isfinite(marker.pose.position.x) && std::isfinite(marker.pose.position.y) &&
                std::isfinite(marker.pose.position.z));
  }
}

TEST_F(Goals, AClickedPointInAFrameTfDoesNotKnowIsExplained) {
  const ros::Time since = ros::Time::now();
  click(kFig14Goal, "nowhere");
  const auto markers = noteAfter(since);
  ASSERT_TRUE(markers) << "no note beside the goal on /path_planner/markers";
  for (const auto& marker : markers->markers) {
    if (marker.ns == "goal_note") {
      EXPECT_NE(marker.text.find("frame 'nowhere'"), std::string::npos) << marker.text;
    }
  }
}

TEST_F(Goals, TheGoalMarkerIsOfferedAndPlannedWhenLetGo) {
  Latest<visualization_msgs::InteractiveMarkerInit> init(node_, "path_planner/goal/update_full");
  ASSERT_TRUE(init.waitFor([](const visualization_msgs::InteractiveMarkerInit& m) {
    return m.markers.size() == 1 && m.markers[0].name == "goal";
  })) << "no goal marker on path_planner/goal";
  place(kReference, "npn");
  const visualization_msgs::InteractiveMarkerFeedback released = test::goalMarkerReleased(kFig14Goal);
  const ros::Time since = ros::Time::now();
  for (int tries = 0; tries < 50 && feedback_.getNumSubscribers() == 0; ++tries) ros::WallDuration(0.1).sleep();
  feedback_.publish(released);
  ASSERT_TRUE(pathAfter(since, kReference, kFig14Goal)) << "no path to the released goal marker";
  expectPlayedTo(since, kFig14Goal);
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  return maximal_workspace::test::runRosTests(argc, argv, "goals_test", {"robot_pose_publisher/set_pose", "plan_path"});
}
