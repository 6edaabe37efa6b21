#include "path_planner_node.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <utility>

#include <Eigen/Geometry>
#include <boost/make_shared.hpp>
#include <nav_msgs/Path.h>
#include <ros/callback_queue_interface.h>
#include <ros/package.h>
#include <tf2/exceptions.h>
#include <visualization_msgs/MarkerArray.h>

#include "label_layout.h"
#include "maximal_workspace/ComputeWorkspace.h"
#include "maximal_workspace/PlannedPath.h"
#include "maximal_workspace/description/robot_description.h"
#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_cache.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/planner/planning.h"
#include "server_settings.h"
#include "workspace_messages.h"

namespace maximal_workspace {

namespace {

std::vector<double> listParameter(ros::NodeHandle& node, const std::string& name) {
  std::vector<double> values;
  node.getParam(name, values);
  return values;
}

// The grid's largest side along x, y, z (m): the scale markers are drawn at.
double spatialSize(const Grid& grid) {
  double size = 0.0;
  for (int d = 0; d < grid.dims(); ++d) {
    const OutputVariable variable = grid.spec().variables[d];
    if (variable == OutputVariable::X || variable == OutputVariable::Y || variable == OutputVariable::Z) {
      size = std::max(size, static_cast<double>(grid.size(d)) * grid.step(d));
    }
  }
  return size;
}

// A reason cut into lines a text marker can show beside a goal.
std::string wrapped(const std::string& text) {
  constexpr std::size_t kWidth = 60, kLines = 4;
  std::string result;
  std::size_t line = 0, lines = 1;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (line >= kWidth && text[i] == ' ') {
      if (++lines > kLines) return result + " ...";
      result += '\n';
      line = 0;
      continue;
    }
    result += text[i];
    ++line;
  }
  return result;
}

visualization_msgs::InteractiveMarker goalMarker(const std::string& frame, const Eigen::Vector3d& at, double scale) {
  visualization_msgs::InteractiveMarker goal;
  goal.header.frame_id = frame;
  goal.name = "goal";
  goal.description = "goal";
  goal.pose.position = pointMessage(at);
  goal.pose.orientation.w = 1.0;
  goal.scale = scale;
  visualization_msgs::InteractiveMarkerControl ball;
  ball.name = "move_3d";
  ball.interaction_mode = visualization_msgs::InteractiveMarkerControl::MOVE_3D;
  ball.always_visible = true;
  visualization_msgs::Marker sphere;
  sphere.type = visualization_msgs::Marker::SPHERE;
  sphere.scale.x = sphere.scale.y = sphere.scale.z = 0.2 * scale;
  sphere.color.r = 1.0f, sphere.color.g = 0.5f, sphere.color.a = 1.0f;  // orange: no working mode's colour
  ball.markers.push_back(sphere);
  goal.controls.push_back(ball);
  // Arrows along x, y, z: a drag of the ball alone moves in the view's plane. Each control
  // moves along its own x axis, which these unit quaternions (w, x, y, z) turn onto the base
  // frame's x, y and z (interactive_markers' convention).
  const double half = std::sqrt(0.5);
  const std::pair<const char*, std::array<double, 4>> axes[3] = {
      {"move_x", {half, half, 0.0, 0.0}}, {"move_y", {half, 0.0, 0.0, half}}, {"move_z", {half, 0.0, half, 0.0}}};
  for (const auto& [name, q] : axes) {
    visualization_msgs::InteractiveMarkerControl arrow;
    arrow.name = name;
    arrow.interaction_mode = visualization_msgs::InteractiveMarkerControl::MOVE_AXIS;
    arrow.orientation.w = q[0];
    arrow.orientation.x = q[1];
    arrow.orientation.y = q[2];
    arrow.orientation.z = q[3];
    goal.controls.push_back(arrow);
  }
  return goal;
}

// A number parameter of this node within [low, high]; out of it, or not a number, the
// default, and a warning that says so.
double rangedParameter(ros::NodeHandle& node, const std::string& name, double fallback, double low, double high) {
  double value = fallback;
  node.param(name, value, fallback);
  if (value >= low && value <= high) return value;
  ROS_WARN("path_planner: parameter %s = %g is not in [%g, %g]; using %g", name.c_str(), value, low, high, fallback);
  return fallback;
}

// A function for a callback queue: runs it once.
class CallOnce : public ros::CallbackInterface {
 public:
  explicit CallOnce(std::function<void()> call) : call_(std::move(call)) {}
  CallResult call() override {
    call_();
    return Success;
  }

