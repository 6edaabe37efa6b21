#pragma once
// The workspace_server node: /compute_workspace over the core library, its cache, and the
// latched topics that show the last result. Parameters, services and publishers are
// declared in this one class (octomap_server's habit).

#include <condition_variable>
#include <deque>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "maximal_workspace/ComputeWorkspace.h"
#include "maximal_workspace/io/display_sampling.h"
#include "maximal_workspace/io/workspace_request.h"

namespace maximal_workspace {

class WorkspaceServer {
 public:
  WorkspaceServer(ros::NodeHandle& node, ros::NodeHandle& private_node);
  ~WorkspaceServer();
  WorkspaceServer(const WorkspaceServer&) = delete;
  WorkspaceServer& operator=(const WorkspaceServer&) = delete;

 private:
  // A request checked and resolved: what to compute and under which cache key.
  struct Prepared : ResolvedWorkspaceRequest {
    std::shared_ptr<const RobotModel> model;
    std::string robot_text;
  };
  // What obtaining a result gave: a cache entry, and the analysis when computed here.
  struct Outcome {
    bool success = false;
    std::string message;
    std::string entry;
    bool from_cache = false;
    bool shared = false;  // joined an identical computation already running
    double seconds = 0.0;
    std::shared_ptr<const WorkspaceAnalysis> analysis;
  };
  struct PublishJob {
    std::string signature;  // entry and assembly-mode filter
    std::string key;
    std::string entry;
    std::int8_t assembly_mode = 0;
    std::shared_ptr<const RobotModel> model;
    std::shared_ptr<const WorkspaceAnalysis> analysis;  // null: read workspace.bin
  };

  bool onComputeWorkspace(ComputeWorkspace::Request& request, ComputeWorkspace::Response& response);
  Prepared prepare(const ComputeWorkspace::Request& request) const;
  Outcome obtain(Prepared prepared, bool force);
  Outcome compute(Prepared prepared);
  void publishLoop();
  void publish(const PublishJob& job);

  // Parameters (private namespace; config/workspace_server.yaml).
  std::string robot_file_;
  std::string base_frame_;
  std::string cache_directory_;
  WorkspaceRequestDefaults request_defaults_;  // default_step, analysis options (memory budget included)
  DisplayLimits display_;                      // display_step, max_points, max_cubes

  // Interfaces.
  ros::ServiceServer compute_service_;
  ros::Publisher singularity_map_publisher_;
  ros::Publisher markers_publisher_;
  ros::Publisher octree_publisher_;
  ros::Publisher progress_publisher_;
  tf2_ros::StaticTransformBroadcaster static_transforms_;

  // Identical requests running now, shared by whoever asks for the same key.
  std::mutex flights_mutex_;
  std::map<std::string, std::shared_future<Outcome>> flights_;

  // Topics are published by one thread, newest result last, after the response is sent.
  std::mutex publish_mutex_;
  std::condition_variable publish_wake_;
  std::deque<PublishJob> publish_jobs_;
  bool stopping_ = false;
  std::string published_;  // signature of what the latched topics show
  std::thread publisher_;
};

}  // namespace maximal_workspace
