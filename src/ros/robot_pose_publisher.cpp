#include "robot_pose_publisher.h"

#include <cmath>

#include <Eigen/Geometry>
#include <ros/package.h>
#include <sensor_msgs/JointState.h>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/planner/plan_playback.h"
#include "workspace_messages.h"

namespace maximal_workspace {

RobotPosePublisher::RobotPosePublisher(ros::NodeHandle& node, ros::NodeHandle& private_node) {
  std::string robot_file;
  private_node.param<std::string>("robot_file", robot_file, ros::package::getPath("maximal_workspace") + "/config/delta_like.yaml");
  bool auxiliary = false;
  private_node.param("auxiliary", auxiliary, false);
  private_node.param("playback_speed", playback_speed_, playback_speed_);
  double rate = 30.0;
  private_node.param("rate", rate, rate);
  if (!(playback_speed_ > 0.0)) throw InputError("~playback_speed must be > 0");
  if (!(rate > 0.0)) throw InputError("~rate must be > 0");
  mechanism_ = auxiliary ? Mechanism::Auxiliary : Mechanism::Robot;
  model_ = loadRobotFile(robot_file);
  // The robot's working modes name the plans; the auxiliary also takes its own, per chain.
  modes_ = coupledWorkingModes(model_);
  if (auxiliary) {
    const std::vector<WorkingMode> uncoupled = uncoupledWorkingModes(model_);
    modes_.insert(modes_.end(), uncoupled.begin(), uncoupled.end());
  }

  // Start where the robot file says the robot is: the reference configuration.
  const IkpResult ikp = solveIkp(model_, model_.reference.pose);
  const WorkingModeIdentification found = identifyWorkingMode(model_, ikp, model_.reference.inputs);
  const WorkingMode& mode = !found.found ? modes_.front() : auxiliary || !found.coupled ? found.uncoupled : found.working_mode;
  shown_ = configurationOf(model_.reference.pose, ikp, mode);
  shown_mode_ = mode.name;

  joint_states_ = node.advertise<sensor_msgs::JointState>("joint_states", 10);
  current_pose_ = private_node.advertise<RobotPose>("current_pose", 1, true);
  pose_subscriber_ = node.subscribe("robot_pose", 1, &RobotPosePublisher::onRobotPose, this);
  plan_subscriber_ = node.subscribe("path_planner/plan", 1, &RobotPosePublisher::onPlan, this);
  set_pose_service_ = private_node.advertiseService("set_pose", &RobotPosePublisher::onSetPose, this);
  play_service_ = private_node.advertiseService("play", &RobotPosePublisher::onPlay, this);
  timer_ = node.createTimer(ros::Duration(1.0 / rate), &RobotPosePublisher::onTimer, this);
  ROS_INFO("robot_pose_publisher: %s (%s), %s in %s; joint_states at %.0f Hz", model_.name.c_str(),
           auxiliary ? "auxiliary" : "robot", vectorText(shown_.pose.position).c_str(), mode.name.c_str(), rate);
}

bool RobotPosePublisher::show(const geometry_msgs::Pose& pose, const std::string& working_mode, std::string* why) {
  int mode = 0;
  Pose target;
  try {
    mode = workingModeIndex(modes_, working_mode, "working_mode");
    target = referenceOrientationPose(requestPose(pose), model_, "pose");
  } catch (const InputError& error) {
    *why = error.what();
    return false;
  }
  const IkpResult ikp = solveIkp(model_, target);
  if (!ikp.assembled) {
    std::string chains;
    for (int c = 0; c < ikp.chain_count; ++c) {
      if (!ikp.chains[c].assembled) chains += (chains.empty() ? "" : " ") + model_.chains[c]->name();
    }
    *why = "the pose " + vectorText(target.position) + " is outside the workspace: chains " + chains + " cannot be assembled";
    return false;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  playing_ = false;
  shown_ = configurationOf(target, ikp, modes_[mode]);
  shown_mode_ = modes_[mode].name;
  return true;
}

void RobotPosePublisher::onRobotPose(const RobotPose& message) {
  std::string why;
  if (!show(message.pose, message.working_mode, &why)) ROS_WARN("robot_pose_publisher: %s", why.c_str());
}

void RobotPosePublisher::onPlan(const PlannedPath& plan) {
  // Any node may publish here: a plan is checked whole before it replaces the last one.
  const std::string problem = planProblem(plan);
  if (!problem.empty()) {
    ROS_WARN("robot_pose_publisher: a plan on %s refused: %s", plan_subscriber_.getTopic().c_str(), problem.c_str());
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  plan_ = plan;
  playing_ = false;  // a playback of the plan replaced stops where it is
  if (!plan.play) return;
  std::string message;
  startPlayback(&message);
  ROS_INFO("robot_pose_publisher: %s", message.c_str());
}

bool RobotPosePublisher::onSetPose(SetRobotPose::Request& request, SetRobotPose::Response& response) {
  response.success = show(request.pose, request.working_mode, &response.message);
  if (response.success) response.message = "shown";
  return true;
}

bool RobotPosePublisher::onPlay(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  std::lock_guard<std::mutex> lock(mutex_);
  response.success = startPlayback(&response.message);
  if (response.success) ROS_INFO("robot_pose_publisher: %s", response.message.c_str());
  return true;
}

std::string RobotPosePublisher::planProblem(const PlannedPath& plan) const {
  PlanToPlay checked;
  for (const auto& pose : plan.path.poses) {
    checked.positions.push_back({pose.pose.position.x, pose.pose.position.y, pose.pose.position.z});
  }
  checked.working_modes = plan.working_modes;
  for (const auto& point : plan.trajectory.points) checked.times.push_back(point.time_from_start.toSec());
  return planToPlayProblem(checked, modes_);
}

bool RobotPosePublisher::startPlayback(std::string* message) {
  if (plan_.path.poses.empty()) {
    *message = "no plan to play: call /plan_path first";
    return false;
  }
  playing_ = true;
  playback_start_ = ros::Time::now();
  const double duration = plan_.trajectory.points.back().time_from_start.toSec() / playback_speed_;
  *message = "playing " + std::to_string(plan_.path.poses.size()) + " poses in " + numberText(duration) + " s, " +
             plan_.working_modes.front() + " to " + plan_.working_modes.back();
  return true;
}

void RobotPosePublisher::onTimer(const ros::TimerEvent&) {
  Configuration configuration;
  std::string working_mode;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (playing_) {
      // Where the plan is now: between two poses, in the earlier pose's working mode (a
      // transition pose carries the new one, which the next stretch uses).
      const double t = (ros::Time::now() - playback_start_).toSec() * playback_speed_;
      const auto& points = plan_.trajectory.points;
      std::size_t k = 0;
      while (k + 2 < points.size() && points[k + 1].time_from_start.toSec() <= t) ++k;
      const double t0 = points[k].time_from_start.toSec(), t1 = points[k + 1].time_from_start.toSec();
      const double s = std::min(1.0, std::max(0.0, (t - t0) / std::max(1e-9, t1 - t0)));
      const geometry_msgs::Point& a = plan_.path.poses[k].pose.position;
      const geometry_msgs::Point& b = plan_.path.poses[k + 1].pose.position;
      Pose pose = model_.reference.pose;
      pose.position = Eigen::Vector3d(a.x + s * (b.x - a.x), a.y + s * (b.y - a.y), a.z + s * (b.z - a.z));
      const IkpResult ikp = solveIkp(model_, pose);
      if (ikp.assembled) {
        shown_ = configurationOf(pose, ikp, *findWorkingMode(modes_, plan_.working_modes[k]));
        shown_mode_ = plan_.working_modes[k];
      }
      if (t >= points.back().time_from_start.toSec()) {
        playing_ = false;
        shown_mode_ = plan_.working_modes.back();
        ROS_INFO("robot_pose_publisher: playback done, at %s in %s", vectorText(pose.position).c_str(),
                 plan_.working_modes.back().c_str());
      }
    }
    configuration = shown_;
    working_mode = shown_mode_;
  }
  publish(configuration, working_mode);
}

void RobotPosePublisher::publish(const Configuration& configuration, const std::string& working_mode) {
  const JointPositions joints = jointPositions(model_, mechanism_, configuration);
  sensor_msgs::JointState message;
  message.header.stamp = ros::Time::now();
  message.name = joints.names;
  message.position = joints.positions;
  joint_states_.publish(message);
  // ~current_pose is latched: sent when it changes, not at the joint states' rate.
  RobotPose current;
  current.pose.position = pointMessage(configuration.pose.position);
  const Eigen::Quaterniond q(configuration.pose.rotation());
  current.pose.orientation.w = q.w();
  current.pose.orientation.x = q.x();
  current.pose.orientation.y = q.y();
  current.pose.orientation.z = q.z();
  current.working_mode = working_mode;
  if (current != last_current_) {
    current_pose_.publish(current);
    last_current_ = current;
  }
}

}  // namespace maximal_workspace
