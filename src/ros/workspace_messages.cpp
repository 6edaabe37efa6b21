#include "workspace_messages.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <sstream>

#include <Eigen/Geometry>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "label_layout.h"
#include "maximal_workspace/description/robot_description.h"
#include "maximal_workspace/io/octree_export.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/surfaces/vertex_conditioning.h"

namespace maximal_workspace {

namespace {

// Surfaces drawn in rviz: smoothed a little (cells' corners otherwise show as facets), and
// at most this many triangles, which rviz redraws interactively.
const MeshOptions kDisplayMesh{10, 200000};
// The share of a surface's colour it keeps where it faces away from the light.
constexpr double kAmbientLight = 0.55;
// Cubes around a surface: smaller than their cells and translucent, so that the surface
// shows through them.
constexpr float kShellAlpha = 0.3f;
constexpr double kShellCubeSize = 0.5;

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

// A marker array that first deletes what the topic showed.
visualization_msgs::MarkerArray clearingMarkers(const std::string& frame) {
  visualization_msgs::MarkerArray markers;
  visualization_msgs::Marker clear;
  clear.header.frame_id = frame;
  clear.action = visualization_msgs::Marker::DELETEALL;
  markers.markers.push_back(clear);
  return markers;
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
  result.time_limit = request.time_limit;
  result.assembly_mode = request.assembly_mode;
  result.single_working_mode = request.single_working_mode;
  result.tilt_max = request.tilt_max;
  result.torsion = request.torsion;
  result.angle_step = request.angle_step;
  return result;
}

geometry_msgs::Point pointMessage(const Eigen::Vector3d& p) {
  geometry_msgs::Point result;
  result.x = p.x();
  result.y = p.y();
  result.z = p.z();
  return result;
}

void planResponse(const RobotModel& model, const std::vector<WorkingMode>& modes, const PlanOutcome& outcome,
                  const std::string& frame, PlanPath::Response& response) {
  const InputTrajectory& trajectory = outcome.trajectory;
  const ros::Time now = ros::Time::now();
  response.path.header.frame_id = frame;
  response.path.header.stamp = now;
  response.trajectory.header.stamp = now;
  response.trajectory.joint_names = trajectory.inputs;
  const auto velocities = inputVelocities(trajectory);
  const auto accelerations = inputAccelerations(trajectory);
  for (std::size_t k = 0; k < trajectory.time.size(); ++k) {
    geometry_msgs::PoseStamped pose;
    pose.header.frame_id = frame;
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
  const Plan& plan = outcome.plan;
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
}

std_msgs::ColorRGBA workingModeColour(int mode) {
  static const float kPalette[8][3] = {{0.90f, 0.10f, 0.10f}, {0.10f, 0.60f, 0.95f}, {0.15f, 0.80f, 0.20f},
                                       {0.95f, 0.65f, 0.05f}, {0.60f, 0.20f, 0.85f}, {0.05f, 0.80f, 0.75f},
                                       {0.95f, 0.35f, 0.70f}, {1.00f, 0.95f, 0.45f}};
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

namespace {

// Text a twentieth of the drawing's height (base frame), at least 3 cm, so that it reads
// on the deltas at the compact view (rviz/compact.rviz, from 2 m; at 2.5 cm minus signs
// vanished), at most 6 cm.
double textHeight(const Eigen::AlignedBox3d& drawn) { return std::clamp(0.05 * drawn.sizes().z(), 0.03, 0.06); }

// The box of the markers' points (the start's position when there are none), in
// coordinates along `axes`' columns.
Eigen::AlignedBox3d pointsBox(const visualization_msgs::MarkerArray& markers, const Grid& grid, const Eigen::Matrix3d& axes) {
  const Eigen::Matrix3d to_axes = axes.transpose();
  Eigen::AlignedBox3d box(to_axes * grid.spec().start.position);
  for (const visualization_msgs::Marker& m : markers.markers) {
    for (const geometry_msgs::Point& p : m.points) box.extend(to_axes * Eigen::Vector3d(p.x, p.y, p.z));
  }
  return box;
}

// Whether working mode m shows in the drawing of either assembly mode.
bool modeDrawn(const WorkspaceDrawing& drawing, std::size_t m) {
  for (int s = 0; s < 2; ++s) {
    if (drawing.surfaces != nullptr) {
      const std::vector<int>& shown = drawing.surfaces->maximal_vertex_modes[s];
      if (std::find(shown.begin(), shown.end(), static_cast<int>(m)) != shown.end()) return true;
    } else if (m < drawing.cubes->cubes[s].size() && !drawing.cubes->cubes[s][m].empty()) {
      return true;
    }
  }
  return false;
}

bool byConditioning(const WorkspaceDrawing& drawing) {
  return !drawing.conditioning[0].empty() || !drawing.conditioning[1].empty();
}

// The top of the conditioning colour scale: one for both assembly modes, so that a colour
// means one index.
double drawingScaleTop(const WorkspaceDrawing& drawing) {
  std::vector<float> all = drawing.conditioning[0];
  all.insert(all.end(), drawing.conditioning[1].begin(), drawing.conditioning[1].end());
  return conditioningScaleTop(all);
}

// The workspace of one assembly mode: its maximal surface coloured by working mode and the
// traditional one, or a faint CUBE_LIST per working mode.
void addWorkspaceShapes(const WorkspaceDrawing& drawing, int s, const std::string& frame, const std::string& name,
                        visualization_msgs::MarkerArray& markers) {
  if (drawing.surfaces != nullptr) {
    const DisplaySurfaces& surfaces = *drawing.surfaces;
    SurfaceMesh coloured = surfaces.maximal[s];
    if (!drawing.conditioning[s].empty()) {
      colourByConditioning(drawing.conditioning[s], drawingScaleTop(drawing), &coloured);
    } else {
      for (int mode : surfaces.maximal_vertex_modes[s]) {
        const std_msgs::ColorRGBA c = workingModeColour(mode);
        coloured.colours.push_back({static_cast<std::uint8_t>(255 * c.r), static_cast<std::uint8_t>(255 * c.g),
                                    static_cast<std::uint8_t>(255 * c.b)});
      }
    }
    std_msgs::ColorRGBA opacity;
    opacity.r = opacity.g = opacity.b = 1.0f;
    opacity.a = drawing.surface_alpha;
    if (!coloured.triangles.empty()) markers.markers.push_back(surfaceMarker(coloured, frame, "maximal_" + name, opacity));
    std_msgs::ColorRGBA grey = opacity;
    grey.r = grey.g = grey.b = 0.75f;
    if (!surfaces.traditional[s].triangles.empty()) {
      markers.markers.push_back(surfaceMarker(surfaces.traditional[s], frame, "traditional_" + name, grey));
    }
    return;
  }
  const SurfaceSample& sample = *drawing.cubes;
  for (std::size_t m = 0; m < sample.cubes[s].size(); ++m) {
    visualization_msgs::Marker cubes =
        marker(frame, "maximal_" + name, static_cast<int>(m), visualization_msgs::Marker::CUBE_LIST, sample.cube_size);
    cubes.color = workingModeColour(static_cast<int>(m));
    // Faint: a path inside is seen through the shells of every working mode in front of it.
    cubes.color.a = 0.06f;
    for (const Eigen::Vector3d& centre : sample.cubes[s][m]) cubes.points.push_back(pointMessage(centre));
    if (!cubes.points.empty()) markers.markers.push_back(cubes);
  }
}

std_msgs::ColorRGBA white() {
  std_msgs::ColorRGBA colour;
  colour.r = colour.g = colour.b = colour.a = 1.0f;
  return colour;
}

std_msgs::ColorRGBA colourMessage(const std::array<std::uint8_t, 3>& rgb) {
  std_msgs::ColorRGBA result;
  result.r = rgb[0] / 255.0f, result.g = rgb[1] / 255.0f, result.b = rgb[2] / 255.0f, result.a = 1.0f;
  return result;
}

// A colour bar: kSteps cubes up the screen in colour(t), t from 0 at the bottom to 1, with
// white ticks at their t to the right.
struct ColourBar {
  static constexpr int kSteps = 11;
  std::function<std_msgs::ColorRGBA(double)> colour;
  std::vector<std::pair<double, std::string>> ticks;

  double tickGap(double height) const { return 0.75 * height; }
  Eigen::Vector2d size(double height) const {
    double tick_width = 0.0;
    for (const auto& tick : ticks) tick_width = std::max(tick_width, textSize(tick.second, height).x());
    return {height + tickGap(height) + tick_width, kSteps * height};
  }
  // Drawn as a block centred at `centre`, in namespace `ns` from id `id` on; the next free id.
  int draw(const ScreenAxes& axes, const Eigen::Vector3d& centre, double height, const std::string& frame,
           const std::string& ns, int id, visualization_msgs::MarkerArray& markers) const {
    // The bar up the block's left side, the ticks to its right.
    const Eigen::Vector3d bottom = axes.moved(centre, 0.5 * (Eigen::Vector2d::Constant(height) - size(height)));
    visualization_msgs::Marker steps = marker(frame, ns, id++, visualization_msgs::Marker::CUBE_LIST, height);
    for (int s = 0; s < kSteps; ++s) {
      steps.points.push_back(pointMessage(axes.moved(bottom, Eigen::Vector2d(0.0, s * height))));
      steps.colors.push_back(colour(static_cast<double>(s) / (kSteps - 1)));
    }
    markers.markers.push_back(steps);
    for (const auto& [at, text] : ticks) {
      visualization_msgs::Marker tick = marker(frame, ns, id++, visualization_msgs::Marker::TEXT_VIEW_FACING, height);
      tick.text = text;
      const double right = 0.5 * height + tickGap(height) + 0.5 * textSize(text, height).x();
      tick.pose.position = pointMessage(axes.moved(bottom, Eigen::Vector2d(right, at * (kSteps - 1) * height)));
      tick.color = white();
      markers.markers.push_back(tick);
    }
    return id;
  }
};

// One line of a title or legend: its marker's namespace (ids count per namespace), text and colour.
struct TextLine {
  std::string ns;
  std::string text;
  std_msgs::ColorRGBA colour;
};

Eigen::Vector2d blockSize(const std::vector<TextLine>& lines, double height) {
  double width = 0.0;
  for (const TextLine& line : lines) width = std::max(width, textSize(line.text, height).x());
  const double gaps = lines.empty() ? 0.0 : static_cast<double>(lines.size() - 1);
  return {width, height * (1.0 + kLineAdvance * gaps)};
}

void addTextColumn(const std::vector<TextLine>& lines, const std::vector<Eigen::Vector3d>& at, const std::string& frame,
                   double height, visualization_msgs::MarkerArray& markers) {
  std::map<std::string, int> ids;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    visualization_msgs::Marker text =
        marker(frame, lines[k].ns, ids[lines[k].ns]++, visualization_msgs::Marker::TEXT_VIEW_FACING, height);
    text.text = lines[k].text;
    text.color = lines[k].colour;
    text.pose.position = pointMessage(at[k]);
    markers.markers.push_back(text);
  }
}

// The legend: the working modes drawn, in their colours, then what the white balls are when
// there are any; with conditioning colours, what the white balls are, then the title of the
// colour bar drawn under these lines.
std::vector<TextLine> legendLines(const WorkspaceAnalysis& analysis, const WorkspaceDrawing& drawing, bool any_transition) {
  std::vector<TextLine> lines;
  if (byConditioning(drawing)) {
    if (any_transition) lines.push_back({"legend", "white ball: a transition", white()});
    lines.push_back({"legend", "conditioning index", white()});
    return lines;
  }
  for (std::size_t m = 0; m < analysis.modes().size(); ++m) {
    if (modeDrawn(drawing, m)) {
      lines.push_back({"legend", "working mode " + analysis.modes()[m].name, workingModeColour(static_cast<int>(m))});
    }
  }
  constexpr std::size_t kLegendLines = 16;  // 64 modes of a hexapod would not fit beside it
  if (lines.size() > kLegendLines) {
    const std::size_t more = lines.size() - (kLegendLines - 1);
    lines.resize(kLegendLines - 1);
    lines.push_back({"legend", "... and " + std::to_string(more) + " more working modes", white()});
  }
  if (any_transition) lines.push_back({"legend", "white ball: a transition", white()});
  return lines;
}

}  // namespace

visualization_msgs::MarkerArray workspaceMarkers(const RobotModel& model, const WorkspaceAnalysis& analysis,
                                                 const WorkspaceDrawing& drawing, const std::string& frame,
                                                 std::int8_t assembly_mode) {
  const Grid& grid = analysis.grid();
  visualization_msgs::MarkerArray markers = clearingMarkers(frame);
  const double total = analysis.workspaceVolume();
  for (const AssemblyModeSummary& am : analysis.assemblyModes()) {
    if (keeps(assembly_mode, am.sign)) addWorkspaceShapes(drawing, am.sign > 0 ? 0 : 1, frame, signName(am.sign), markers);
  }
  // Labels 6 cm high over a workspace a metre or more high (the delta-like robot's), in
  // proportion over smaller ones (the deltas'), so they read at the default view beside
  // the robot.
  const double text_height = textHeight(pointsBox(markers, grid, Eigen::Matrix3d::Identity()));
  const std::vector<TransitionMark> marks = transitionMarks(analysis, assembly_mode);
  std::vector<TextLine> titles;
  for (const AssemblyModeSummary& am : analysis.assemblyModes()) {
    if (!keeps(assembly_mode, am.sign)) continue;
    const std::string name = signName(am.sign);
    // One ball per transition, where its two regions meet.
    int id = 0;
    for (const TransitionMark& mark : marks) {
      if (mark.sign != am.sign) continue;
      visualization_msgs::Marker ball =
          marker(frame, "transitions_" + name, id++, visualization_msgs::Marker::SPHERE, 0.6 * text_height);
      ball.pose.position = pointMessage(mark.position);
      ball.color = white();
      markers.markers.push_back(ball);
    }
    char text[200];
    std::snprintf(text, sizeof text, "assembly mode %s: maximal %.1f %%, traditional %.1f %%, reachable %.1f %% (%s)",
                  am.sign > 0 ? "+" : "-", 100 * am.maximal_volume / total, 100 * am.traditional_volume / total,
                  100 * am.reachable_volume / total, marginText(analysis.settings().margin).c_str());
    titles.push_back({"label_" + name, text, white()});
  }
  const std::vector<TextLine> legend = legendLines(analysis, drawing, !marks.empty());
  // Around the whole drawn robot, not the workspace alone: rviz hides text behind the rails
  // and cranks that stand outside it.
  const ScreenAxes axes = ScreenAxes::defaultView();
  // With conditioning colours, the colour bar under the legend's lines, in one block.
  std::optional<ColourBar> bar;
  if (byConditioning(drawing)) {
    const double top = drawingScaleTop(drawing);
    bar = ColourBar{[top](double t) { return colourMessage(conditioningColour(t * top, top)); },
                    {{0.0, "0"}, {0.5, numberText(0.5 * top)}, {1.0, ">= " + numberText(top)}}};
  }
  const Eigen::Vector2d lines_size = blockSize(legend, text_height);
  const Eigen::Vector2d bar_size = bar ? bar->size(text_height) : Eigen::Vector2d::Zero();
  const double bar_gap = bar ? text_height : 0.0;
  const Eigen::Vector2d legend_size(std::max(lines_size.x(), bar_size.x()), lines_size.y() + bar_gap + bar_size.y());
  const FramePlacement place = placeFrame(axes, drawnRobotBox(model, pointsBox(markers, grid, axes.view), axes.view),
                                          blockSize(titles, text_height), legend_size, 2.0 * text_height);
  addTextColumn(titles, blockLines(axes, place.title, titles.size(), text_height), frame, text_height, markers);
  const Eigen::Vector3d lines_centre = axes.moved(place.legend, Eigen::Vector2d(0.0, 0.5 * (legend_size.y() - lines_size.y())));
  addTextColumn(legend, blockLines(axes, lines_centre, legend.size(), text_height), frame, text_height, markers);
  if (bar) {
    const Eigen::Vector3d bar_centre = axes.moved(place.legend, Eigen::Vector2d(0.0, 0.5 * (bar_size.y() - legend_size.y())));
    bar->draw(axes, bar_centre, text_height, frame, "legend", static_cast<int>(legend.size()), markers);
  }
  return markers;
}

visualization_msgs::MarkerArray modeSurfaceMarkers(const WorkspaceAnalysis& analysis, const DisplaySurfaces& surfaces,
                                                   const std::string& frame, float alpha) {
  visualization_msgs::MarkerArray markers = clearingMarkers(frame);
  for (int s = 0; s < 2; ++s) {
    for (std::size_t m = 0; m < surfaces.modes[s].size(); ++m) {
      if (surfaces.modes[s][m].triangles.empty()) continue;
      std_msgs::ColorRGBA colour = workingModeColour(static_cast<int>(m));
      colour.a = alpha;
      markers.markers.push_back(surfaceMarker(surfaces.modes[s][m], frame,
                                              analysis.modes()[m].name + "_" + signName(s == 0 ? 1 : -1), colour));
    }
  }
  return markers;
}

visualization_msgs::Marker surfaceMarker(const SurfaceMesh& mesh, const std::string& frame, const std::string& ns,
                                         const std_msgs::ColorRGBA& colour) {
  visualization_msgs::Marker result = marker(frame, ns, 0, visualization_msgs::Marker::TRIANGLE_LIST, 1.0);
  result.color = colour;
  // rviz lights a TRIANGLE_LIST with vertex colours not at all, and one without by ambient
  // light alone (no normals): the shading is baked into vertex colours, a light from above
  // and in front of the configurations' default view, so that the shape reads.
  const Eigen::Vector3d light = Eigen::Vector3d(-0.3, -0.7, 0.65).normalized();
  const std::vector<std::array<float, 3>> normals = vertexNormals(mesh);
  result.points.reserve(3 * mesh.triangles.size());
  result.colors.reserve(3 * mesh.triangles.size());
  for (const std::array<std::uint32_t, 3>& triangle : mesh.triangles) {
    for (std::uint32_t v : triangle) {
      geometry_msgs::Point point;
      point.x = mesh.vertices[v][0], point.y = mesh.vertices[v][1], point.z = mesh.vertices[v][2];
      result.points.push_back(point);
      const Eigen::Vector3d normal(normals[v][0], normals[v][1], normals[v][2]);
      const float shade = static_cast<float>(kAmbientLight + (1.0 - kAmbientLight) * std::max(0.0, normal.dot(light)));
      std_msgs::ColorRGBA vertex = colour;
      if (!mesh.colours.empty()) {
        vertex.r = mesh.colours[v][0] / 255.0f, vertex.g = mesh.colours[v][1] / 255.0f, vertex.b = mesh.colours[v][2] / 255.0f;
      }
      vertex.r *= shade, vertex.g *= shade, vertex.b *= shade;
      result.colors.push_back(vertex);
    }
  }
  return result;
}

visualization_msgs::MarkerArray coverageMarkers(const RobotModel& model, const WorkspaceAnalysis& analysis,
                                                const OrientationCoverage& coverage, const std::string& frame,
                                                std::int8_t assembly_mode) {
  const Grid& grid = analysis.grid();
  visualization_msgs::MarkerArray markers = clearingMarkers(frame);
  const auto colour = [](double share) { return colourMessage(coverageColour(share)); };
  char heading[160];
  std::snprintf(heading, sizeof heading, "orientations reached: tilt <= %.0f deg, torsion %.0f to %.0f deg",
                (grid.centre(4, grid.size(4) - 1) + 0.5 * grid.step(4)) * 180.0 / M_PI,
                (grid.centre(5, 0) - 0.5 * grid.step(5)) * 180.0 / M_PI,
                (grid.centre(5, grid.size(5) - 1) + 0.5 * grid.step(5)) * 180.0 / M_PI);
  std::string title = heading;
  for (const AssemblyModeCoverage& am : coverage.assemblyModes()) {
    if (!keeps(assembly_mode, am.sign)) continue;
    const int a = am.sign > 0 ? 0 : 1;
    // The positions reaching every orientation as one opaque surface (the full share's
    // colour), the others as translucent cubes around it, so that it shows through.
    visualization_msgs::Marker surface =
        surfaceMarker(surfaceMesh(totalOrientationCells(grid, coverage, a, false), kDisplayMesh), frame,
                      std::string("total_orientation_") + signName(am.sign), colour(1.0));
    const bool has_surface = !surface.points.empty();
    if (has_surface) markers.markers.push_back(surface);
    visualization_msgs::Marker cubes = marker(frame, std::string("coverage_") + signName(am.sign), 0,
                                              visualization_msgs::Marker::CUBE_LIST,
                                              (has_surface ? kShellCubeSize : 1.0) * grid.step(0));
    for (std::int64_t i = 0; i < coverage.size(0); ++i) {
      for (std::int64_t j = 0; j < coverage.size(1); ++j) {
        for (std::int64_t k = 0; k < coverage.size(2); ++k) {
          const float share = coverage.reachable(a, coverage.position(i, j, k));
          if (!(share > 0.0f) || (has_surface && share >= 1.0f)) continue;
          cubes.points.push_back(pointMessage(Eigen::Vector3d(grid.centre(0, i), grid.centre(1, j), grid.centre(2, k))));
          cubes.colors.push_back(colour(share));
          if (has_surface) cubes.colors.back().a = kShellAlpha;
        }
      }
    }
    if (!cubes.points.empty()) markers.markers.push_back(cubes);
    if (!has_surface && cubes.points.empty()) continue;
    char line[160];
    std::snprintf(line, sizeof line, "\nAM %s: all %.3g m^3 (traditional %.3g), some %.3g m^3",
                  am.sign > 0 ? "+" : "-", am.reachable.total_orientation_volume, am.traditional.total_orientation_volume,
                  am.reachable.inclusion_volume);
    title += line;
  }
  // Title above and colour bar beside the whole drawn robot (workspaceMarkers says why).
  const ScreenAxes axes = ScreenAxes::defaultView();
  const double text_height = textHeight(pointsBox(markers, grid, Eigen::Matrix3d::Identity()));
  const ColourBar bar{colour, {{0.0, "none"}, {0.5, "half"}, {1.0, "all of the set"}}};
  const FramePlacement place = placeFrame(axes, drawnRobotBox(model, pointsBox(markers, grid, axes.view), axes.view),
                                          textSize(title, text_height), bar.size(text_height), 2.0 * text_height);
  const int id = bar.draw(axes, place.legend, text_height, frame, "coverage_legend", 0, markers);
  visualization_msgs::Marker label =
      marker(frame, "coverage_legend", id, visualization_msgs::Marker::TEXT_VIEW_FACING, text_height);
  label.text = title;
  label.pose.position = pointMessage(place.title);
  label.color = white();
  markers.markers.push_back(label);
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
  response.workspace_inner_volume = summary["workspace"]["bounds"]["inner_volume"].get<double>();
  response.workspace_boundary_volume = summary["workspace"]["bounds"]["boundary_volume"].get<double>();
  response.volume_unit = summary["grid"]["volume_unit"].get<std::string>();
  response.transitions = 0;
  const nlohmann::json* conditioning = summary.contains("conditioning") && summary["conditioning"].is_object()
                                           ? &summary["conditioning"] : nullptr;
  if (conditioning != nullptr) response.conditioning_threshold = (*conditioning)["threshold"].get<double>();
  for (const nlohmann::json& am : summary["assembly_modes"]) {
    const std::int8_t sign = static_cast<std::int8_t>(am["sign"].get<int>());
    if (!keeps(assembly_mode, sign)) continue;
    AssemblyModeVolumes volumes;
    volumes.sign = sign;
    volumes.maximal_volume = am["maximal_volume"].get<double>();
    volumes.traditional_volume = am["traditional_volume"].get<double>();
    volumes.reachable_volume = am["reachable_volume"].get<double>();
    volumes.maximal_inner_volume = am["maximal_bounds"]["inner_volume"].get<double>();
    volumes.maximal_boundary_volume = am["maximal_bounds"]["boundary_volume"].get<double>();
    volumes.traditional_inner_volume = am["traditional_bounds"]["inner_volume"].get<double>();
    volumes.traditional_boundary_volume = am["traditional_bounds"]["boundary_volume"].get<double>();
    volumes.reachable_inner_volume = am["reachable_bounds"]["inner_volume"].get<double>();
    volumes.reachable_boundary_volume = am["reachable_bounds"]["boundary_volume"].get<double>();
    volumes.regions = am["regions"].get<std::uint32_t>();
    volumes.debris_regions = am["debris_regions"].get<std::uint32_t>();
    volumes.transitions = am["transitions"].get<std::uint32_t>();
    volumes.groups = am["components"].get<std::uint32_t>();
    if (summary.contains("orientation_set") && summary["orientation_set"].is_object()) {
      for (const nlohmann::json& coverage : summary["orientation_set"]["assembly_modes"]) {
        if (coverage["sign"].get<int>() != sign) continue;
        volumes.total_orientation_volume = coverage["maximal"]["total_orientation_volume"].get<double>();
        volumes.inclusion_volume = coverage["maximal"]["inclusion_volume"].get<double>();
        volumes.total_orientation_traditional_volume = coverage["traditional"]["total_orientation_volume"].get<double>();
        volumes.inclusion_traditional_volume = coverage["traditional"]["inclusion_volume"].get<double>();
      }
    }
    if (conditioning != nullptr) {
      for (const nlohmann::json& figures : (*conditioning)["assembly_modes"]) {
        if (figures["sign"].get<int>() != sign) continue;
        volumes.well_conditioned_volume = figures["well_conditioned_volume"].get<double>();
        volumes.global_conditioning_index = figures["global_conditioning_index"].get<double>();
      }
    }
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
