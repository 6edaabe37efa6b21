#include "workspace_messages.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <unordered_set>

#include <Eigen/Geometry>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "maximal_workspace/io/octree_export.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

const char* signName(std::int8_t sign) { return sign > 0 ? "positive" : "negative"; }

bool keeps(std::int8_t assembly_mode, std::int8_t sign) { return assembly_mode == 0 || assembly_mode == sign; }

visualization_msgs::Marker marker(const std::string& frame, const std::string& ns, int id, int type, double scale) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = scale;
  return m;
}

}  // namespace

RequestPose requestPose(const geometry_msgs::Pose& message) {
  RequestPose pose;
  pose.position = {message.position.x, message.position.y, message.position.z};
  pose.orientation = {message.orientation.w, message.orientation.x, message.orientation.y, message.orientation.z};
  return pose;
}

PathRequest pathRequest(const PlanPath::Request& request) {
  PathRequest result;
  result.start = requestPose(request.start);
  result.goal = requestPose(request.goal);
  result.start_inputs = request.start_inputs;
  result.start_working_mode = request.start_working_mode;
  result.goal_working_mode = request.goal_working_mode;
  result.clearance = request.clearance;
  result.assembly_mode = request.assembly_mode;
  result.single_working_mode = request.single_working_mode;
  return result;
}

geometry_msgs::Point pointMessage(const Eigen::Vector3d& p) {
  geometry_msgs::Point result;
  result.x = p.x();
  result.y = p.y();
  result.z = p.z();
  return result;
}

std_msgs::ColorRGBA workingModeColour(int mode) {
  static const float kPalette[8][3] = {{0.90f, 0.10f, 0.10f}, {0.10f, 0.60f, 0.95f}, {0.15f, 0.80f, 0.20f},
                                       {0.95f, 0.65f, 0.05f}, {0.60f, 0.20f, 0.85f}, {0.05f, 0.80f, 0.75f},
                                       {0.95f, 0.35f, 0.70f}, {0.55f, 0.45f, 0.25f}};
  std_msgs::ColorRGBA colour;
  if (mode < 8) {
    colour.r = kPalette[mode][0];
    colour.g = kPalette[mode][1];
    colour.b = kPalette[mode][2];
  } else {
    // Beyond eight (uncoupled modes), hues spread by the golden angle.
    const float hue = std::fmod(mode * 0.618034f, 1.0f) * 6.0f;
    const float x = 1.0f - std::abs(std::fmod(hue, 2.0f) - 1.0f);
    const int sector = static_cast<int>(hue);
    colour.r = (sector == 0 || sector == 5) ? 1.0f : (sector == 1 || sector == 4) ? x : 0.0f;
    colour.g = (sector == 1 || sector == 2) ? 1.0f : (sector == 0 || sector == 3) ? x : 0.0f;
    colour.b = (sector == 3 || sector == 4) ? 1.0f : (sector == 2 || sector == 5) ? x : 0.0f;
  }
  colour.a = 1.0f;
  return colour;
}

sensor_msgs::PointCloud2 singularityCloud(const SingularitySample& sample, const std::string& frame) {
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = frame;
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  modifier.setPointCloud2Fields(7, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32, "z", 1,
                                sensor_msgs::PointField::FLOAT32, "working_mode", 1, sensor_msgs::PointField::UINT8, "kind",
                                1, sensor_msgs::PointField::UINT8, "chain", 1, sensor_msgs::PointField::INT8, "det", 1,
                                sensor_msgs::PointField::FLOAT32);
  modifier.resize(sample.points.size());
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z"), det(cloud, "det");
  sensor_msgs::PointCloud2Iterator<std::uint8_t> mode(cloud, "working_mode"), kind(cloud, "kind");
  sensor_msgs::PointCloud2Iterator<std::int8_t> chain(cloud, "chain");
  for (const SingularityPoint& point : sample.points) {
    *x = static_cast<float>(point.position.x());
    *y = static_cast<float>(point.position.y());
    *z = static_cast<float>(point.position.z());
    *mode = point.working_mode;
    *kind = point.kind;
    *chain = point.chain;
    *det = point.measure;
    ++x, ++y, ++z, ++mode, ++kind, ++chain, ++det;
  }
  return cloud;
}

