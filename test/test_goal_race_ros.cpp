// Goals from rviz racing each other (issue 28, finding 1; test/goal_race.test): clicked
// points that plan, published while goal-marker MOUSE_UPs for a goal outside the workspace
// arrive. Each plan ends by moving the goal marker (the marker server's lock); the marker
// server calls its feedback callback under that same lock. Taken in opposite orders by
// the two spinner threads, the locks hung path_planner for good within 10 to 20 pairs; it
// must answer /plan_path within 1 s after 2,000 of each.

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <memory>
#include <optional>
#include <thread>

#include <geometry_msgs/PointStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <visualization_msgs/InteractiveMarkerFeedback.h>
#include <visualization_msgs/MarkerArray.h>

#include "maximal_workspace/PlanPath.h"
#include "ros_test_support.h"

namespace maximal_workspace {
namespace {

using test::pose;

constexpr int kPairs = 2000;

geometry_msgs::Point point(double x, double y, double z) {
  geometry_msgs::Point p;
  p.x = x, p.y = y, p.z = z;
  return p;
}

// Near the reference (0.15, 0.15, 0.75), in its region: a plan of a few milliseconds.
const geometry_msgs::Point kNearGoal = point(0.2, 0.1, 0.7);
const geometry_msgs::Point kOutside = point(3.0, 3.0, 3.0);

// /plan_path from the reference to `goal`, in a thread of its own: a hung planner must
// fail the test, not hang it. Empty when no answer came within `seconds`.
std::optional<PlanPath::Response> planWithin(const geometry_msgs::Point& goal, double seconds) {
  auto answer = std::make_shared<std::promise<PlanPath::Response>>();
  std::future<PlanPath::Response> future = answer->get_future();
  std::thread([answer, goal] {
    PlanPath srv;
    srv.request.start = pose(0.15, 0.15, 0.75);
    srv.request.goal.position = goal;
    srv.request.goal.orientation.w = 1.0;
    if (!ros::service::call("plan_path", srv)) srv.response.message = "the service call itself failed";
    answer->set_value(srv.response);
  }).detach();  // left blocked on a hung planner
  if (future.wait_for(std::chrono::duration<double>(seconds)) != std::future_status::ready) return std::nullopt;
  return future.get();
}

TEST(GoalRace, ClickedPointsRacingGoalMarkerReleasesLeaveThePlannerAnswering) {
  ros::NodeHandle node;
  // The workspace computed and held by the planner before the race.
  const auto warm = planWithin(kNearGoal, 120.0);
  ASSERT_TRUE(warm) << "no answer to the first /plan_path";
  ASSERT_TRUE(warm->success) << warm->message;

  std::atomic<int> paths{0}, notes{0};
  const ros::Subscriber path_subscriber =
      node.subscribe<nav_msgs::Path>("path_planner/path", 100, [&](const nav_msgs::PathConstPtr&) { ++paths; });
  const ros::Subscriber marker_subscriber = node.subscribe<visualization_msgs::MarkerArray>(
      "path_planner/markers", 100, [&](const visualization_msgs::MarkerArrayConstPtr& markers) {
        for (const auto& marker : markers->markers) notes += marker.ns == "goal_note";
      });
  ros::Publisher clicked = node.advertise<geometry_msgs::PointStamped>("clicked_point", 100);
  ros::Publisher feedback = node.advertise<visualization_msgs::InteractiveMarkerFeedback>("path_planner/goal/feedback", 100);
  for (int tries = 0; tries < 100 && (clicked.getNumSubscribers() == 0 || feedback.getNumSubscribers() == 0); ++tries) {
    ros::WallDuration(0.1).sleep();
  }
  ASSERT_GT(clicked.getNumSubscribers(), 0u);
  ASSERT_GT(feedback.getNumSubscribers(), 0u);
  ros::WallDuration(0.5).sleep();  // the path and marker subscriptions connected

  geometry_msgs::PointStamped click;
  click.header.frame_id = "base_link";
  click.point = kNearGoal;
  visualization_msgs::InteractiveMarkerFeedback released = test::goalMarkerReleased(kOutside);
  const int paths_before = paths, notes_before = notes;
  for (int i = 0; i < kPairs; ++i) {
    click.header.stamp = released.header.stamp = ros::Time::now();
    clicked.publish(click);
    feedback.publish(released);
    // Paced over some seconds, so that planning on both threads overlaps throughout.
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const auto answered_at = std::chrono::steady_clock::now();
  const auto after = planWithin(point(0.25, 0.2, 0.65), 1.0);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - answered_at).count();
  std::printf("after %d clicked points and %d goal-marker releases: %d paths and %d notes published; /plan_path: %s "
              "after %.3f s\n",
              kPairs, kPairs, paths - paths_before, notes - notes_before, after ? "answered" : "no answer", seconds);
  ASSERT_TRUE(after) << "path_planner did not answer /plan_path within 1 s of the race: deadlocked";
  EXPECT_TRUE(after->success) << after->message;
  // Both kinds of goal were planned during the race: it raced.
  EXPECT_GT(paths - paths_before, 1);
  EXPECT_GT(notes - notes_before, 1);
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  const int result = maximal_workspace::test::runRosTests(argc, argv, "goal_race_test", {"plan_path"});
  // A detached call may still be blocked on a hung planner: leave without waiting for it.
  std::fflush(nullptr);
  std::_Exit(result);
}
