#pragma once
// The path_planner node: /plan_path over the core planner, on the workspace that
// workspace_server computes and caches for the requested step, read from that cache
// through the core's store under the key this node resolves itself. Goals also come from
// rviz: its Publish Point tool (/clicked_point) and an interactive marker; they are planned
// from the robot's current configuration (robot_pose_publisher's ~current_pose) and played
// back. Parameters, the service, the subscriptions and the publishers are declared in this
// one class.

#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <geometry_msgs/PointStamped.h>
#include <interactive_markers/interactive_marker_server.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include "label_layout.h"
#include "maximal_workspace/PlanPath.h"
#include "maximal_workspace/RobotPose.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/io/workspace_store.h"
#include "maximal_workspace/planner/path_planner.h"
#include "maximal_workspace/planner/path_request.h"
#include "maximal_workspace/planner/planning.h"
#include "maximal_workspace/planner/trajectory.h"

namespace maximal_workspace {

class PathPlannerNode {
 public:
  PathPlannerNode(ros::NodeHandle& node, ros::NodeHandle& private_node);

 private:
  // A workspace in memory with its planner (the planner keeps references into it).
  struct Loaded {
    std::shared_ptr<const RobotModel> model;
    std::shared_ptr<const WorkspaceAnalysis> analysis;
    std::unique_ptr<PathPlanner> planner;
  };

  bool onPlanPath(PlanPath::Request& request, PlanPath::Response& response);
  // The service's work; `play`: the robot display plays the plan at once.
  void plan(PlanPath::Request request, PlanPath::Response& response, bool play);
  // A goal picked in rviz, in `frame`: planned from the current configuration; a failure
  // is shown beside the goal and logged.
  void planToGoal(const geometry_msgs::Point& goal, const std::string& frame, const std::string& source);
  // A start left out: the robot's current configuration, else the reference one; says which.
  std::string startFromTheRobot(const RobotModel& model, PathRequest& request);
  // The trajectory settings of this node's parameters.
  PlanSettings planSettings(const RobotModel& model) const;
  void onClickedPoint(const geometry_msgs::PointStamped& point);
  // A goal with a NaN or an infinity: explained at the base frame's origin, and true.
  bool refusedNonFinite(const geometry_msgs::Point& goal, const std::string& source);
  void onGoalMarker(const visualization_msgs::InteractiveMarkerFeedbackConstPtr& feedback);
  // The goal marker's goals handed over by onGoalMarker, planned on a spinner thread.
  void planMarkerGoals();
  void onCurrentPose(const RobotPose& pose);
  // The workspace at the request's step and orientation set and at `margin` (0 for the step
  // or the margin: the server's default), computed by workspace_server if needed, and its
  // planner.
  std::shared_ptr<const Loaded> workspace(const PlanPath::Request& plan, double margin);
  // Opens, once, the cache of the workspace_server node whose entries this planner reads.
  void openServerCache();
  void publish(const RobotModel& model, const PlanPath::Response& response, const std::vector<int>& modes,
               double workspace_size, bool play);
  // The last path's markers with a text beside a goal that has no plan (empty: none).
  // The caller holds publish_mutex_.
  void publishMarkers(const std::string& goal_note, const geometry_msgs::Point& goal);
  // The goal marker to goal_pose_; the caller must not hold publish_mutex_.
  void moveGoalMarker();

  // Parameters (private namespace; config/path_planner.yaml).
  std::string robot_file_;
  std::string base_frame_;
  std::string workspace_server_;  // the node whose parameters say how requests resolve
  std::string cache_directory_;   // the cache that server computes into (read at start)
  double service_timeout_ = 10.0;
  InputLimits limits_;
  PlannerCosts costs_;
  double heuristic_weight_ = 1.5;
  double time_limit_ = kDefaultPlanTimeLimit;  // s, for requests that set none
  int samples_per_segment_ = 64;

  // Interfaces.
  ros::NodeHandle node_;
  ros::ServiceServer plan_service_;
  ros::Publisher path_publisher_;
  ros::Publisher markers_publisher_;
  ros::Publisher plan_publisher_;
  ros::Subscriber clicked_point_;
  ros::Subscriber current_pose_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_{tf_buffer_};
  std::unique_ptr<interactive_markers::InteractiveMarkerServer> goal_marker_;

  // The server's cache (cache_directory_), opened at the first request. The server's request
  // defaults are read at every request (they can change).
  std::once_flag server_cache_opened_;
  std::unique_ptr<WorkspaceStore> store_;  // over the server's cache
  // The last workspaces planned on, newest first, by cache key, within memory_bytes_.
  std::uint64_t memory_bytes_ = WorkspaceStore::kDefaultMemoryBytes;
  std::mutex planners_mutex_;
  std::deque<std::pair<std::string, std::shared_ptr<const Loaded>>> planners_;
  std::mutex publish_mutex_;
  visualization_msgs::MarkerArray path_markers_;  // the last plan's, shown again beside a goal note; publish_mutex_
  // Its labels and spheres on the screen, which a note avoids, and the depth (view
  // coordinates) of the robot's front, where labels go; publish_mutex_.
  std::vector<ScreenBox> label_boxes_;
  double label_depth_ = -std::numeric_limits<double>::infinity();
  geometry_msgs::Pose goal_pose_;                  // where the last plan ends; publish_mutex_
  std::uint64_t goal_pose_version_ = 0;            // plans published; publish_mutex_
  // The goal marker's newest goal not yet planned, and whether a spinner thread has it in
  // hand (planMarkerGoals). Never held while planning or calling the marker server.
  struct MarkerGoal {
    geometry_msgs::Point position;
    std::string frame;
  };
  std::mutex marker_goal_mutex_;
  std::optional<MarkerGoal> marker_goal_;
  bool marker_goal_queued_ = false;
  std::mutex current_mutex_;
  RobotPose current_;  // the robot display's configuration; empty working mode: none received
};

}  // namespace maximal_workspace