visualization_msgs::MarkerArray workspaceMarkers(const WorkspaceAnalysis& analysis, const SurfaceSample& surfaces,
                                                 const std::string& frame, std::int8_t assembly_mode) {
  const Grid& grid = analysis.grid();
  visualization_msgs::MarkerArray markers;
  visualization_msgs::Marker clear;
  clear.header.frame_id = frame;
  clear.action = visualization_msgs::Marker::DELETEALL;
  markers.markers.push_back(clear);
  const double total = analysis.workspaceVolume();
  double top = grid.spec().start.position.z(), bottom = top;
  for (const auto& per_sign : surfaces.cubes) {
    for (const auto& cubes : per_sign) {
      for (const Eigen::Vector3d& centre : cubes) top = std::max(top, centre.z()), bottom = std::min(bottom, centre.z());
    }
  }
  // Labels 5 cm high over a workspace a metre or more high (the delta-like robot's), in
  // proportion over smaller ones (the deltas'), so they stay readable beside the robot.
  const double text_height = std::clamp(0.04 * (top - bottom), 0.02, 0.05);
  const std::vector<Region>& regions = analysis.regions();
  const TransitionGraph& graph = analysis.transitions();
  for (const AssemblyModeSummary& am : analysis.assemblyModes()) {
    if (!keeps(assembly_mode, am.sign)) continue;
    const std::string name = signName(am.sign);
    const auto& per_mode = surfaces.cubes[am.sign > 0 ? 0 : 1];
    for (std::size_t m = 0; m < per_mode.size(); ++m) {
      visualization_msgs::Marker cubes =
          marker(frame, "maximal_" + name, static_cast<int>(m), visualization_msgs::Marker::CUBE_LIST, surfaces.cube_size);
      cubes.color = workingModeColour(static_cast<int>(m));
      cubes.color.a = 0.12f;  // shells of several modes overlap and the robot is inside: see through
      for (const Eigen::Vector3d& centre : per_mode[m]) cubes.points.push_back(pointMessage(centre));
      if (!cubes.points.empty()) markers.markers.push_back(cubes);
    }
    // Transition points between real regions of this assembly mode, thinned to about a
    // thousand: enough to see where working modes meet without hiding the rest.
    std::unordered_set<std::uint32_t> points;
    for (const Transition& t : graph.transitions) {
      if (t.sign != am.sign || regions[t.from_region].debris || regions[t.to_region].debris) continue;
      points.insert(t.points.begin(), t.points.end());
    }
    std::vector<std::uint32_t> sorted(points.begin(), points.end());
    std::sort(sorted.begin(), sorted.end());
    const std::size_t stride = std::max<std::size_t>(1, sorted.size() / 1000);
    visualization_msgs::Marker spheres =
        marker(frame, "transitions_" + name, 0, visualization_msgs::Marker::SPHERE_LIST, 0.6 * surfaces.cube_size);
    spheres.color.r = spheres.color.g = spheres.color.b = spheres.color.a = 1.0f;
    for (std::size_t i = 0; i < sorted.size(); i += stride) {
      spheres.points.push_back(pointMessage(graph.points[sorted[i]].pose.position));
    }
    if (!spheres.points.empty()) markers.markers.push_back(spheres);
    visualization_msgs::Marker label = marker(frame, "label_" + name, 0,
                                              visualization_msgs::Marker::TEXT_VIEW_FACING, text_height);
    char text[200];
    std::snprintf(text, sizeof text, "assembly mode %s: maximal %.1f %%, traditional %.1f %%, reachable %.1f %% (%s)",
                  am.sign > 0 ? "+" : "-", 100 * am.maximal_volume / total, 100 * am.traditional_volume / total,
                  100 * am.reachable_volume / total, marginText(analysis.settings().margin).c_str());
    label.text = text;
    label.pose.position = pointMessage(grid.spec().start.position);
    label.pose.position.z = top + (am.sign > 0 ? 6.0 : 4.4) * text_height;
    label.color.r = label.color.g = label.color.b = label.color.a = 1.0f;
    markers.markers.push_back(label);
  }
  return markers;
}

MaximalWorkspaceOctrees octreesMessage(const WorkspaceAnalysis& analysis, const std::string& frame,
                                       std::int8_t assembly_mode) {
  MaximalWorkspaceOctrees message;
  message.header.frame_id = frame;
  message.margin = analysis.settings().margin;
  std::string why_not;
  if (!octreeExportable(analysis.grid(), &why_not)) return message;
  for (std::int8_t sign : {1, -1}) {
    if (!keeps(assembly_mode, sign)) continue;
    const std::unique_ptr<octomap::OcTree> tree = maximalWorkspaceOctree(analysis, sign);
    std::stringstream bytes;
    tree->writeBinaryData(bytes);
    const std::string data = bytes.str();
    Octree octree;
    octree.header.frame_id = frame;
    octree.binary = true;
    octree.id = tree->getTreeType();
    octree.resolution = tree->getResolution();
    octree.data.assign(data.begin(), data.end());
    message.signs.push_back(sign);
    message.octrees.push_back(octree);
  }
  return message;
}

void fillResponse(const nlohmann::json& summary, std::int8_t assembly_mode, ComputeWorkspace::Response& response) {
  response.margin = summary["options"]["margin"].get<double>();
  response.workspace_volume = summary["workspace"]["volume"].get<double>();
  response.volume_unit = summary["grid"]["volume_unit"].get<std::string>();
  response.transitions = 0;
  for (const nlohmann::json& am : summary["assembly_modes"]) {
    const std::int8_t sign = static_cast<std::int8_t>(am["sign"].get<int>());
    if (!keeps(assembly_mode, sign)) continue;
    AssemblyModeVolumes volumes;
    volumes.sign = sign;
    volumes.maximal_volume = am["maximal_volume"].get<double>();
    volumes.traditional_volume = am["traditional_volume"].get<double>();
    volumes.reachable_volume = am["reachable_volume"].get<double>();
    volumes.regions = am["regions"].get<std::uint32_t>();
    volumes.debris_regions = am["debris_regions"].get<std::uint32_t>();
    volumes.transitions = am["transitions"].get<std::uint32_t>();
    volumes.groups = am["components"].get<std::uint32_t>();
    response.transitions += volumes.transitions;
    response.assembly_modes.push_back(volumes);
  }
  for (const nlohmann::json& mode : summary["volumes_per_mode"]) {
    for (std::int8_t sign : {1, -1}) {
      if (!keeps(assembly_mode, sign)) continue;
      const nlohmann::json& figures = mode[sign > 0 ? "positive" : "negative"];
      ModeRegions regions;
      regions.working_mode = mode["mode"].get<std::string>();
      regions.sign = sign;
      regions.regions = figures["regions"].get<std::uint32_t>();
      regions.debris_regions = figures["debris"].get<std::uint32_t>();
      regions.volume = figures["volume"].get<double>();
      response.working_modes.push_back(regions);
    }
  }
}

}  // namespace maximal_workspace
