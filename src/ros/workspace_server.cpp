#include "workspace_server.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <geometry_msgs/TransformStamped.h>
#include <nlohmann/json.hpp>
#include <ros/package.h>

#include "maximal_workspace/ComputeProgress.h"
#include "maximal_workspace/MaximalWorkspaceOctrees.h"
#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_cache.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/io/workspace_state.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "workspace_messages.h"

namespace maximal_workspace {

WorkspaceServer::WorkspaceServer(ros::NodeHandle& node, ros::NodeHandle& private_node) {
  private_node.param<std::string>("robot_file", robot_file_,
                                  ros::package::getPath("maximal_workspace") + "/config/delta_like.yaml");
  private_node.param<std::string>("base_frame", base_frame_, "base_link");
  private_node.param<std::string>("cache_directory", cache_directory_, defaultCacheDirectory());
  // Integer parameters through int, and byte counts through double: XmlRpc has no
  // unsigned 64-bit type.
  int debris_min_voxels = static_cast<int>(request_defaults_.options.debris.min_voxels);
  double memory_budget = 0.0;
  AnalysisOptions& options = request_defaults_.options;
  private_node.param("default_step", request_defaults_.step, request_defaults_.step);
  private_node.param("memory_budget", memory_budget, memory_budget);
  private_node.param("singular_threshold", options.singular_threshold, options.singular_threshold);
  private_node.param("debris_min_voxels", debris_min_voxels, debris_min_voxels);
  private_node.param("debris_min_fraction", options.debris.min_fraction, options.debris.min_fraction);
  private_node.param("threads", options.threads, options.threads);
  if (!(memory_budget >= 0.0) || debris_min_voxels < 0) {
    ROS_WARN("workspace_server: memory_budget (%g) and debris_min_voxels (%d) cannot be negative; 0 (the default) is used",
             memory_budget, debris_min_voxels);
  }
  options.memory_budget = static_cast<std::uint64_t>(std::max(memory_budget, 0.0));
  options.debris.min_voxels = static_cast<std::uint64_t>(std::max(debris_min_voxels, 0));
  int max_points = static_cast<int>(display_.max_points), max_cubes = static_cast<int>(display_.max_cubes);
  private_node.param("display_step", display_.display_step, display_.display_step);
  private_node.param("max_points", max_points, max_points);
  private_node.param("max_cubes", max_cubes, max_cubes);
  display_.max_points = static_cast<std::uint64_t>(std::max(max_points, 1));
  display_.max_cubes = static_cast<std::uint64_t>(std::max(max_cubes, 1));
  bool publish_base_frame = false;
  std::string base_parent_frame;
  private_node.param("publish_base_frame", publish_base_frame, false);
  private_node.param<std::string>("base_parent_frame", base_parent_frame, "world");

  singularity_map_publisher_ = node.advertise<sensor_msgs::PointCloud2>("singularity_map", 1, true);
  markers_publisher_ = node.advertise<visualization_msgs::MarkerArray>("maximal_workspace/markers", 1, true);
  octree_publisher_ = node.advertise<MaximalWorkspaceOctrees>("maximal_workspace/octree", 1, true);
  progress_publisher_ = node.advertise<ComputeProgress>("compute_workspace/progress", 10);
  compute_service_ = node.advertiseService("compute_workspace", &WorkspaceServer::onComputeWorkspace, this);

  if (publish_base_frame) {
    // Identity: the robot's base frame where rviz's fixed frame is, with nothing else running.
    geometry_msgs::TransformStamped transform;
    transform.header.stamp = ros::Time::now();
    transform.header.frame_id = base_parent_frame;
    transform.child_frame_id = base_frame_;
    transform.transform.rotation.w = 1.0;
    static_transforms_.sendTransform(transform);
  }
  publisher_ = std::thread(&WorkspaceServer::publishLoop, this);
  try {
    const RobotModel model = loadRobotFile(robot_file_);
    ROS_INFO("workspace_server: robot %s (%s), cache %s, frame %s; /compute_workspace ready", model.name.c_str(),
             robot_file_.c_str(), cache_directory_.c_str(), base_frame_.c_str());
  } catch (const InputError& error) {
    // The file is read again on every request: it may be fixed while the node runs.
    ROS_ERROR("workspace_server: %s; every request will fail until the robot file is fixed", error.what());
  }
}

WorkspaceServer::~WorkspaceServer() {
  {
    std::lock_guard<std::mutex> lock(publish_mutex_);
    stopping_ = true;
  }
  publish_wake_.notify_all();
  publisher_.join();
}

WorkspaceServer::Prepared WorkspaceServer::prepare(const ComputeWorkspace::Request& request) const {
  Prepared prepared;
  prepared.robot_text = readTextFile(robot_file_, "robot file");
  prepared.model = std::make_shared<const RobotModel>(parseRobotFile(prepared.robot_text, robot_file_));
  static_cast<ResolvedWorkspaceRequest&>(prepared) =
      resolveWorkspaceRequest(*prepared.model, prepared.robot_text, workspaceRequest(request), request_defaults_);
  return prepared;
}

WorkspaceServer::Outcome WorkspaceServer::obtain(Prepared prepared, bool force) {
  const WorkspaceCache cache(cache_directory_);
  std::promise<Outcome> promise;
  {
    std::unique_lock<std::mutex> lock(flights_mutex_);
    const auto running = flights_.find(prepared.key);
    if (running != flights_.end()) {
      // The same request is being computed: wait for it instead of computing it twice.
      const std::shared_future<Outcome> result = running->second;
      lock.unlock();
      Outcome outcome = result.get();
      outcome.shared = true;
      return outcome;
    }
    if (!force) {
      std::string problem;
      const auto entry = cache.find(prepared.key, &problem, {"summary.json"});
      if (!problem.empty()) ROS_WARN("workspace_server: %s; computing again", problem.c_str());
      if (entry) {
        Outcome outcome;
        outcome.success = outcome.from_cache = true;
        outcome.entry = *entry;
        return outcome;
      }
    }
    flights_[prepared.key] = promise.get_future().share();
  }
  const std::string key = prepared.key;
  Outcome outcome;
  try {
    outcome = compute(std::move(prepared));
  } catch (const InputError& error) {
    outcome.message = error.what();
  } catch (const std::exception& error) {
    outcome.message = std::string("internal error: ") + error.what();
  } catch (...) {
    // Whatever happened, callers waiting on this key must get an answer.
    outcome.message = "internal error";
  }
  promise.set_value(outcome);
  std::lock_guard<std::mutex> lock(flights_mutex_);
  flights_.erase(key);
  return outcome;
}

WorkspaceServer::Outcome WorkspaceServer::compute(Prepared prepared) {
  const auto started = std::chrono::steady_clock::now();
  auto last_progress = started - std::chrono::seconds(1);
  const std::string description = prepared.description;
  prepared.options.progress = [&, description](const AnalysisProgress& progress) {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_progress < std::chrono::milliseconds(200)) return;
    last_progress = now;
    ComputeProgress message;
    message.header.stamp = ros::Time::now();
    message.request = description;
    message.stage = progress.stage;
    message.fraction = static_cast<float>(std::min(0.99, progress.fraction));
    message.poses_evaluated = progress.evaluated;
    message.voxels_inside = progress.inside;
    message.elapsed = progress.elapsed_seconds;
    message.remaining = message.fraction > 0.01f ? progress.elapsed_seconds * (1.0 - message.fraction) / message.fraction : -1.0;
    progress_publisher_.publish(message);
    ROS_INFO_THROTTLE(2.0, "workspace_server: %s: %s, %.0f %% (%.1f s)", description.c_str(), progress.stage,
                      100.0 * message.fraction, progress.elapsed_seconds);
  };
  ROS_INFO("workspace_server: computing %s", description.c_str());
  auto analysis = std::make_shared<const WorkspaceAnalysis>(analyseWorkspace(*prepared.model, prepared.spec, prepared.options));
  ComputeProgress done;
  done.header.stamp = ros::Time::now();
  done.request = description;
  done.fraction = 1.0f;
  done.stage = "done";
  done.poses_evaluated = analysis->posesEvaluated();
  done.voxels_inside = analysis->voxelCount();
  done.elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  done.remaining = 0.0;
  progress_publisher_.publish(done);