 private:
  std::function<void()> call_;
};

// A marker added in `header`'s frame, unrotated.
visualization_msgs::Marker newMarker(const std_msgs::Header& header, const std::string& ns, int id, int type) {
  visualization_msgs::Marker m;
  m.header = header;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  return m;
}

// One strip per stretch of the path in one working mode (modes[k]: the pose k's), in that
// mode's colour.
void addPathStrips(const nav_msgs::Path& path, const std::vector<int>& modes, double width,
                   visualization_msgs::MarkerArray& markers) {
  for (std::size_t k = 0; k + 1 < path.poses.size();) {
    visualization_msgs::Marker strip =
        newMarker(path.header, "path", static_cast<int>(markers.markers.size()), visualization_msgs::Marker::LINE_STRIP);
    strip.scale.x = width;
    strip.color = workingModeColour(modes[k + 1]);
    strip.points.push_back(path.poses[k].pose.position);
    std::size_t j = k + 1;
    while (j < path.poses.size() && modes[j] == modes[k + 1]) strip.points.push_back(path.poses[j++].pose.position);
    markers.markers.push_back(strip);
    k = j - 1;
  }
}

}  // namespace

PathPlannerNode::PathPlannerNode(ros::NodeHandle& node, ros::NodeHandle& private_node) : node_(node) {
  private_node.param<std::string>("robot_file", robot_file_,
                                  ros::package::getPath("maximal_workspace") + "/config/delta_like.yaml");
  private_node.param<std::string>("base_frame", base_frame_, "base_link");
  private_node.param<std::string>("workspace_server", workspace_server_, "workspace_server");
  // Its own, read once: a parameter of another node's namespace, read at a request, let any
  // client redirect this planner's cache (issue 28). The launch files give both nodes the same.
  private_node.param<std::string>("cache_directory", cache_directory_, defaultCacheDirectory());
  service_timeout_ = rangedParameter(private_node, "service_timeout", service_timeout_, 1e-3, 3600.0);
  costs_.transition = rangedParameter(private_node, "transition_cost", costs_.transition, 0.0, 1000.0);
  time_limit_ = rangedParameter(private_node, "time_limit", time_limit_, 1e-3, 3600.0);
  heuristic_weight_ = rangedParameter(private_node, "heuristic_weight", heuristic_weight_, 1.0, 100.0);
  samples_per_segment_ = static_cast<int>(rangedParameter(private_node, "samples_per_segment", samples_per_segment_, 2, 100000));
  memory_bytes_ = static_cast<std::uint64_t>(
      rangedParameter(private_node, "memory_bytes", static_cast<double>(memory_bytes_), 0.0, 1e15));
  limits_.velocity = listParameter(private_node, "max_velocity");
  limits_.acceleration = listParameter(private_node, "max_acceleration");
  path_publisher_ = node.advertise<nav_msgs::Path>("path_planner/path", 1, true);
  markers_publisher_ = node.advertise<visualization_msgs::MarkerArray>("path_planner/markers", 1, true);
  plan_publisher_ = node.advertise<PlannedPath>("path_planner/plan", 1, true);
  plan_service_ = node.advertiseService("plan_path", &PathPlannerNode::onPlanPath, this);
  std::string current_pose_topic;
  private_node.param<std::string>("current_pose_topic", current_pose_topic, "robot_pose_publisher/current_pose");
  current_pose_ = node.subscribe(current_pose_topic, 1, &PathPlannerNode::onCurrentPose, this);
  clicked_point_ = node.subscribe("clicked_point", 1, &PathPlannerNode::onClickedPoint, this);
  bool interactive_goal = true;
  private_node.param("interactive_goal", interactive_goal, interactive_goal);
  if (interactive_goal) {
    // At the reference pose to begin with: inside the workspace, beside the robot.
    Eigen::Vector3d at = Eigen::Vector3d::Zero();
    double scale = 0.3;
    try {
      const RobotModel model = loadRobotFile(robot_file_);
      at = model.reference.pose.position;
      // In proportion to the robot: arrows a third of its longest rod.
      double rod = 0.0;
      for (const ChainPtr& chain : model.chains) rod = std::max(rod, chain->rodLength());
      scale = 0.35 * rod;
    } catch (const InputError& error) {
      ROS_ERROR("path_planner: %s; every request will fail until the robot file is fixed", error.what());
    }
    goal_marker_ = std::make_unique<interactive_markers::InteractiveMarkerServer>("path_planner/goal");
    goal_marker_->insert(goalMarker(base_frame_, at, scale),
                         [this](const visualization_msgs::InteractiveMarkerFeedbackConstPtr& f) { onGoalMarker(f); });
    goal_marker_->applyChanges();
  }
  ROS_INFO("path_planner: robot file %s, workspaces from %s; /plan_path ready; goals from %s%s, from the robot's "
           "configuration on %s",
           robot_file_.c_str(), node.resolveName("compute_workspace").c_str(), node.resolveName("clicked_point").c_str(),
           interactive_goal ? " and the interactive marker path_planner/goal" : "",
           node.resolveName(current_pose_topic).c_str());
}

