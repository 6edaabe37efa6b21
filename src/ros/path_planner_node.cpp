#include "path_planner_node.h"

#include <cmath>

#include <Eigen/Geometry>
#include <nav_msgs/Path.h>
#include <ros/package.h>
#include <visualization_msgs/MarkerArray.h>

#include "maximal_workspace/ComputeWorkspace.h"
#include "maximal_workspace/PlannedPath.h"
#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/planner/verification.h"
#include "server_settings.h"
#include "workspace_messages.h"

namespace maximal_workspace {

namespace {

std::vector<double> listParameter(ros::NodeHandle& node, const std::string& name) {
  std::vector<double> values;
  node.getParam(name, values);
  return values;
}

}  // namespace

PathPlannerNode::PathPlannerNode(ros::NodeHandle& node, ros::NodeHandle& private_node) : node_(node) {
  private_node.param<std::string>("robot_file", robot_file_,
                                  ros::package::getPath("maximal_workspace") + "/config/delta_like.yaml");
  private_node.param<std::string>("base_frame", base_frame_, "base_link");
  private_node.param<std::string>("workspace_server", workspace_server_, "workspace_server");
  private_node.param("service_timeout", service_timeout_, service_timeout_);
  private_node.param("transition_cost", costs_.transition, costs_.transition);
  private_node.param("clearance_weight", costs_.clearance_weight, costs_.clearance_weight);
  private_node.param("clearance_soft", costs_.clearance_soft, costs_.clearance_soft);
  private_node.param("heuristic_weight", heuristic_weight_, heuristic_weight_);
  private_node.param("samples_per_segment", samples_per_segment_, samples_per_segment_);
  limits_.velocity = listParameter(private_node, "max_velocity");
  limits_.acceleration = listParameter(private_node, "max_acceleration");
  path_publisher_ = node.advertise<nav_msgs::Path>("path_planner/path", 1, true);
  markers_publisher_ = node.advertise<visualization_msgs::MarkerArray>("path_planner/markers", 1, true);
  plan_publisher_ = node.advertise<PlannedPath>("path_planner/plan", 1, true);
  plan_service_ = node.advertiseService("plan_path", &PathPlannerNode::onPlanPath, this);
  ROS_INFO("path_planner: robot file %s, workspaces from %s; /plan_path ready", robot_file_.c_str(),
           node.resolveName("compute_workspace").c_str());
}

std::shared_ptr<const PathPlannerNode::Loaded> PathPlannerNode::workspace(double step) {
  // The entry is found by the request resolved here, never by a path in a response: any
  // process can answer the service.
  std::call_once(server_settings_read_, &PathPlannerNode::readServerSettings, this);
  const std::string robot_text = readTextFile(robot_file_, "robot file");
  auto model = std::make_shared<const RobotModel>(parseRobotFile(robot_text, robot_file_));
  WorkspaceRequest request;
  request.step = step;
  const ResolvedWorkspaceRequest resolved = resolveWorkspaceRequest(*model, robot_text, request, request_defaults_);
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
  compute.request.step = step;
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
  // Planners hold their analyses: a couple of steps at a time is what a client switches
  // between, and keeps the memory the store's cap allows.
  if (planners_.size() > kPlannersKept) planners_.pop_back();
  return loaded;
}

void PathPlannerNode::readServerSettings() {
  const WorkspaceServerSettings settings = workspaceServerSettings(ros::NodeHandle(node_.resolveName(workspace_server_)));
  request_defaults_ = settings.request_defaults;
  store_ = std::make_unique<WorkspaceStore>(settings.cache_directory, settings.cache_bytes);
  ROS_INFO("path_planner: workspaces from the cache %s of %s", settings.cache_directory.c_str(),
           node_.resolveName(workspace_server_).c_str());
}

bool PathPlannerNode::onPlanPath(PlanPath::Request& request, PlanPath::Response& response) {
  try {
    const std::shared_ptr<const Loaded> loaded = workspace(request.step);
    const RobotModel& model = *loaded->model;
    const WorkspaceAnalysis& analysis = *loaded->analysis;
    const std::vector<WorkingMode>& modes = analysis.modes();
    PlanRequest plan_request = resolvePathRequest(model, modes, pathRequest(request));
    plan_request.costs = costs_;
    plan_request.heuristic_weight = heuristic_weight_;

    const Plan plan = loaded->planner->plan(plan_request);
    if (!plan.success) throw InputError(plan.message);
    if (request.assembly_mode != 0 && request.assembly_mode != plan.sign) {
      throw InputError(std::string("the start is in assembly mode ") + (plan.sign > 0 ? "+" : "-") + " in working mode " +
                       modes[plan_request.start_mode].name + ", not the one asked for");
    }
    // Limits: the parameters, else by kind (1 rad/s, 2 rad/s^2 for cranks; 0.5 m/s, 1 m/s^2 for sliders).
    InputLimits limits = limits_;
    for (const Input& input : model.inputs) {
      const bool revolute = input.kind == InputKind::Revolute;
      if (limits_.velocity.empty()) limits.velocity.push_back(revolute ? 1.0 : 0.5);
      if (limits_.acceleration.empty()) limits.acceleration.push_back(revolute ? 2.0 : 1.0);
    }
    const InputTrajectory trajectory = inputTrajectory(model, analysis, plan, limits, samples_per_segment_);
    const Verification verification = verifyByDkpContinuation(model, trajectory, plan.sign);
    response.verified = verification.passed;
    response.verification = verification.message;
    if (!verification.passed) throw InputError("the plan failed its verification: " + verification.message);

    const ros::Time now = ros::Time::now();
    response.path.header.frame_id = base_frame_;
    response.path.header.stamp = now;
    response.trajectory.header.stamp = now;
    response.trajectory.joint_names = trajectory.inputs;
    const auto velocities = inputVelocities(trajectory);
    const auto accelerations = inputAccelerations(trajectory);
    for (std::size_t k = 0; k < trajectory.time.size(); ++k) {
      geometry_msgs::PoseStamped pose;
      pose.header.frame_id = base_frame_;
      pose.header.stamp = now + ros::Duration(trajectory.time[k]);
      pose.pose.position = pointMessage(trajectory.poses[k].position);
      const Eigen::Quaterniond q(trajectory.poses[k].rotation());
      pose.pose.orientation.w = q.w();
      pose.pose.orientation.x = q.x();
      pose.pose.orientation.y = q.y();
      pose.pose.orientation.z = q.z();
      response.path.poses.push_back(pose);
      response.working_modes.push_back(modes[trajectory.modes[k]].name);
      trajectory_msgs::JointTrajectoryPoint sample;
      sample.positions = trajectory.q[k];
      sample.velocities = velocities[k];
      sample.accelerations = accelerations[k];
      sample.time_from_start = ros::Duration(trajectory.time[k]);
      response.trajectory.points.push_back(sample);
    }
    for (const PlanTransition& t : plan.transitions) {
      PathTransition transition;
      transition.pose_index = static_cast<std::uint32_t>(trajectory.waypoint_samples[t.waypoint]);
      const Input& input = model.inputs[t.input];
      transition.input = input.name;
      for (int c : input.chains) transition.chains.push_back(model.chains[c]->name());
      transition.from_working_mode = modes[t.from_mode].name;
      transition.to_working_mode = modes[t.to_mode].name;
      transition.label = input.name + " " + transition.from_working_mode[t.input] + "->" + transition.to_working_mode[t.input];
      transition.point = pointMessage(plan.waypoints[t.waypoint].pose.position);
      response.transitions.push_back(transition);
    }
    response.length = plan.length;
    response.min_measure = plan.min_measure;
    response.min_measure_at = pointMessage(plan.min_measure_at.position);
    response.success = true;
    response.message = countText(plan.transitions.size(), "transition") + ", length " + numberText(plan.length) +
                       " m, duration " + numberText(trajectory.time.back()) + " s";
    publish(response, trajectory.modes);
    ROS_INFO("path_planner: %s", response.message.c_str());
  } catch (const InputError& error) {
    const std::string verification = response.verification;
    response = PlanPath::Response();
    response.success = false;
    response.message = error.what();
    response.verification = verification;
    ROS_WARN("path_planner: no plan: %s", error.what());
  } catch (const std::exception& error) {
    response = PlanPath::Response();
    response.success = false;
    response.message = std::string("internal error: ") + error.what();
    ROS_ERROR("path_planner: %s", response.message.c_str());
  }
  return true;
}

void PathPlannerNode::publish(const PlanPath::Response& response, const std::vector<int>& modes) {
  std::lock_guard<std::mutex> lock(publish_mutex_);
  path_publisher_.publish(response.path);
  PlannedPath plan;
  plan.path = response.path;
  plan.working_modes = response.working_modes;
  plan.transitions = response.transitions;
  plan.trajectory = response.trajectory;
  plan_publisher_.publish(plan);
  visualization_msgs::MarkerArray markers;
  visualization_msgs::Marker clear;
  clear.header.frame_id = base_frame_;
  clear.action = visualization_msgs::Marker::DELETEALL;
  markers.markers.push_back(clear);
  auto marker = [&](const std::string& ns, int id, int type) {
    visualization_msgs::Marker m;
    m.header = response.path.header;
    m.ns = ns;
    m.id = id;
    m.type = type;
    m.action = visualization_msgs::Marker::ADD;
    m.pose.orientation.w = 1.0;
    return m;
  };
  // One strip per stretch in one working mode, in that mode's colour.
  for (std::size_t k = 0; k + 1 < response.path.poses.size();) {
    visualization_msgs::Marker strip = marker("path", static_cast<int>(markers.markers.size()), visualization_msgs::Marker::LINE_STRIP);
    strip.scale.x = 0.025;  // wide enough to stay visible inside the translucent workspace markers
    strip.color = workingModeColour(modes[k + 1]);
    strip.points.push_back(response.path.poses[k].pose.position);
    std::size_t j = k + 1;
    while (j < response.path.poses.size() && modes[j] == modes[k + 1]) strip.points.push_back(response.path.poses[j++].pose.position);
    markers.markers.push_back(strip);
    k = j - 1;
  }
  for (std::size_t t = 0; t < response.transitions.size(); ++t) {
    visualization_msgs::Marker sphere = marker("transitions", static_cast<int>(t), visualization_msgs::Marker::SPHERE);
    sphere.pose.position = response.transitions[t].point;
    sphere.scale.x = sphere.scale.y = sphere.scale.z = 0.04;
    sphere.color.r = sphere.color.g = sphere.color.a = 1.0f;  // yellow: apart from the workspace's white ones
    markers.markers.push_back(sphere);
    visualization_msgs::Marker label = marker("transition_labels", static_cast<int>(t), visualization_msgs::Marker::TEXT_VIEW_FACING);
    label.pose.position = response.transitions[t].point;
    label.pose.position.z += 0.05;
    label.scale.z = 0.04;
    label.color.r = label.color.g = label.color.b = label.color.a = 1.0f;
    label.text = response.transitions[t].label;
    markers.markers.push_back(label);
  }
  markers_publisher_.publish(markers);
}

}  // namespace maximal_workspace
