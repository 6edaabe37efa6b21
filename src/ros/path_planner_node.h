#pragma once
// The path_planner node: /plan_path over the core planner, on the workspace that
// workspace_server computes and caches for the requested step, read from that cache
// through the core's store under the key this node resolves itself. Parameters, the service
// and the publishers are declared in this one class.

#include <deque>
#include <memory>
#include <mutex>
#include <string>

#include <ros/ros.h>

#include "maximal_workspace/PlanPath.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/io/workspace_store.h"
#include "maximal_workspace/planner/path_planner.h"
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
  std::shared_ptr<const Loaded> workspace(double step);
  // Reads, once, the settings of the workspace_server node whose cache this planner reads.
  void readServerSettings();
  void publish(const PlanPath::Response& response, const std::vector<int>& modes);

  // Parameters (private namespace; config/path_planner.yaml).
  std::string robot_file_;
  std::string base_frame_;
  std::string workspace_server_;  // the node whose parameters say how requests resolve and where entries are
  double service_timeout_ = 10.0;
  InputLimits limits_;
  PlannerCosts costs_;
  double heuristic_weight_ = 1.5;
  int samples_per_segment_ = 64;

  // Interfaces.
  ros::NodeHandle node_;
  ros::ServiceServer plan_service_;
  ros::Publisher path_publisher_;
  ros::Publisher markers_publisher_;
  ros::Publisher plan_publisher_;

  // The server's settings, read at the first request: by the time it answers, it has set them.
  std::once_flag server_settings_read_;
  WorkspaceRequestDefaults request_defaults_;
  std::unique_ptr<WorkspaceStore> store_;  // over the server's cache; holds the analyses read
  // The last workspaces planned on, newest first, by cache key.
  static constexpr std::size_t kPlannersKept = 2;
  std::mutex planners_mutex_;
  std::deque<std::pair<std::string, std::shared_ptr<const Loaded>>> planners_;
  std::mutex publish_mutex_;
};

}  // namespace maximal_workspace
