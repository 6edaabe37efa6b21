#pragma once
// The conditioning index (kinematics/conditioning.h) on a maximal workspace's boundary mesh:
// the heat map a designer reads on the surface, as rviz vertex colours and in PLY files.

#include <array>
#include <cstdint>
#include <vector>

#include "maximal_workspace/model/robot_model.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "maximal_workspace/surfaces/surface_mesh.h"

namespace maximal_workspace {

// Per vertex of a mesh of assembly mode `sign`'s maximal workspace (an analysis over x y z),
// the conditioning index at the cell of that workspace nearest to the point half a `depth`
// inside along the vertex normal: the best of the working modes with a non-debris region of
// that sign there, as the conditioning figures count it. On the boundary itself the index
// is 0 (the boundary is singular), hence a cell inside. NaN where no cell of the workspace
// lies within `depth` of that point.
std::vector<float> vertexConditioning(const RobotModel& model, const WorkspaceAnalysis& analysis, const SurfaceMesh& mesh,
                                      std::int8_t sign, double depth, int threads = 0);

// `values` (one per vertex) averaged `iterations` times with their neighbours along the
// mesh's edges, NaN left out: for a display, where cell-sized steps of the index between
// neighbouring vertices (the staircase of the cells under the surface) read as stripes.
std::vector<float> smoothedOverMesh(const SurfaceMesh& mesh, std::vector<float> values, int iterations);

// The colour scale's top: the smallest of 0.01, 0.02, 0.05, 0.1, 0.2, 0.5 and 1 at or above
// 95 % of the finite indices. Near a workspace's boundary the index is small (the boundary
// is singular): a scale up to 1 would paint it one colour. The few indices above the top
// take its colour.
double conditioningScaleTop(const std::vector<float>& indices);

// Viridis (perceptually uniform, legible to colour-blind readers): dark violet at 0,
// through blue and green, to yellow at `top` and above; mid grey for NaN.
std::array<std::uint8_t, 3> conditioningColour(double index, double top);

// Sets the mesh's vertex colours from `indices` on a scale of [0, top], and its quality
// (the indices themselves, written to PLY).
void colourByConditioning(const std::vector<float>& indices, double top, SurfaceMesh* mesh);

}  // namespace maximal_workspace
