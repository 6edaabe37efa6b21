#pragma once
// What a display is given of an analysis, at a resolution it can draw: at 2 mm the
// singularity map has millions of entries and the workspace's surface millions of cells,
// far more than rviz stays interactive with. Both are sampled on a display lattice of
// `factor` grid steps a side, the factor doubled until the caps hold; files keep the full
// resolution. The ROS messages are packed from these (src/ros/workspace_messages.h).

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "maximal_workspace/model/robot_model.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "maximal_workspace/surfaces/surface_mesh.h"

namespace maximal_workspace {

struct DisplayLimits {
  double display_step = 0.01;       // m (or rad): the display lattice's spacing at least; 0: the grid step
  std::uint64_t max_points = 500'000;  // singularity-map points
  std::uint64_t max_cubes = 200'000;   // surface cubes, all working modes and assembly modes together
  std::uint64_t max_triangles = 300'000;  // triangles of each display surface
  bool surfaces = true;        // the workspaces as surfaces (displaySurfaces), else cubes (sampleSurfaces)
  double surface_alpha = 1.0;  // the surfaces' opacity
  bool colour_by_conditioning = false;  // the maximal surfaces by the conditioning index, not by working mode
};

// How a sampling came out, for a log line or a message field.
struct DisplayDecimation {
  int factor = 1;            // grid steps per display cell along each variable
  std::uint64_t full = 0;    // singularity entries of the analysis (0 for surface cells)
  std::uint64_t shown = 0;   // points or cubes drawn
  // The singularity map's, e.g. "401501 points for 5185147 entries, one per display cell of
  // 4 grid steps (display_step, doubled while over max_points), kind and working mode".
  std::string text() const;
};

constexpr std::uint8_t kAllWorkingModes = 255;  // working_mode of IKP points: every mode's boundary

struct SingularityPoint {
  Eigen::Vector3d position;     // DKP: the cell centre; else the centre of the boundary face
  std::uint8_t working_mode = kAllWorkingModes;
  // 0 DKP singularity, 1 IKP singularity, 2 actuator limit, 3 joint cone, 4 interference
  // (ConstraintKind); IKP points and walls sit at the centre of the boundary face.
  std::uint8_t kind = 0;
  std::int8_t chain = -1;       // IKP: the chain that cannot be assembled across the face; walls: the
                                // chain whose limit it is (the first of two interfering rods)
  float measure = 0.0f;         // DKP: the normalised measure of that working mode there
};

struct SingularitySample {
  std::vector<SingularityPoint> points;
  DisplayDecimation decimation;
};

// One point per display cell, kind and working mode (DKP) or face direction (IKP).
SingularitySample sampleSingularities(const RobotModel& model, const WorkspaceAnalysis& analysis,
                                      const DisplayLimits& limits);

struct SurfaceSample {
  double cube_size = 0.0;  // m: the display cell's side
  // [assembly mode 0 (+) / 1 (-)][working mode]: centres of the display cells on the surface
  // of that working mode's non-debris regions of that sign.
  std::vector<std::vector<Eigen::Vector3d>> cubes[2];
  DisplayDecimation decimation;
};

// The surfaces of the assembly modes kept (`assembly_mode` 0: both); empty unless the grid
// is over x y z (or x y).
SurfaceSample sampleSurfaces(const WorkspaceAnalysis& analysis, const DisplayLimits& limits, std::int8_t assembly_mode);

// The workspaces as surfaces for a display: meshed on the display lattice of
// `display_step` (a display cell is in a set when its middle grid cell is), smoothed, at
// most `max_triangles` each. Empty unless the grid is over x y z.
struct DisplaySurfaces {
  double cell_size = 0.0;  // m: the display lattice's side
  // Per assembly mode (0: +, 1: -) kept: the maximal workspace, and per vertex of it the
  // working mode shown there (the start's where it has a region there, else the first).
  SurfaceMesh maximal[2];
  std::vector<int> maximal_vertex_modes[2];
  SurfaceMesh traditional[2];
  // [assembly mode][working mode]: the surface of its non-debris regions of that sign.
  std::vector<SurfaceMesh> modes[2];
};

// The surfaces of the assembly modes kept (`assembly_mode` 0: both); `per_mode` false leaves
// `modes` empty (two meshes per working mode that no display may show).
DisplaySurfaces displaySurfaces(const WorkspaceAnalysis& analysis, const DisplayLimits& limits, std::int8_t assembly_mode,
                                bool per_mode = true);

// One mark per transition between non-debris regions: thousands of transition points
// would speckle the volume, while a reader wants where each pair of regions meets.
struct TransitionMark {
  Eigen::Vector3d position;  // the transition's point nearest the centroid of its points
  std::int8_t sign = 0;      // assembly mode
  int input = 0;             // the couple changing branch
  int from_mode = 0, to_mode = 0;  // working-mode indices, from_mode the lower
  std::size_t points = 0;    // transition points it stands for
};

// The marks of the assembly modes kept (`assembly_mode` 0: both), in the order of the
// analysis's transitions.
std::vector<TransitionMark> transitionMarks(const WorkspaceAnalysis& analysis, std::int8_t assembly_mode);

}  // namespace maximal_workspace
