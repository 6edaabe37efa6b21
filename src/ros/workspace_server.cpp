#include "workspace_server.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <utility>

#include <unistd.h>

#include <geometry_msgs/TransformStamped.h>
#include <nlohmann/json.hpp>
#include <ros/package.h>

#include "maximal_workspace/ComputeProgress.h"
#include "maximal_workspace/MaximalWorkspaceOctrees.h"
#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/mesh_files.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/surfaces/vertex_conditioning.h"
#include "pose_query_messages.h"
#include "workspace_messages.h"

namespace maximal_workspace {

namespace {

// The action's result from the service's response: the same fields.
ComputeWorkspaceResult actionResult(const ComputeWorkspace::Response& response) {
  ComputeWorkspaceResult result;
  result.success = response.success;
  result.message = response.message;
  result.from_cache = response.from_cache;
  result.margin = response.margin;
  result.workspace_volume = response.workspace_volume;
  result.workspace_inner_volume = response.workspace_inner_volume;
  result.workspace_boundary_volume = response.workspace_boundary_volume;
  result.volume_unit = response.volume_unit;
  result.assembly_modes = response.assembly_modes;
  result.working_modes = response.working_modes;
  result.transitions = response.transitions;
  result.summary_file = response.summary_file;
  result.octree_files = response.octree_files;
  result.conditioning_threshold = response.conditioning_threshold;
  result.mesh_files = response.mesh_files;
  result.compute_time = response.compute_time;
  return result;
}

// Triangles of a mesh served at most (mow workspace's --mesh-triangles default).
constexpr std::uint64_t kServedMeshTriangles = 1'000'000;
// Averagings of the conditioning index over the display surface's neighbours: enough to
// blend the display cells' staircase (a few cells), not to move the gradients.
constexpr int kDisplayValueSmoothing = 3;

// The meshes of `format` a cache entry already holds (file names).
std::vector<std::string> existingMeshes(const std::string& directory, MeshFormat format) {
  std::vector<std::string> names;
  std::error_code error;
  for (std::filesystem::directory_iterator it(directory, error), end; !error && it != end; it.increment(error)) {
    if (it->path().extension() == "." + meshExtension(format)) names.push_back(it->path().filename().string());
  }
  return names;
}

// The message of a request that failed, from the exception being handled: an InputError is
// the request's fault and says what is wrong; anything else is an internal error. Logged.
std::string failureMessage() {
  try {
    throw;
  } catch (const InputError& error) {
    ROS_WARN("workspace_server: request refused: %s", error.what());
    return error.what();
  } catch (const std::exception& error) {
    ROS_ERROR("workspace_server: internal error: %s", error.what());
    return std::string("internal error: ") + error.what();
  } catch (...) {
    ROS_ERROR("workspace_server: internal error");
    return "internal error";
  }
}

// A fresh response saying why not: nothing of a half-made one is sent.
template <class Response>
void refuse(Response& response, const std::string& message) {
  response = Response();
  response.success = false;
  response.message = message;
}

// "computed in 12.9 s, stored in 7.08 s": the analysis, then its files written into the cache.
std::string computedText(const ComputedEntry& computed) {
  char text[96];
  std::snprintf(text, sizeof text, "computed in %.3g s, stored in %.3g s", computed.seconds, computed.storing_seconds);
  return text;
}

// The workspace_worker beside this node's binary (both in the package's lib directory).
std::string workerExecutable() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  return (error ? std::filesystem::path(".") : self.parent_path()).append("workspace_worker").string();
}

}  // namespace

