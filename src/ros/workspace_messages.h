#pragma once
// ROS messages built from a workspace analysis: the singularity map as a PointCloud2, the
// maximal workspaces as markers, their octrees, and the service response from a
// summary.json; request poses read back. Translation only: every figure comes from the core
// library.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <geometry_msgs/Pose.h>
#include <nlohmann/json.hpp>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include "maximal_workspace/ComputeWorkspace.h"
#include "maximal_workspace/MaximalWorkspaceOctrees.h"
#include "maximal_workspace/PlanPath.h"
#include "maximal_workspace/planner/planning.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/planner/path_request.h"
#include "maximal_workspace/io/display_sampling.h"
#include "maximal_workspace/regions/orientation_coverage.h"
#include "maximal_workspace/surfaces/surface_mesh.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

// Fields x y z (float32), working_mode (uint8 index into the analysis's modes, 255 for
// IKP points: the boundary belongs to every working mode), kind (uint8: 0 DKP
// singularity, 1 IKP singularity, 2 actuator limit, 3 joint cone, 4 interference), chain
// (int8, -1 for DKP), det (float32: the normalised measure; 0 on the other kinds), from a
// display sample (io/display_sampling.h).
sensor_msgs::PointCloud2 singularityCloud(const SingularitySample& sample, const std::string& frame);

// What workspaceMarkers draws the workspaces with: surfaces (display_sampling.h
// displaySurfaces) when `surfaces` is given, else the cubes of their boundary cells.
struct WorkspaceDrawing {
  const SurfaceSample* cubes = nullptr;
  const DisplaySurfaces* surfaces = nullptr;
  float surface_alpha = 1.0f;
  // Per assembly mode (0: +, 1: -), the conditioning index at each vertex of
  // surfaces->maximal (vertexConditioning): the surface coloured by it, with a colour bar
  // for a legend. Empty: coloured by working mode.
  std::array<std::vector<float>, 2> conditioning;
};

// A DELETEALL, then per assembly mode kept (`assembly_mode` 0: both) a namespace
// "maximal_positive" / "maximal_negative": the maximal workspace as one lit TRIANGLE_LIST
// coloured by the working mode at each vertex, or one CUBE_LIST per working mode (the
// surface cells of its non-debris regions of that sign, translucent); with surfaces,
// "traditional_positive" / "_negative", the start's region alone (inside the maximal
// surface: seen when that namespace is hidden); "transitions_positive" / "_negative" with
// one SPHERE per transition (io/display_sampling.h transitionMarks) and a text label in
// "label_positive" / "label_negative": a display can show one assembly mode alone.
// Namespace "legend": the working-mode colours, one text line each, or with conditioning
// colours a colour bar of the index. The titles go above and the legend beside the whole
// drawn robot (label_layout.h), for `model`'s description.
visualization_msgs::MarkerArray workspaceMarkers(const RobotModel& model, const WorkspaceAnalysis& analysis,
                                                 const WorkspaceDrawing& drawing, const std::string& frame,
                                                 std::int8_t assembly_mode);

// The maximal workspace of each assembly mode kept, as serialized OcTrees; empty when the
// grid does not map onto an octree.
// Per working mode and assembly mode kept, the surface of its non-debris regions, in its
// colour: namespace "<mode name>_positive" / "_negative", for a display that shows one
// working mode's regions at a time (a topic of their own: drawn together they would hide
// each other).
visualization_msgs::MarkerArray modeSurfaceMarkers(const WorkspaceAnalysis& analysis, const DisplaySurfaces& surfaces,
                                                   const std::string& frame, float alpha);
// A closed surface as one TRIANGLE_LIST in `colour` (its vertex colours, when it has them).
visualization_msgs::Marker surfaceMarker(const SurfaceMesh& mesh, const std::string& frame, const std::string& ns,
                                         const std_msgs::ColorRGBA& colour);
// An orientation set's coverage as a heat map (the analysis must have one): per assembly
// mode reported, in the maximal workspace reachable from the start, the positions reaching
// every orientation of the set as an opaque surface (namespace total_orientation_<sign>, in
// coverageColour(1)), and a cube per position reaching some of it (coverage_<sign>),
// coloured by the share reached, translucent around the surface; with a colour bar and a
// title around the whole drawn robot, as workspaceMarkers places its legend and titles.
visualization_msgs::MarkerArray coverageMarkers(const RobotModel& model, const WorkspaceAnalysis& analysis,
                                                const OrientationCoverage& coverage, const std::string& frame,
                                                std::int8_t assembly_mode);

MaximalWorkspaceOctrees octreesMessage(const WorkspaceAnalysis& analysis, const std::string& frame,
                                       std::int8_t assembly_mode);

// The figures of the response, read from a summary.json, for the assembly modes kept.
void fillResponse(const nlohmann::json& summary, std::int8_t assembly_mode, ComputeWorkspace::Response& response);

// A pose of a request as it came; referenceOrientationPose (planner/path_request.h) checks it.
RequestPose requestPose(const geometry_msgs::Pose& message);

// The service requests in the core's plain types, unchecked: resolveWorkspaceRequest and
// resolvePathRequest check them. `Fields`: /compute_workspace's request or the action's
// goal, which have the same fields.
template <class Fields>
WorkspaceRequest workspaceRequest(const Fields& request) {
  WorkspaceRequest result;
  result.step = request.step;
  result.start = request.start;
  result.start_working_mode = request.start_working_mode;
  result.variables = request.variables;
  result.bounds = request.bounds;
  result.working_modes = request.working_modes;
  result.assembly_mode = request.assembly_mode;
  result.margin = request.margin;
  result.tilt_max = request.tilt_max;
  result.torsion = request.torsion;
  result.angle_step = request.angle_step;
  result.conditioning = request.conditioning;
  result.conditioning_threshold = request.conditioning_threshold;
  return result;
}
PathRequest pathRequest(const PlanPath::Request& request);

geometry_msgs::Point pointMessage(const Eigen::Vector3d& point);

// A verified plan into the response: the path (in `frame`), the working mode at every pose,
// the trajectory of the inputs, the transitions, its length and smallest |measure|.
void planResponse(const RobotModel& model, const std::vector<WorkingMode>& modes, const PlanOutcome& outcome,
                  const std::string& frame, PlanPath::Response& response);

// Colour of a working mode in markers: distinct for the first eight.
std_msgs::ColorRGBA workingModeColour(int mode);

}  // namespace maximal_workspace