void PathPlannerNode::onCurrentPose(const RobotPose& pose) {
  std::lock_guard<std::mutex> lock(current_mutex_);
  current_ = pose;
}

void PathPlannerNode::onClickedPoint(const geometry_msgs::PointStamped& point) {
  const std::string source = node_.resolveName("clicked_point");
  if (refusedNonFinite(point.point, source)) return;
  planToGoal(point.point, point.header.frame_id, source);
}

bool PathPlannerNode::refusedNonFinite(const geometry_msgs::Point& goal, const std::string& source) {
  if (std::isfinite(goal.x) && std::isfinite(goal.y) && std::isfinite(goal.z)) return false;
  const std::string why =
      "no plan: a goal from " + source + " must be finite, got " + vectorText(Eigen::Vector3d(goal.x, goal.y, goal.z));
  ROS_WARN("path_planner: %s", why.c_str());
  // Shown at the frame's origin: beside a NaN goal rviz never draws it.
  std::lock_guard<std::mutex> lock(publish_mutex_);
  publishMarkers(why, geometry_msgs::Point());
  return true;
}

void PathPlannerNode::onGoalMarker(const visualization_msgs::InteractiveMarkerFeedbackConstPtr& feedback) {
  // Plan once the marker is let go, not at every step of the drag.
  if (feedback->event_type != visualization_msgs::InteractiveMarkerFeedback::MOUSE_UP) return;
  if (refusedNonFinite(feedback->pose.position, "the goal marker")) return;
  // The marker server calls this under its own lock, which every plan's end takes to move
  // the marker: planned here, a goal would hold it for a whole plan (a workspace
  // computation, even) and lock against publish_mutex_ (issue 28). The goal goes to a
  // spinner thread instead; of goals let go meanwhile only the newest is planned, as
  // /clicked_point keeps one.
  std::lock_guard<std::mutex> lock(marker_goal_mutex_);
  marker_goal_ = MarkerGoal{feedback->pose.position, feedback->header.frame_id};
  if (std::exchange(marker_goal_queued_, true)) return;  // the spinner thread planning them takes it
  node_.getCallbackQueue()->addCallback(boost::make_shared<CallOnce>([this] { planMarkerGoals(); }));
}

void PathPlannerNode::planMarkerGoals() {
  while (true) {
    MarkerGoal goal;
    {
      std::lock_guard<std::mutex> lock(marker_goal_mutex_);
      if (!marker_goal_) {
        marker_goal_queued_ = false;
        return;
      }
      goal = *std::exchange(marker_goal_, std::nullopt);
    }
    planToGoal(goal.position, goal.frame, "the goal marker");
  }
}

