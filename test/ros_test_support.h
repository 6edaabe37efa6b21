#pragma once
// Helpers shared by the tests that run against ROS nodes (rostest).

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include <geometry_msgs/Pose.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <visualization_msgs/InteractiveMarkerFeedback.h>

namespace maximal_workspace::test {

// A pose at the robots' reference orientation (the identity).
inline geometry_msgs::Pose pose(double x, double y, double z) {
  geometry_msgs::Pose p;
  p.position.x = x;
  p.position.y = y;
  p.position.z = z;
  p.orientation.w = 1.0;
  return p;
}

// What rviz sends when path_planner's goal marker is let go at `at`.
inline visualization_msgs::InteractiveMarkerFeedback goalMarkerReleased(const geometry_msgs::Point& at) {
  visualization_msgs::InteractiveMarkerFeedback released;
  released.header.frame_id = "base_link";
  released.client_id = "/rviz/Goal";
  released.marker_name = "goal";
  released.control_name = "move_3d";
  released.event_type = visualization_msgs::InteractiveMarkerFeedback::MOUSE_UP;
  released.pose.position = at;
  released.pose.orientation.w = 1.0;
  return released;
}

// main() of a rostest gtest whose tests call services: the node must be started (a
// NodeHandle) and spinning for the replies and subscriptions. `services` must come up
// within 60 s each; `before` reads the test's private parameters, `after` cleans up.
inline int runRosTests(int argc, char** argv, const char* node_name, const std::vector<std::string>& services = {},
                       const std::function<void(const ros::NodeHandle&)>& before = {},
                       const std::function<void()>& after = {}) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, node_name);
  ros::NodeHandle node;
  if (before) before(ros::NodeHandle("~"));
  ros::AsyncSpinner spinner(2);
  spinner.start();
  for (const std::string& service : services) {
    if (!ros::service::waitForService(service, ros::Duration(60))) {
      std::fprintf(stderr, "no %s service after 60 s\n", service.c_str());
      return 1;
    }
  }
  const int result = RUN_ALL_TESTS();
  if (after) after();
  // The launch file's server cache goes with the test: a run at fine steps leaves gigabytes.
  std::string cache;
  if (ros::param::get("/workspace_server/cache_directory", cache) && cache.rfind("/tmp/mow_", 0) == 0) {
    std::error_code ignored;
    std::filesystem::remove_all(cache, ignored);
  }
  return result;
}

// runRosTests for a test of workspace_server: its ~cache_directory and ~robot_file go to
// the given strings, and the cache (and the "_broken" server's beside it) is removed after.
inline int runServerTests(int argc, char** argv, const char* node_name, const char* service,
                          std::string& cache_directory, std::string& robot_file) {
  return runRosTests(
      argc, argv, node_name, {service},
      [&](const ros::NodeHandle& private_node) {
        private_node.getParam("cache_directory", cache_directory);
        private_node.getParam("robot_file", robot_file);
      },
      [&] {
        std::error_code ignored;
        std::filesystem::remove_all(cache_directory, ignored);
        std::filesystem::remove_all(cache_directory + "_broken", ignored);
      });
}

// The last messages of a topic, kept for the tests to wait on.
template <class Message>
class Latest {
 public:
  Latest(ros::NodeHandle& node, const std::string& topic)
      : subscriber_(node.subscribe(topic, 10, &Latest::receive, this)) {}

  // Waits for a message for which `accept` holds (messages received before included).
  boost::shared_ptr<const Message> waitFor(const std::function<bool(const Message&)>& accept, double seconds = 60.0) {
    std::unique_lock<std::mutex> lock(mutex_);
    boost::shared_ptr<const Message> found;
    wake_.wait_for(lock, std::chrono::duration<double>(seconds), [&] {
      for (auto it = received_.rbegin(); it != received_.rend(); ++it) {
        if (accept(**it)) {
          found = *it;
          return true;
        }
      }
      return false;
    });
    return found;
  }
  std::vector<boost::shared_ptr<const Message>> all() {
    std::lock_guard<std::mutex> lock(mutex_);
    return received_;
  }

 private:
  void receive(const boost::shared_ptr<const Message>& message) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      received_.push_back(message);
    }
    wake_.notify_all();
  }
  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<boost::shared_ptr<const Message>> received_;
  // Last: made after, and shut down before, what its callbacks use. A latched topic calls
  // back on a spinner thread as soon as the subscription is made; declared first, that
  // callback pushed into a vector not yet constructed (a heap corruption seen once in CI).
  ros::Subscriber subscriber_;
};

}  // namespace maximal_workspace::test