WorkspaceServer::WorkspaceServer(ros::NodeHandle& node, ros::NodeHandle& private_node)
    : parameters_(private_node),
      ceilings_(serverCeilings(private_node)),
      settings_(workspaceServerSettings(private_node, ceilings_)),
      worker_(workerExecutable()),
      // Computations run in worker processes: the gigabytes a fine one frees never lock this
      // node's memory map while it answers (docs/reliability.md).
      store_(settings_.cache_directory, settings_.cache_bytes, WorkspaceStore::kDefaultMemoryBytes, settings_.admission,
             std::make_shared<const WorkerProcessComputation>(worker_)),
      reconfigure_(private_node),
      action_server_(node, "compute_workspace_action",
                     [this](const ComputeWorkspaceGoalConstPtr& goal) { onComputeGoal(goal); }, false) {
  private_node.param<std::string>("robot_file", robot_file_,
                                  ros::package::getPath("maximal_workspace") + "/config/delta_like.yaml");
  private_node.param<std::string>("base_frame", base_frame_, "base_link");
  bool publish_base_frame = false;
  std::string base_parent_frame;
  private_node.param("publish_base_frame", publish_base_frame, false);
  private_node.param<std::string>("base_parent_frame", base_parent_frame, "world");

  // Latched, and drawn only while someone subscribes (undrawn_).
  const auto drawn = [&](const std::string& topic, auto message, bool mode_surfaces) {
    return node.advertise<decltype(message)>(
        topic, 1, [this, mode_surfaces](const ros::SingleSubscriberPublisher&) { onDisplaySubscriber(mode_surfaces); },
        ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true);
  };
  singularity_map_publisher_ = drawn("singularity_map", sensor_msgs::PointCloud2(), false);
  markers_publisher_ = drawn("maximal_workspace/markers", visualization_msgs::MarkerArray(), false);
  mode_surfaces_publisher_ = drawn("maximal_workspace/mode_surfaces", visualization_msgs::MarkerArray(), true);
  octree_publisher_ = drawn("maximal_workspace/octree", MaximalWorkspaceOctrees(), false);
  progress_publisher_ = node.advertise<ComputeProgress>("compute_workspace/progress", 10);
  compute_service_ = node.advertiseService("compute_workspace", &WorkspaceServer::onComputeWorkspace, this);
  query_service_ = node.advertiseService("query_pose", &WorkspaceServer::onQueryPose, this);

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
  action_server_.start();
  if (::access(worker_.c_str(), X_OK) != 0) {
    ROS_ERROR("workspace_server: %s is missing or not executable: every computation will fail (cached workspaces "
              "are still served); build or install the package again",
              worker_.c_str());
  }
  try {
    const RobotModel model = loadRobotFile(robot_file_);
    ROS_INFO("workspace_server: robot %s (%s), cache %s, frame %s; at most %d threads a computation and %s of memory "
             "for all; /compute_workspace, compute_workspace_action and /query_pose ready",
             model.name.c_str(), robot_file_.c_str(), settings_.cache_directory.c_str(), base_frame_.c_str(),
             ceilings_.threads, byteText(ceilings_.memory_bytes).c_str());
  } catch (const InputError& error) {
    // The file is read again on every request: it may be fixed while the node runs.
    ROS_ERROR("workspace_server: %s; every request will fail until the robot file is fixed", error.what());
  }
  reconfigure_.setCallback([this, first = true](WorkspaceServerConfig& config, std::uint32_t) mutable {
    // dynamic_reconfigure writes to the parameters what this leaves in `config`.
    boundSettings(config, ceilings_);
    if (std::exchange(first, false)) return;  // the values at start, from the parameters
    ROS_INFO("workspace_server: settings changed (default_step %g, margin %g, memory_budget %g, threads %d, display_step "
             "%g, max_points %d, max_cubes %d, surfaces %s, surface_alpha %g, colour_by_conditioning %s); the next request "
             "uses them",
             config.default_step, config.margin, config.memory_budget, config.threads, config.display_step,
             config.max_points, config.max_cubes, config.surfaces ? "true" : "false", config.surface_alpha,
             config.colour_by_conditioning ? "true" : "false");
  });
  bool compute_at_start = false;
  private_node.param("compute_at_start", compute_at_start, compute_at_start);
  if (compute_at_start) start_computation_ = std::thread(&WorkspaceServer::computeAtStart, this);
}