  const WorkspaceCache cache(cache_directory_);
  const RobotSource source{robot_file_, hex64(fnv1a64(prepared.robot_text))};
  Outcome outcome;
  outcome.entry = cache.store(prepared.key, [&](const std::string& directory) {
    writeWorkspaceFiles(*prepared.model, source, *analysis, directory);
  });
  outcome.success = true;
  outcome.seconds = analysis->seconds().total;
  outcome.analysis = analysis;
  ROS_INFO("workspace_server: %s computed in %.2f s: %llu voxels, cached in %s", description.c_str(), outcome.seconds,
           static_cast<unsigned long long>(analysis->voxelCount()), outcome.entry.c_str());
  return outcome;
}

bool WorkspaceServer::onComputeWorkspace(ComputeWorkspace::Request& request, ComputeWorkspace::Response& response) {
  try {
    Prepared prepared = prepare(request);
    const std::string key = prepared.key;
    const std::shared_ptr<const RobotModel> model = prepared.model;
    const Outcome outcome = obtain(std::move(prepared), request.force);
    if (!outcome.success) throw InputError(outcome.message);
    fillResponse(nlohmann::json::parse(readTextFile(outcome.entry + "/summary.json", "cached summary")),
                 request.assembly_mode, response);
    response.success = true;
    response.from_cache = outcome.from_cache;
    response.compute_time = outcome.from_cache || outcome.shared ? 0.0 : outcome.seconds;
    response.message = outcome.from_cache ? "from cache"
                       : outcome.shared   ? "shared a computation of the same request that was already running"
                                          : "computed in " + numberText(outcome.seconds) + " s";
    response.summary_file = outcome.entry + "/summary.json";
    for (std::int8_t sign : {1, -1}) {
      const std::string name = outcome.entry + (sign > 0 ? "/maximal_positive.bt" : "/maximal_negative.bt");
      if ((request.assembly_mode == 0 || request.assembly_mode == sign) && std::filesystem::exists(name)) {
        response.octree_files.push_back(name);
      }
    }
    std::vector<std::string> label_trees;
    for (const auto& file : std::filesystem::directory_iterator(outcome.entry)) {
      if (file.path().extension() == ".ot") label_trees.push_back(file.path().string());
    }
    std::sort(label_trees.begin(), label_trees.end());
    response.octree_files.insert(response.octree_files.end(), label_trees.begin(), label_trees.end());
    {
      std::lock_guard<std::mutex> lock(publish_mutex_);
      publish_jobs_.push_back(PublishJob{outcome.entry + "#" + std::to_string(request.assembly_mode), key, outcome.entry,
                                         request.assembly_mode, model, outcome.analysis});
    }
    publish_wake_.notify_one();
  } catch (const InputError& error) {
    response = ComputeWorkspace::Response();
    response.success = false;
    response.message = error.what();
    ROS_WARN("workspace_server: request refused: %s", error.what());
  } catch (const std::exception& error) {
    response = ComputeWorkspace::Response();
    response.success = false;
    response.message = std::string("internal error: ") + error.what();
    ROS_ERROR("workspace_server: %s", response.message.c_str());
  } catch (...) {
    response = ComputeWorkspace::Response();
    response.success = false;
    response.message = "internal error";
    ROS_ERROR("workspace_server: internal error");
  }
  return true;  // the outcome is in the response; false would hide the message from the caller
}

