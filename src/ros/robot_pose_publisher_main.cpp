// robot_pose_publisher: see robot_pose_publisher.h.

#include <ros/ros.h>

#include "maximal_workspace/model/input_error.h"
#include "robot_pose_publisher.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "robot_pose_publisher");
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  try {
    maximal_workspace::RobotPosePublisher publisher(node, private_node);
    ros::AsyncSpinner spinner(2);
    spinner.start();
    ros::waitForShutdown();
  } catch (const maximal_workspace::InputError& error) {
    // A display with no robot to show has nothing to do: say why and stop.
    ROS_FATAL("robot_pose_publisher: %s", error.what());
    return 1;
  }
  return 0;
}