void WorkspaceServer::computeAtStart() {
  ComputeWorkspace::Response response;
  const bool finished = serve(WorkspaceRequest(), false, response, [] { return !ros::ok(); }, {});
  if (!finished) return;  // shut down meanwhile
  if (response.success) {
    ROS_INFO("workspace_server: the default workspace at start: %s, %g %s", response.message.c_str(),
             response.workspace_volume, response.volume_unit.c_str());
  } else {
    ROS_WARN("workspace_server: no default workspace at start: %s", response.message.c_str());
  }
}

WorkspaceServer::~WorkspaceServer() {
  if (start_computation_.joinable()) start_computation_.join();
  {
    std::lock_guard<std::mutex> lock(publish_mutex_);
    stopping_ = true;
  }
  publish_wake_.notify_all();
  publisher_.join();
}

WorkspaceServer::Prepared WorkspaceServer::prepare(const WorkspaceRequest& request) const {
  const WorkspaceServerSettings settings = workspaceServerSettings(parameters_, ceilings_);
  Prepared prepared;
  const std::string robot_text = readTextFile(robot_file_, "robot file");
  prepared.model = robotModel(robot_text);
  prepared.source = RobotSource{robot_file_, hex64(fnv1a64(robot_text))};
  static_cast<ResolvedWorkspaceRequest&>(prepared) =
      resolveWorkspaceRequest(*prepared.model, robot_text, request, settings.request_defaults);
  prepared.display = settings.display;
  return prepared;
}

std::shared_ptr<const RobotModel> WorkspaceServer::robotModel(const std::string& robot_text) const {
  std::lock_guard<std::mutex> lock(model_mutex_);
  if (!model_ || robot_text != model_text_) {
    model_ = std::make_shared<const RobotModel>(parseRobotFile(robot_text, robot_file_));
    model_text_ = robot_text;
  }
  return model_;
}

// A computed request's time is the analysis's, then the storing of its files: the
// delta-like robot at 2 mm takes 9.3 s (with the memory estimate before it) and 4.5 s.
// Progress reports the whole, so its remaining time holds to the end.
constexpr double kAnalysisShare = 0.68;

namespace {

using Clock = std::chrono::steady_clock;

// A request's ComputeProgress, on the topic and to the goal's feedback: at most five
// messages a second as the stages report, and at least one a second whatever they do (a
// heartbeat repeats the last with its times brought up to date), so that a stage that
// reports seldom, or a wait, never looks like a server that stopped. A request answered
// within a second (from the cache) sends none.
class ProgressReport {
 public:
  using Feedback = std::function<void(const ComputeProgress&)>;
  ProgressReport(std::string request, const ros::Publisher& publisher, const Feedback& feedback)
      : request_(std::move(request)), publisher_(publisher), feedback_(feedback), heartbeat_(&ProgressReport::beat, this) {}
  ~ProgressReport() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    heartbeat_.join();
  }