void PathPlannerNode::planToGoal(const geometry_msgs::Point& goal, const std::string& frame, const std::string& source) {
  geometry_msgs::Point in_base = goal;
  if (!frame.empty() && frame != base_frame_) {
    try {
      const geometry_msgs::TransformStamped t = tf_buffer_.lookupTransform(base_frame_, frame, ros::Time(0), ros::Duration(0.5));
      const Eigen::Quaterniond q(t.transform.rotation.w, t.transform.rotation.x, t.transform.rotation.y,
                                 t.transform.rotation.z);
      const Eigen::Vector3d p = q * Eigen::Vector3d(goal.x, goal.y, goal.z) +
                                Eigen::Vector3d(t.transform.translation.x, t.transform.translation.y, t.transform.translation.z);
      in_base = pointMessage(p);
    } catch (const tf2::TransformException& error) {
      const std::string why = "a goal from " + source + " in frame '" + frame + "' cannot be put in " + base_frame_ + ": " +
                              error.what();
      ROS_WARN("path_planner: %s", why.c_str());
      std::lock_guard<std::mutex> lock(publish_mutex_);
      publishMarkers(why, goal);
      return;
    }
  }
  ROS_INFO("path_planner: goal %s from %s", vectorText(Eigen::Vector3d(in_base.x, in_base.y, in_base.z)).c_str(),
           source.c_str());
  PlanPath::Request request;  // start left out: the robot's current configuration
  request.goal.position = in_base;
  PlanPath::Response response;
  plan(request, response, true);
  if (!response.success) {
    std::lock_guard<std::mutex> lock(publish_mutex_);
    publishMarkers("no plan: " + response.message, in_base);
  }
}

std::shared_ptr<const PathPlannerNode::Loaded> PathPlannerNode::workspace(const PlanPath::Request& plan, double margin) {
  // The entry is found by the request resolved here, never by a path in a response: any
  // process can answer the service.
  std::call_once(server_cache_opened_, &PathPlannerNode::openServerCache, this);
  const std::string robot_text = readTextFile(robot_file_, "robot file");
  auto model = std::make_shared<const RobotModel>(parseRobotFile(robot_text, robot_file_));
  WorkspaceRequest request;
  request.step = plan.step;
  request.margin = margin;
  request.tilt_max = plan.tilt_max;
  request.torsion = plan.torsion;
  request.angle_step = plan.angle_step;
  request.bounds = plan.bounds;
  request.working_modes = plan.working_modes;
  // The server's defaults as they are now: they may have changed since its last request.
  const WorkspaceServerSettings settings = workspaceServerSettings(ros::NodeHandle(node_.resolveName(workspace_server_)));
  const ResolvedWorkspaceRequest resolved = resolveWorkspaceRequest(*model, robot_text, request, settings.request_defaults);
  {
    // A workspace planned on already: its planner is ready (the key covers the robot file).
    std::lock_guard<std::mutex> lock(planners_mutex_);
    for (const auto& held : planners_) {
      if (held.first == resolved.key) return held.second;
    }
  }
  const std::string service = node_.resolveName("compute_workspace");
  if (!ros::service::waitForService(service, ros::Duration(service_timeout_))) {
    throw InputError("the service " + service + " is not available after " + numberText(service_timeout_) +
                     " s: start workspace_server (roslaunch maximal_workspace workspace.launch)");
  }
  ComputeWorkspace compute;
  compute.request.step = plan.step;
  compute.request.margin = margin;
  compute.request.tilt_max = plan.tilt_max;
  compute.request.torsion = plan.torsion;
  compute.request.angle_step = plan.angle_step;
  compute.request.bounds = plan.bounds;
  compute.request.working_modes = plan.working_modes;
  compute.request.keep_topics = true;  // what rviz shows stays the user's
  if (!ros::service::call(service, compute)) throw InputError("the call to " + service + " failed");
  if (!compute.response.success) throw InputError("the workspace cannot be computed: " + compute.response.message);
  WorkspaceStore::Options options;
  options.policy = WorkspaceStore::Policy::CacheOnly;
  options.load = true;
  options.warn = [](const std::string& problem) { ROS_WARN("path_planner: %s", problem.c_str()); };
  const WorkspaceStore::Entry entry =
      store_->obtain(resolved, *model, RobotSource{robot_file_, hex64(fnv1a64(robot_text))}, options);
  if (entry.origin == WorkspaceStore::Origin::Cache) {
    ROS_INFO("path_planner: workspace of %s read from %s", resolved.description.c_str(), entry.path.c_str());
  }
  auto loaded = std::make_shared<Loaded>();
  loaded->model = model;
  loaded->analysis = entry.analysis;
  loaded->planner = std::make_unique<PathPlanner>(*loaded->model, *loaded->analysis);
  std::lock_guard<std::mutex> lock(planners_mutex_);
  planners_.emplace_front(resolved.key, loaded);
  // The planners are the only holders of the analyses (the store keeps none here): the
  // oldest go while together they are over memory_bytes, the newest stays (it is in use).
  std::uint64_t total = 0;
  for (const auto& held : planners_) total += held.second->analysis->memoryBytes();
  while (planners_.size() > 1 && total > memory_bytes_) {
    total -= planners_.back().second->analysis->memoryBytes();
    planners_.pop_back();
  }
  return loaded;
}