void WorkspaceServer::publishLoop() {
  while (true) {
    PublishJob job;
    {
      std::unique_lock<std::mutex> lock(publish_mutex_);
      publish_wake_.wait(lock, [this] { return stopping_ || !publish_jobs_.empty(); });
      if (stopping_) return;
      // Only the newest result matters for latched topics.
      job = std::move(publish_jobs_.back());
      publish_jobs_.clear();
      if (job.signature == published_) continue;
    }
    try {
      publish(job);
      std::lock_guard<std::mutex> lock(publish_mutex_);
      published_ = job.signature;
    } catch (const std::exception& error) {
      ROS_WARN("workspace_server: cannot publish the result in %s: %s", job.entry.c_str(), error.what());
    }
  }
}

void WorkspaceServer::publish(const PublishJob& job) {
  std::shared_ptr<const WorkspaceAnalysis> analysis = job.analysis;
  if (!analysis) {
    const WorkspaceCache cache(cache_directory_);
    std::string problem;
    if (!cache.verify(job.key, {kStateFileName}, &problem)) throw InputError(problem);
    std::ifstream in(job.entry + "/" + kStateFileName, std::ios::binary);
    analysis = std::make_shared<const WorkspaceAnalysis>(
        readWorkspaceState(*job.model, in, job.entry + "/" + kStateFileName, request_defaults_.options.threads));
  }
  const ros::Time now = ros::Time::now();
  const SingularitySample singularities = sampleSingularities(*job.model, *analysis, display_);
  sensor_msgs::PointCloud2 cloud = singularityCloud(singularities, base_frame_);
  cloud.header.stamp = now;
  singularity_map_publisher_.publish(cloud);
  const SurfaceSample surfaces = sampleSurfaces(*analysis, display_, job.assembly_mode);
  visualization_msgs::MarkerArray markers = workspaceMarkers(*analysis, surfaces, base_frame_, job.assembly_mode);
  for (visualization_msgs::Marker& marker : markers.markers) marker.header.stamp = now;
  markers_publisher_.publish(markers);
  MaximalWorkspaceOctrees octrees = octreesMessage(*analysis, base_frame_, job.assembly_mode);
  octrees.header.stamp = now;
  octree_publisher_.publish(octrees);
  ROS_INFO("workspace_server: published the singularity map (%s), markers (%s surface cubes of %g m, %zu markers) "
           "and %zu octrees at full resolution",
           singularities.decimation.text().c_str(), std::to_string(surfaces.decimation.shown).c_str(), surfaces.cube_size,
           markers.markers.size(), octrees.octrees.size());
}

}  // namespace maximal_workspace