  // `at_once`: whatever the throttle (a new situation, such as waiting in the queue).
  void update(const char* stage, double fraction, std::uint64_t evaluated, std::uint64_t inside, bool at_once = false) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const Clock::time_point now = Clock::now();
    if (stage_ != stage && std::string(stage) == "storing") storing_started_ = now;
    if (!analysis_started_ && std::string(stage) != "queued") analysis_started_ = now;
    stage_ = stage;
    fraction_ = fraction;
    evaluated_ = evaluated;
    inside_ = inside;
    if (!at_once && sent_any_ && now - sent_ < std::chrono::milliseconds(200)) return;
    send(now);
  }

  // The last message: the stage "done" at 1.
  void done(std::uint64_t evaluated, std::uint64_t inside) {
    const std::lock_guard<std::mutex> lock(mutex_);
    stage_ = "done";
    fraction_ = 1.0;
    evaluated_ = evaluated;
    inside_ = inside;
    send(Clock::now());
  }

  double elapsed() const { return std::chrono::duration<double>(Clock::now() - started_).count(); }

 private:
  // Under mutex_.
  void send(Clock::time_point now) {
    sent_ = now;
    sent_any_ = true;
    ComputeProgress message;
    message.header.stamp = ros::Time::now();
    message.request = request_;
    message.stage = stage_;
    message.fraction = static_cast<float>(stage_ == "done" ? 1.0 : std::min(0.99, fraction_));
    message.poses_evaluated = evaluated_;
    message.voxels_inside = inside_;
    message.elapsed = std::chrono::duration<double>(now - started_).count();
    // The rate is taken from the analysis's start: what came before it (the memory
    // estimate, the worker's start, a wait in the queue) is no part of the fraction, and
    // counted in, it made the first estimates 1.5 times too long at 3 mm. Meshing has no
    // measure of its own progress: its remaining time is unknown.
    const double analysing = std::chrono::duration<double>(now - analysis_started_.value_or(now)).count();
    message.remaining = stage_ == "done"                                ? 0.0
                        : message.fraction > 0.01f && stage_ != "meshing" ? analysing * (1.0 - message.fraction) / message.fraction
                                                                         : -1.0;
    if (stage_ == "storing") {
      // Storing writes at the disk's pace, not the analysis's (which other work on the
      // machine may have slowed): past its first tenth it is also timed by its own rate,
      // and the smaller estimate is given, since the rate of its first tenths can be slow
      // (2.3 times the time that remained, once in CI at 3 mm).
      const double stored = (fraction_ - kAnalysisShare) / (1.0 - kAnalysisShare);
      const double storing_elapsed = std::chrono::duration<double>(now - storing_started_).count();
      if (stored >= 0.1) message.remaining = std::min(message.remaining, storing_elapsed * (1.0 - stored) / stored);
    }
    publisher_.publish(message);
    if (feedback_) feedback_(message);
    if (stage_ != "done") {
      ROS_INFO_THROTTLE(2.0, "workspace_server: %s: %s, %.0f %% (%.1f s)", request_.c_str(), stage_.c_str(),
                        100.0 * message.fraction, message.elapsed);
    }
  }

  void beat() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_until(lock, sent_ + std::chrono::seconds(1), [this] { return stopping_; })) {
      if (Clock::now() - sent_ >= std::chrono::seconds(1)) send(Clock::now());
    }
  }

  const std::string request_;
  const ros::Publisher& publisher_;
  const Feedback& feedback_;
  const Clock::time_point started_ = Clock::now();
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  bool sent_any_ = false;
  Clock::time_point sent_ = started_;
  Clock::time_point storing_started_;
  std::optional<Clock::time_point> analysis_started_;  // the first report that is not a wait
  // Before the first stage: the cache lookup, the memory estimate, the worker's start.
  std::string stage_ = "starting";
  double fraction_ = 0.0;
  std::uint64_t evaluated_ = 0, inside_ = 0;
  std::thread heartbeat_;  // last: it starts once the rest is ready
};

}  // namespace

WorkspaceStore::Entry WorkspaceServer::obtain(Prepared prepared, bool force, bool load, const CancelCheck& cancelled,
                                              const Feedback& feedback,
                                              const std::function<void(const WorkspaceStore::Entry&)>& meshing) {
  const std::string description = prepared.description;
  ProgressReport progress(description, progress_publisher_, feedback);
  std::uint64_t evaluated = 0, inside = 0;
  prepared.options.cancelled = cancelled;
  prepared.options.progress = [&](const AnalysisProgress& analysis) {
    evaluated = analysis.evaluated;
    inside = analysis.inside;
    progress.update(analysis.stage, kAnalysisShare * analysis.fraction, evaluated, inside);
  };
  WorkspaceStore::Options options;
  options.policy = force ? WorkspaceStore::Policy::Recompute : WorkspaceStore::Policy::CacheOrCompute;
  options.load = load;
  if (!load) options.files = {"summary.json"};  // what the response reads; publishing checks workspace.bin
  options.warn = [](const std::string& problem) { ROS_WARN("workspace_server: %s; computing again", problem.c_str()); };
  options.queued = [&](const std::string& why) {
    ROS_INFO("workspace_server: %s: %s", description.c_str(), why.c_str());
    progress.update("queued", 0.0, evaluated, inside, true);
  };
  options.storing = [&](double fraction) {
    // Until the entry is committed (1.0) a cancelled goal's files are dropped, not cached.
    if (fraction < 1.0) throwIfCancelled(cancelled);
    progress.update("storing", kAnalysisShare + (1.0 - kAnalysisShare) * fraction, evaluated, inside);
  };
  WorkspaceStore::Entry entry = store_.obtain(prepared, *prepared.model, prepared.source, options);
  if (meshing) {
    // The heartbeat repeats this stage while the meshes are made (seconds at fine steps).
    progress.update("meshing", 1.0, evaluated, inside, true);
    meshing(entry);
  }
  if (entry.origin != WorkspaceStore::Origin::Computed) return entry;
  progress.done(entry.computed.poses_evaluated, entry.computed.voxels);
  ROS_INFO("workspace_server: %s: %s, %.2f s in all (worker peak %s): %llu voxels, cached in %s",
           description.c_str(), computedText(entry.computed).c_str(), progress.elapsed(),
           byteText(entry.computed.peak_bytes).c_str(), static_cast<unsigned long long>(entry.computed.voxels),
           entry.path.c_str());
  return entry;
}