void PathPlannerNode::openServerCache() {
  // Memory cap 0: the store holds no analysis; the planners hold theirs, within memory_bytes.
  // The cache cap does not apply: this store only reads.
  store_ = std::make_unique<WorkspaceStore>(cache_directory_, WorkspaceStore::kDefaultCacheBytes, 0);
  ROS_INFO("path_planner: workspaces from the cache %s, which %s computes into", cache_directory_.c_str(),
           node_.resolveName(workspace_server_).c_str());
}

bool PathPlannerNode::onPlanPath(PlanPath::Request& request, PlanPath::Response& response) {
  plan(request, response, false);
  return true;  // the outcome is in the response
}

std::string PathPlannerNode::startFromTheRobot(const RobotModel& model, PathRequest& request) {
  std::lock_guard<std::mutex> lock(current_mutex_);
  if (!current_.working_mode.empty()) {
    request.start = requestPose(current_.pose);
    request.start_working_mode = current_.working_mode;
    return "from the robot's configuration " +
           vectorText(Eigen::Vector3d(current_.pose.position.x, current_.pose.position.y, current_.pose.position.z)) +
           " in " + current_.working_mode;
  }
  const Eigen::Vector3d& at = model.reference.pose.position;
  request.start.position = {at.x(), at.y(), at.z()};
  return "from the reference configuration (no robot display on " + current_pose_.getTopic() + ")";
}

PlanSettings PathPlannerNode::planSettings(const RobotModel& model) const {
  PlanSettings settings;
  // Limits: the parameters, else by kind (1 rad/s, 2 rad/s^2 for cranks; 0.5 m/s, 1 m/s^2
  // for sliders). The shipped config lists the delta-like robot's three inputs: lists of
  // another length are for another robot, and give way to the defaults with a warning.
  auto perInput = [&](const std::vector<double>& listed, const char* name, double revolute, double prismatic) {
    if (static_cast<int>(listed.size()) == model.inputCount()) return listed;
    if (!listed.empty()) {
      ROS_WARN_ONCE("path_planner: ~%s lists %zu values but %s has %d inputs: the defaults by input kind are used", name,
                    listed.size(), model.name.c_str(), model.inputCount());
    }
    std::vector<double> values;
    for (const Input& input : model.inputs) values.push_back(input.kind == InputKind::Revolute ? revolute : prismatic);
    return values;
  };
  settings.limits.velocity = perInput(limits_.velocity, "max_velocity", 1.0, 0.5);
  settings.limits.acceleration = perInput(limits_.acceleration, "max_acceleration", 2.0, 1.0);
  settings.samples_per_segment = samples_per_segment_;
  return settings;
}

