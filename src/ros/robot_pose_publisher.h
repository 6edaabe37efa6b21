#pragma once
// robot_pose_publisher: /joint_states for every joint of the URDF (mow urdf), so that
// robot_state_publisher and rviz show the robot assembled: at a TCP pose in a working mode
// (topic robot_pose, service ~set_pose), or playing back the last plan of path_planner
// (service ~play, or at once when the plan says so), switching branch at its transitions.
// What it shows goes out on ~current_pose (latched): path_planner plans from there when a
// request leaves its start out. Parameters, subscriptions,
// services and the publisher are declared in this one class.

#include <mutex>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include "maximal_workspace/PlannedPath.h"
#include "maximal_workspace/RobotPose.h"
#include "maximal_workspace/SetRobotPose.h"
#include "maximal_workspace/description/robot_description.h"

namespace maximal_workspace {

class RobotPosePublisher {
 public:
  RobotPosePublisher(ros::NodeHandle& node, ros::NodeHandle& private_node);

 private:
  // Shows the robot at a pose in a working mode; false (and why) when it cannot be.
  bool show(const geometry_msgs::Pose& pose, const std::string& working_mode, std::string* why);
  void onRobotPose(const RobotPose& message);
  void onPlan(const PlannedPath& plan);
  bool onSetPose(SetRobotPose::Request& request, SetRobotPose::Response& response);
  bool onPlay(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  // Why a received plan cannot be played (sizes, working modes, times), or "".
  std::string planProblem(const PlannedPath& plan) const;
  // Starts playing the last plan; false (and why) when there is none. Holds mutex_.
  bool startPlayback(std::string* message);
  void onTimer(const ros::TimerEvent& event);
  void publish(const Configuration& configuration, const std::string& working_mode);

  // Parameters (private namespace).
  Mechanism mechanism_ = Mechanism::Robot;
  double playback_speed_ = 1.0;

  RobotModel model_;
  std::vector<WorkingMode> modes_;

  // Interfaces.
  ros::Publisher joint_states_;
  ros::Publisher current_pose_;
  ros::Subscriber pose_subscriber_;
  ros::Subscriber plan_subscriber_;
  ros::ServiceServer set_pose_service_;
  ros::ServiceServer play_service_;
  ros::Timer timer_;

  std::mutex mutex_;
  Configuration shown_;       // what is published while nothing plays
  std::string shown_mode_;    // its working mode
  RobotPose last_current_;    // last sent on ~current_pose (the timer thread's alone)
  PlannedPath plan_;          // the last plan received that can be played
  bool playing_ = false;
  ros::Time playback_start_;
};

}  // namespace maximal_workspace