bool WorkspaceServer::onComputeWorkspace(ComputeWorkspace::Request& request, ComputeWorkspace::Response& response) {
  if (!validMeshFormat(request.mesh, response)) return true;
  // Ctrl-C or SIGTERM stops a computation within a block: nothing half-written is cached.
  serve(workspaceRequest(request), request.force, response, [] { return !ros::ok(); }, {}, !request.keep_topics,
        request.mesh);
  return true;  // the outcome is in the response; false would hide the message from the caller
}

bool WorkspaceServer::validMeshFormat(const std::string& mesh, ComputeWorkspace::Response& response) const {
  if (mesh.empty()) return true;
  try {
    parseMeshFormat(mesh, "mesh");
    return true;
  } catch (const InputError& error) {
    ROS_WARN("workspace_server: request refused: %s", error.what());
    response.success = false;
    response.message = error.what();
    return false;
  }
}

void WorkspaceServer::addMeshes(const Prepared& prepared, const std::string& entry, const std::string& mesh,
                                std::int8_t assembly_mode, ComputeWorkspace::Response& response) {
  try {
    const MeshFormat format = parseMeshFormat(mesh, "mesh");
    // Written once into the entry (each file atomically), then found there.
    std::vector<std::string> names = existingMeshes(entry, format);
    if (names.empty()) {
      WorkspaceStore::Options options;
      options.policy = WorkspaceStore::Policy::CacheOnly;
      options.load = true;
      const auto analysis = store_.obtain(prepared, *prepared.model, prepared.source, options).analysis;
      if (!workspaceMeshable(analysis->grid())) throw InputError("mesh: meshes need a grid over x y z, or x y z and an orientation set");
      for (const MeshFile& file :
           writeWorkspaceMeshes(*analysis, format, MeshOptions{0, kServedMeshTriangles}, entry, prepared.model.get())) {
        names.push_back(file.name);
      }
      ROS_INFO("workspace_server: %zu meshes written into %s", names.size(), entry.c_str());
    }
    for (const std::string& name : names) {
      const bool positive = name.find("_positive.") != std::string::npos;
      if (assembly_mode == 0 || (assembly_mode > 0) == positive) response.mesh_files.push_back(entry + "/" + name);
    }
    std::sort(response.mesh_files.begin(), response.mesh_files.end());
  } catch (const std::exception& error) {
    throw InputError(std::string("the meshes cannot be written: ") + error.what());
  }
}