void PathPlannerNode::plan(PlanPath::Request request, PlanPath::Response& response, bool play) {
  try {
    if (!(request.clearance >= 0.0 && request.clearance < 1.0)) throw InputError("clearance must be in [0, 1)");
    const double clearance = request.clearance > 0.0 ? request.clearance : kDefaultPlanClearance;
    // Plans are made on the analysis at the clearance; the server's own margin explains a refusal.
    const double server_margin =
        workspaceServerSettings(ros::NodeHandle(node_.resolveName(workspace_server_))).request_defaults.options.margin;
    const std::shared_ptr<const Loaded> loaded = workspace(request, planningMargin(server_margin, clearance));
    const RobotModel& model = *loaded->model;
    const std::vector<WorkingMode>& modes = loaded->analysis->modes();
    PathRequest path_request = pathRequest(request);
    const std::string start_text = startLeftOut(path_request) ? startFromTheRobot(model, path_request) : "";
    PlanRequest plan_request = resolvePathRequest(model, modes, path_request);
    plan_request.costs = costs_;
    plan_request.heuristic_weight = heuristic_weight_;
    if (path_request.time_limit == 0.0) plan_request.time_limit = time_limit_;

    PlanSettings settings = planSettings(model);
    settings.request_margin = server_margin;
    settings.analysis_at = [&](double margin) { return workspace(request, margin)->analysis; };
    const PlanOutcome outcome = planPath(model, *loaded->planner, plan_request, settings);
    response.plan_time = outcome.seconds;
    response.workable_clearance = outcome.workable_clearance;
    const Plan& plan = outcome.plan;
    if (!plan.success) throw InputError(outcome.message);
    if (request.assembly_mode != 0 && request.assembly_mode != plan.sign) {
      throw InputError(std::string("the start is in assembly mode ") + (plan.sign > 0 ? "+" : "-") + " in working mode " +
                       modes[plan_request.start_mode].name + ", not the one asked for");
    }
    response.verified = outcome.verification.passed;
    response.verification = outcome.verification.message;
    if (!outcome.success) throw InputError(outcome.message);

    planResponse(model, modes, outcome, base_frame_, response);
    response.success = true;
    response.message = countText(plan.transitions.size(), "transition") + ", length " + numberText(plan.length) +
                       " m, duration " + numberText(outcome.trajectory.time.back()) + " s" +
                       (start_text.empty() ? "" : ", " + start_text);
    publish(model, response, outcome.trajectory.modes, spatialSize(loaded->analysis->grid()), play);
    ROS_INFO("path_planner: %s", response.message.c_str());
  } catch (const InputError& error) {
    const std::string verification = response.verification;
    const double plan_time = response.plan_time, workable_clearance = response.workable_clearance;
    response = PlanPath::Response();
    response.success = false;
    response.message = error.what();
    response.verification = verification;
    response.plan_time = plan_time;
    response.workable_clearance = workable_clearance;
    ROS_WARN("path_planner: no plan: %s", error.what());
  } catch (const std::exception& error) {
    response = PlanPath::Response();
    response.success = false;
    response.message = std::string("internal error: ") + error.what();
    ROS_ERROR("path_planner: %s", response.message.c_str());
  }
}

void PathPlannerNode::publish(const RobotModel& model, const PlanPath::Response& response, const std::vector<int>& modes,
                              double workspace_size, bool play) {
  std::unique_lock<std::mutex> lock(publish_mutex_);
  path_publisher_.publish(response.path);
  PlannedPath plan;
  plan.path = response.path;
  plan.working_modes = response.working_modes;
  plan.transitions = response.transitions;
  plan.trajectory = response.trajectory;
  plan.play = play;
  plan_publisher_.publish(plan);
  visualization_msgs::MarkerArray markers;
  auto marker = [&](const std::string& ns, int id, int type) { return newMarker(response.path.header, ns, id, type); };
  // Sizes in proportion to the workspace, so that the path reads through the translucent
  // workspace markers at the default view of a metre-size robot and of a small one.
  const double width = std::clamp(0.022 * workspace_size, 0.008, 0.04);
  const double text_height = std::clamp(0.05 * workspace_size, 0.03, 0.08);
  addPathStrips(response.path, modes, width, markers);
  // The labels beside their spheres, away from the robot's centre, merged where close, and
  // white: the spheres are yellow and the robot's links yellow-green.
  std::vector<Callout> callouts;
  for (const PathTransition& transition : response.transitions) {
    callouts.push_back({transition.label, Eigen::Vector3d(transition.point.x, transition.point.y, transition.point.z)});
  }
  const ScreenAxes axes = ScreenAxes::defaultView();
  Eigen::AlignedBox3d path_box;  // in view coordinates
  for (const geometry_msgs::PoseStamped& pose : response.path.poses) {
    path_box.extend(axes.toView(Eigen::Vector3d(pose.pose.position.x, pose.pose.position.y, pose.pose.position.z)));
  }
  const Eigen::AlignedBox3d extent = drawnRobotBox(model, path_box, axes.view);
  const std::vector<PlacedCallout> labels = placeCallouts(axes, callouts, extent, text_height);
  std_msgs::ColorRGBA yellow;
  yellow.r = yellow.g = yellow.a = 1.0f;  // apart from the workspace's white balls
  visualization_msgs::Marker leaders = marker("transition_leaders", 0, visualization_msgs::Marker::LINE_LIST);
  leaders.scale.x = 0.15 * width;
  leaders.color = yellow;
  for (std::size_t t = 0; t < labels.size(); ++t) {
    visualization_msgs::Marker label = marker("transition_labels", static_cast<int>(t), visualization_msgs::Marker::TEXT_VIEW_FACING);
    label.pose.position = pointMessage(labels[t].position);
    label.scale.z = text_height;
    label.color.r = label.color.g = label.color.b = label.color.a = 1.0f;
    label.text = labels[t].text;
    markers.markers.push_back(label);
    for (const Eigen::Vector3d& point : labels[t].points) {
      visualization_msgs::Marker sphere =
          marker("transitions", static_cast<int>(leaders.points.size() / 2), visualization_msgs::Marker::SPHERE);
      sphere.pose.position = pointMessage(point);
      sphere.scale.x = sphere.scale.y = sphere.scale.z = 2.5 * width;
      sphere.color = yellow;
      markers.markers.push_back(sphere);
      leaders.points.push_back(pointMessage(labels[t].leader_start));
      leaders.points.push_back(pointMessage(point));
    }
  }
  if (!leaders.points.empty()) markers.markers.push_back(leaders);
  label_boxes_ = calloutBoxes(axes, labels, text_height);
  label_depth_ = extent.max().z();
  path_markers_ = markers;
  publishMarkers("", geometry_msgs::Point());
  if (!goal_marker_) return;
  // The goal marker stands where the last plan ends, ready to be dragged on from there.
  goal_pose_.position = response.path.poses.back().pose.position;
  goal_pose_.orientation.w = 1.0;
  ++goal_pose_version_;
  lock.unlock();
  moveGoalMarker();
}

