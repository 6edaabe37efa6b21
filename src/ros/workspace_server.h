#pragma once
// The workspace_server node: /compute_workspace (a service, and a cancellable action with
// feedback) over the core library, its cache, and the latched topics that show the last
// result; /query_pose, where a pose is in a workspace. Parameters, services and publishers are
// declared in this one class (octomap_server's habit).

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <actionlib/server/simple_action_server.h>
#include <dynamic_reconfigure/server.h>
#include <nlohmann/json.hpp>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "maximal_workspace/ComputeProgress.h"
#include "maximal_workspace/ComputeWorkspace.h"
#include "maximal_workspace/ComputeWorkspaceAction.h"
#include "maximal_workspace/QueryPose.h"
#include "maximal_workspace/WorkspaceServerConfig.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/io/workspace_store.h"
#include "server_settings.h"

namespace maximal_workspace {

class WorkspaceServer {
 public:
  WorkspaceServer(ros::NodeHandle& node, ros::NodeHandle& private_node);
  ~WorkspaceServer();
  WorkspaceServer(const WorkspaceServer&) = delete;
  // Threads for the node's callbacks: every computation admitted or waiting holds one, and
  // two more stay free, so a cached answer never waits behind computations.
  int callbackThreads() const { return settings_.admission.computations + settings_.admission.waiting + 2; }
  WorkspaceServer& operator=(const WorkspaceServer&) = delete;

 private:
  // A request checked and resolved: what to compute and under which cache key.
  struct Prepared : ResolvedWorkspaceRequest {
    std::shared_ptr<const RobotModel> model;
    RobotSource source;
    DisplayLimits display;  // the display caps in force when the request came
  };
  struct PublishJob {
    std::string signature;  // entry, assembly-mode filter and display caps
    std::string entry;
    std::int8_t assembly_mode = 0;
    Prepared prepared;
    std::shared_ptr<const WorkspaceAnalysis> analysis;  // null: load it through the store
  };

  using Feedback = std::function<void(const ComputeProgress&)>;

  bool onComputeWorkspace(ComputeWorkspace::Request& request, ComputeWorkspace::Response& response);
  // A request's mesh format: empty or known; else the response refuses it, naming the field.
  bool validMeshFormat(const std::string& mesh, ComputeWorkspace::Response& response) const;
  // The meshes of a request's cache entry (`mesh` not empty): written into it the first
  // time, listed in response.mesh_files for the assembly modes kept; throws when they cannot be.
  void addMeshes(const Prepared& prepared, const std::string& entry, const std::string& mesh, std::int8_t assembly_mode,
                 ComputeWorkspace::Response& response);
  // The workspace of the request's step through the store (cached, else computed), then
  // the core's pose query on it.
  bool onQueryPose(QueryPose::Request& request, QueryPose::Response& response);
  // compute_workspace_action's goals, one at a time: a new goal preempts the running one.
  void onComputeGoal(const ComputeWorkspaceGoalConstPtr& goal);
  // What the service and the action do: the response, or why not; false when `cancelled`
  // stopped the computation (nothing is cached then). `feedback` gets every progress
  // message the topic gets. `publish`: the result replaces what the topics show. `mesh`:
  // the meshes too (addMeshes), made while the progress still reports, as stage "meshing".
  bool serve(const WorkspaceRequest& request, bool force, ComputeWorkspace::Response& response,
             const CancelCheck& cancelled, const Feedback& feedback, bool publish = true, const std::string& mesh = "");
  Prepared prepare(const WorkspaceRequest& request) const;
  // The robot file's model, parsed again only when its text changed: parsing allocates
  // much, and a cached answer's allocations wait behind a computation's (docs/reliability.md).
  std::shared_ptr<const RobotModel> robotModel(const std::string& robot_text) const;
  // Through the store, with progress published and the computation logged; `load`: with
  // the analysis in memory, else the entry's files. `meshing`, when given, is called with
  // the entry before the last progress message, as stage "meshing".
  WorkspaceStore::Entry obtain(Prepared prepared, bool force, bool load, const CancelCheck& cancelled,
                               const Feedback& feedback,
                               const std::function<void(const WorkspaceStore::Entry&)>& meshing = {});
  // The default request, computed or read from the cache when the node starts (parameter
  // compute_at_start), so that a display shows a workspace without anyone asking.
  void computeAtStart();
  void publishLoop();
  // Returns false when the working-mode surfaces were left out (made only while someone
  // subscribes to them).
  bool publish(const PublishJob& job);
  // Whether anyone subscribes to a topic the publisher draws. Under publish_mutex_.
  bool displayWatched() const;
  // A new subscriber to a drawn topic: the newest result, left undrawn while nobody
  // subscribed, drawn now; to the working-mode surfaces, also the last result published
  // again with them, if they were left out.
  void onDisplaySubscriber(bool mode_surfaces);
  // The figures of an entry's summary.json that a response needs, parsed once per entry
  // (again after a computation): at 2 mm the file is megabytes of region tables.
  std::shared_ptr<const nlohmann::json> responseFigures(const WorkspaceStore::Entry& entry);

  // Parameters (private namespace; config/workspace_server.yaml).
  std::string robot_file_;
  std::string base_frame_;
  ros::NodeHandle parameters_;       // private: settings are read again at every request
  ServerCeilings ceilings_;          // at start: threads and memory_budget at most
  WorkspaceServerSettings settings_;  // at start: cache_directory and cache_bytes, fixed for the store
  std::string worker_;  // the workspace_worker executable
  WorkspaceStore store_;

  // Interfaces.
  ros::ServiceServer compute_service_;
  ros::ServiceServer query_service_;
  ros::Publisher singularity_map_publisher_;
  ros::Publisher markers_publisher_;
  ros::Publisher mode_surfaces_publisher_;  // one working mode's regions at a time
  ros::Publisher octree_publisher_;
  ros::Publisher progress_publisher_;
  tf2_ros::StaticTransformBroadcaster static_transforms_;

  mutable std::mutex model_mutex_;
  mutable std::string model_text_;
  mutable std::shared_ptr<const RobotModel> model_;
  std::mutex figures_mutex_;
  std::deque<std::pair<std::string, std::shared_ptr<const nlohmann::json>>> figures_;  // newest first, by entry

  // Topics are published by one thread, newest result last, after the response is sent.
  std::mutex publish_mutex_;
  std::condition_variable publish_wake_;
  std::deque<PublishJob> publish_jobs_;
  bool stopping_ = false;
  std::string published_;  // signature of what the latched topics show
  PublishJob last_published_;
  // The newest result, while nobody subscribed to what it would be drawn on: drawing a 2 mm
  // result takes seconds of CPU and a gigabyte in the server, for no one.
  std::optional<PublishJob> undrawn_;
  bool mode_surfaces_complete_ = false;  // the last result's working-mode surfaces went out, if it has any
  std::thread publisher_;
  std::thread start_computation_;

  // rqt_reconfigure / dynparam: writes the settings to the parameter server, where the next
  // request reads them.
  dynamic_reconfigure::Server<WorkspaceServerConfig> reconfigure_;

  // Last: its thread runs goals through everything above.
  actionlib::SimpleActionServer<ComputeWorkspaceAction> action_server_;
};

}  // namespace maximal_workspace