void WorkspaceServer::onComputeGoal(const ComputeWorkspaceGoalConstPtr& goal) {
  const auto started = std::chrono::steady_clock::now();
  ComputeWorkspace::Response response;
  if (!validMeshFormat(goal->mesh, response)) {
    action_server_.setAborted(actionResult(response), response.message);
    return;
  }
  const bool finished = serve(
      workspaceRequest(*goal), goal->force, response,
      [this] { return action_server_.isPreemptRequested() || !ros::ok(); },
      [this](const ComputeProgress& progress) {
        ComputeWorkspaceFeedback feedback;
        feedback.progress = progress;
        action_server_.publishFeedback(feedback);
      },
      true, goal->mesh);
  const ComputeWorkspaceResult result = actionResult(response);
  if (!finished) {
    ROS_INFO("workspace_server: goal cancelled after %.2f s; nothing was cached",
             std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    action_server_.setPreempted(result, response.message);
  } else if (response.success) {
    action_server_.setSucceeded(result, response.message);
  } else {
    action_server_.setAborted(result, response.message);
  }
}

bool WorkspaceServer::serve(const WorkspaceRequest& request, bool force, ComputeWorkspace::Response& response,
                            const CancelCheck& cancelled, const Feedback& feedback, bool publish, const std::string& mesh) {
  try {
    const Prepared prepared = prepare(request);
    const auto assembly_mode = static_cast<std::int8_t>(request.assembly_mode);  // -1, 0 or 1: checked by prepare
    std::function<void(const WorkspaceStore::Entry&)> meshing;
    if (!mesh.empty()) {
      meshing = [&](const WorkspaceStore::Entry& entry) { addMeshes(prepared, entry.path, mesh, assembly_mode, response); };
    }
    const WorkspaceStore::Entry outcome = obtain(prepared, force, false, cancelled, feedback, meshing);
    fillResponse(*responseFigures(outcome), assembly_mode, response);
    const bool from_cache = outcome.origin == WorkspaceStore::Origin::Cache;
    const bool shared = outcome.origin == WorkspaceStore::Origin::Shared;
    response.success = true;
    response.from_cache = from_cache;
    response.compute_time = from_cache || shared ? 0.0 : outcome.computed.seconds;
    response.message = from_cache ? "from cache"
                       : shared   ? "shared a computation of the same request that was already running"
                                  : computedText(outcome.computed);
    response.summary_file = outcome.path + "/summary.json";
    for (std::int8_t sign : {1, -1}) {
      for (const char* set : {"/maximal_", "/total_orientation_"}) {
        const std::string name = outcome.path + set + (sign > 0 ? "positive.bt" : "negative.bt");
        if ((assembly_mode == 0 || assembly_mode == sign) && std::filesystem::exists(name)) {
          response.octree_files.push_back(name);
        }
      }
    }
    std::vector<std::string> label_trees;
    for (const auto& file : std::filesystem::directory_iterator(outcome.path)) {
      if (file.path().extension() == ".ot") label_trees.push_back(file.path().string());
    }
    std::sort(label_trees.begin(), label_trees.end());
    response.octree_files.insert(response.octree_files.end(), label_trees.begin(), label_trees.end());
    if (publish) {
      std::lock_guard<std::mutex> lock(publish_mutex_);
      const DisplayLimits& caps = prepared.display;
      const std::string signature = outcome.path + "#" + std::to_string(assembly_mode) + "#" +
                                    numberText(caps.display_step) + "," + std::to_string(caps.max_points) + "," +
                                    std::to_string(caps.max_cubes) + "," + std::to_string(caps.surfaces) + "," +
                                    numberText(caps.surface_alpha) + "," + std::to_string(caps.colour_by_conditioning);
      publish_jobs_.push_back(PublishJob{signature, outcome.path,
                                         assembly_mode, prepared, outcome.analysis});
    }
    publish_wake_.notify_one();
  } catch (const Cancelled&) {
    refuse(response, "cancelled: nothing was cached");
    return false;
  } catch (...) {
    refuse(response, failureMessage());
  }
  return true;
}

bool WorkspaceServer::onQueryPose(QueryPose::Request& request, QueryPose::Response& response) {
  try {
    WorkspaceRequest workspace_request;
    workspace_request.step = request.step;
    workspace_request.tilt_max = request.tilt_max;
    workspace_request.torsion = request.torsion;
    workspace_request.angle_step = request.angle_step;
    workspace_request.working_modes = request.working_modes;
    const Prepared prepared = prepare(workspace_request);
    const Pose pose = queryRequestPose(request, *prepared.model);
    const WorkspaceStore::Entry entry = obtain(prepared, false, true, [] { return !ros::ok(); }, {});
    fillQueryResponse(*entry.analysis, queryPose(*prepared.model, *entry.analysis, pose), response);
    response.success = true;
    response.message = entry.origin == WorkspaceStore::Origin::Computed
                           ? "workspace " + computedText(entry.computed)
                       : entry.origin == WorkspaceStore::Origin::Shared
                           ? "workspace shared with a computation of the same request already running"
                           : "workspace from the cache";
  } catch (...) {
    refuse(response, failureMessage());
  }
  return true;  // the outcome is in the response
}

std::shared_ptr<const nlohmann::json> WorkspaceServer::responseFigures(const WorkspaceStore::Entry& entry) {
  constexpr std::size_t kEntriesKept = 64;
  if (entry.origin != WorkspaceStore::Origin::Computed) {
    std::lock_guard<std::mutex> lock(figures_mutex_);
    for (const auto& known : figures_) {
      if (known.first == entry.path) return known.second;
    }
  }
  // Read unlocked: a fine entry's summary takes a while, and cached answers must not wait.
  const nlohmann::json summary = readWorkspaceSummary(entry.path);
  auto figures = std::make_shared<nlohmann::json>();
  for (const char* part :
       {"options", "workspace", "grid", "assembly_modes", "volumes_per_mode", "orientation_set", "conditioning"}) {
    (*figures)[part] = summary.at(part);
  }
  std::lock_guard<std::mutex> lock(figures_mutex_);
  figures_.erase(std::remove_if(figures_.begin(), figures_.end(), [&](const auto& known) { return known.first == entry.path; }),
                 figures_.end());
  figures_.emplace_front(entry.path, figures);
  if (figures_.size() > kEntriesKept) figures_.pop_back();
  return figures;
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
      undrawn_.reset();  // older than this job
      // Shown already, unless its working-mode surfaces were left out and someone wants them.
      const bool wants_mode_surfaces = !mode_surfaces_complete_ && mode_surfaces_publisher_.getNumSubscribers() > 0;
      if (job.signature == published_ && !wants_mode_surfaces) continue;
      if (!displayWatched()) {
        job.analysis.reset();  // loaded again from the cache if someone comes to look
        undrawn_ = std::move(job);
        continue;
      }
    }
    try {
      const bool complete = publish(job);
      std::lock_guard<std::mutex> lock(publish_mutex_);
      published_ = job.signature;
      last_published_ = job;
      mode_surfaces_complete_ = complete;
    } catch (const std::exception& error) {
      ROS_WARN("workspace_server: cannot publish the result in %s: %s", job.entry.c_str(), error.what());
    }
  }
}