void PathPlannerNode::moveGoalMarker() {
  // Called without publish_mutex_: the marker server's calls take its own lock, under which
  // it calls onGoalMarker; holding publish_mutex_ across them ordered the two locks both
  // ways and deadlocked (issue 28). A plan published meanwhile may have set its pose
  // before this one's older pose: set again until the newest pose was the last set.
  std::uint64_t moved = 0;
  while (true) {
    geometry_msgs::Pose pose;
    {
      std::lock_guard<std::mutex> lock(publish_mutex_);
      if (goal_pose_version_ == moved) return;
      moved = goal_pose_version_;
      pose = goal_pose_;
    }
    goal_marker_->setPose("goal", pose);
    goal_marker_->applyChanges();
  }
}

void PathPlannerNode::publishMarkers(const std::string& goal_note, const geometry_msgs::Point& goal) {
  visualization_msgs::MarkerArray markers;
  visualization_msgs::Marker clear;
  clear.header.frame_id = base_frame_;
  clear.action = visualization_msgs::Marker::DELETEALL;
  markers.markers.push_back(clear);
  markers.markers.insert(markers.markers.end(), path_markers_.markers.begin(), path_markers_.markers.end());
  if (!goal_note.empty()) {
    // Red, beside the goal: the reason in the view where the goal was picked. To its left,
    // away from the legend (right of the drawing), and clear of the last plan's labels.
    constexpr double kNoteHeight = 0.07;  // the size of the transitions' labels on a metre-size robot
    const ScreenAxes axes = ScreenAxes::defaultView();
    const std::string text = wrapped(goal_note);
    visualization_msgs::Marker note;
    note.header.frame_id = base_frame_;
    note.header.stamp = ros::Time::now();
    note.ns = "goal_note";
    note.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    note.action = visualization_msgs::Marker::ADD;
    const Eigen::Vector3d at(goal.x, goal.y, goal.z);
    note.pose.position =
        pointMessage(placeNote(axes, at, textSize(text, kNoteHeight), label_boxes_, kNoteHeight, label_depth_));
    note.pose.orientation.w = 1.0;
    note.scale.z = kNoteHeight;
    note.color.r = note.color.a = 1.0f;
    note.color.g = note.color.b = 0.3f;
    note.text = text;
    markers.markers.push_back(note);
    visualization_msgs::Marker cross = note;
    cross.ns = "goal_note_point";
    cross.type = visualization_msgs::Marker::SPHERE;
    cross.pose.position = goal;
    cross.scale.x = cross.scale.y = cross.scale.z = 0.04;
    cross.text.clear();
    markers.markers.push_back(cross);
  }
  markers_publisher_.publish(markers);
}

}  // namespace maximal_workspace