bool WorkspaceServer::displayWatched() const {
  for (const ros::Publisher* topic :
       {&singularity_map_publisher_, &markers_publisher_, &mode_surfaces_publisher_, &octree_publisher_}) {
    if (topic->getNumSubscribers() > 0) return true;
  }
  return false;
}

void WorkspaceServer::onDisplaySubscriber(bool mode_surfaces) {
  {
    std::lock_guard<std::mutex> lock(publish_mutex_);
    // A queued job is newer than either, and is drawn for this subscriber anyway
    // (publishLoop drops undrawn_ when it takes it).
    if (!publish_jobs_.empty()) return;
    if (undrawn_) {
      publish_jobs_.push_back(std::move(*undrawn_));
      undrawn_.reset();
    } else if (mode_surfaces && !published_.empty() && !mode_surfaces_complete_) {
      publish_jobs_.push_back(last_published_);  // publishLoop draws it again, with them
    } else {
      return;
    }
  }
  publish_wake_.notify_one();
}

bool WorkspaceServer::publish(const PublishJob& job) {
  std::shared_ptr<const WorkspaceAnalysis> analysis = job.analysis;
  if (!analysis) {
    WorkspaceStore::Options options;
    options.policy = WorkspaceStore::Policy::CacheOnly;  // the response named this entry; never compute here
    options.load = true;
    options.warn = [](const std::string& problem) { ROS_WARN("workspace_server: %s", problem.c_str()); };
    analysis = store_.obtain(job.prepared, *job.prepared.model, job.prepared.source, options).analysis;
  }
  const ros::Time now = ros::Time::now();
  const SingularitySample singularities = sampleSingularities(*job.prepared.model, *analysis, job.prepared.display);
  sensor_msgs::PointCloud2 cloud = singularityCloud(singularities, base_frame_);
  cloud.header.stamp = now;
  singularity_map_publisher_.publish(cloud);
  const DisplayLimits& display = job.prepared.display;
  // Surfaces where the grid is over x y z, else (a plane) the cubes of the boundary cells.
  // Two meshes per working mode for a display that is off by default: made while someone
  // subscribes, else when someone does (onDisplaySubscriber).
  const bool per_mode = mode_surfaces_publisher_.getNumSubscribers() > 0;
  const DisplaySurfaces surfaces =
      display.surfaces ? displaySurfaces(*analysis, display, job.assembly_mode, per_mode) : DisplaySurfaces();
  const bool meshed = surfaces.cell_size > 0.0;
  const SurfaceSample cubes = meshed ? SurfaceSample() : sampleSurfaces(*analysis, display, job.assembly_mode);
  WorkspaceDrawing drawing;
  drawing.cubes = &cubes;
  drawing.surfaces = meshed ? &surfaces : nullptr;
  drawing.surface_alpha = static_cast<float>(display.surface_alpha);
  if (meshed && display.colour_by_conditioning) {
    for (int s = 0; s < 2; ++s) {
      if (surfaces.maximal[s].vertices.empty()) continue;
      drawing.conditioning[s] = smoothedOverMesh(
          surfaces.maximal[s],
          vertexConditioning(*job.prepared.model, *analysis, surfaces.maximal[s], s == 0 ? 1 : -1, surfaces.cell_size,
                             job.prepared.options.threads),
          kDisplayValueSmoothing);
    }
  }
  visualization_msgs::MarkerArray markers =
      hasOrientationSet(analysis->grid())
          ? coverageMarkers(*job.prepared.model, *analysis, orientationCoverage(*analysis), base_frame_, job.assembly_mode)
          : workspaceMarkers(*job.prepared.model, *analysis, drawing, base_frame_, job.assembly_mode);
  for (visualization_msgs::Marker& marker : markers.markers) marker.header.stamp = now;
  markers_publisher_.publish(markers);
  visualization_msgs::MarkerArray mode_surfaces =
      modeSurfaceMarkers(*analysis, surfaces, base_frame_, static_cast<float>(display.surface_alpha));
  for (visualization_msgs::Marker& marker : mode_surfaces.markers) marker.header.stamp = now;
  mode_surfaces_publisher_.publish(mode_surfaces);
  MaximalWorkspaceOctrees octrees = octreesMessage(*analysis, base_frame_, job.assembly_mode);
  octrees.header.stamp = now;
  octree_publisher_.publish(octrees);
  std::uint64_t triangles = 0;
  for (const SurfaceMesh& mesh : surfaces.maximal) triangles += mesh.triangles.size();
  const std::string shapes = meshed ? "surfaces of " + std::to_string(triangles) + " triangles on a " +
                                          numberText(surfaces.cell_size) + " m lattice"
                                    : std::to_string(cubes.decimation.shown) + " boundary cubes of " +
                                          numberText(cubes.cube_size) + " m";
  ROS_INFO("workspace_server: published the singularity map, %s; the workspaces as %s in %zu markers; %zu octrees "
           "at the grid's resolution",
           singularities.decimation.text().c_str(), shapes.c_str(), markers.markers.size(), octrees.octrees.size());
  return per_mode || !meshed;  // without surfaces there are none to add
}

}  // namespace maximal_workspace
