#include "maximal_workspace/surfaces/vertex_conditioning.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "maximal_workspace/model/input_error.h"
#include "regions/conditioning_summary.h"
#include "workspace/parallel.h"

namespace maximal_workspace {

namespace {

constexpr std::uint64_t kNoCell = std::numeric_limits<std::uint64_t>::max();

// The cell of `sign`'s maximal workspace whose centre is nearest `point`, among those within
// `reach` cells of the one holding it along each axis; kNoCell when there is none.
std::uint64_t nearestMaximalCell(const WorkspaceAnalysis& analysis, const Eigen::Vector3d& point, std::int8_t sign,
                                 std::int64_t reach) {
  const Grid& grid = analysis.grid();
  GridCell at{};
  for (int d = 0; d < 3; ++d) {
    at[d] = static_cast<std::int64_t>(std::floor((point[d] - grid.centre(d, 0)) / grid.step(d) + 0.5));
  }
  std::uint64_t best = kNoCell;
  double best_distance = std::numeric_limits<double>::infinity();
  GridCell cell{};
  for (cell[0] = std::max<std::int64_t>(0, at[0] - reach); cell[0] <= std::min(grid.size(0) - 1, at[0] + reach); ++cell[0]) {
    for (cell[1] = std::max<std::int64_t>(0, at[1] - reach); cell[1] <= std::min(grid.size(1) - 1, at[1] + reach); ++cell[1]) {
      for (cell[2] = std::max<std::int64_t>(0, at[2] - reach); cell[2] <= std::min(grid.size(2) - 1, at[2] + reach);
           ++cell[2]) {
        const std::uint64_t index = grid.index(cell);
        if (!analysis.inMaximalWorkspace(index, sign)) continue;
        const Eigen::Vector3d centre(grid.centre(0, cell[0]), grid.centre(1, cell[1]), grid.centre(2, cell[2]));
        const double distance = (centre - point).squaredNorm();
        if (distance < best_distance) best_distance = distance, best = index;
      }
    }
  }
  return best;
}

}  // namespace

std::vector<float> vertexConditioning(const RobotModel& model, const WorkspaceAnalysis& analysis, const SurfaceMesh& mesh,
                                      std::int8_t sign, double depth, int threads) {
  const Grid& grid = analysis.grid();
  if (grid.dims() != 3 || !grid.isSpatial()) throw InputError("conditioning on a surface: the grid must be over x y z");
  const std::vector<std::array<float, 3>> normals = vertexNormals(mesh);
  const std::int64_t reach = static_cast<std::int64_t>(std::ceil(depth / grid.step(0)));
  std::vector<std::uint64_t> cells(mesh.vertices.size());
  parallelFor(cells.size(), threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) {
      const Eigen::Vector3d inward = -0.5 * depth * Eigen::Vector3d(normals[v][0], normals[v][1], normals[v][2]);
      const Eigen::Vector3d point = Eigen::Vector3d(mesh.vertices[v][0], mesh.vertices[v][1], mesh.vertices[v][2]) + inward;
      cells[v] = nearestMaximalCell(analysis, point, sign, reach);
    }
  });
  // Neighbouring vertices share cells: each cell's index is computed once.
  std::vector<std::uint64_t> distinct = cells;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  if (!distinct.empty() && distinct.back() == kNoCell) distinct.pop_back();
  std::vector<float> cell_indices(distinct.size());
  const int assembly = sign > 0 ? 0 : 1;
  parallelFor(distinct.size(), threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint64_t cell = distinct[k];
      const std::array<double, 2> best = bestConditioning(model, grid.pose(cell), analysis.modes(), [&](int m) {
        const std::int32_t label = analysis.label(cell, m);
        return label < 0 || analysis.regions()[label].debris ? 0 : int{analysis.regions()[label].sign};
      });
      cell_indices[k] = best[assembly] < 0.0 ? NAN : static_cast<float>(best[assembly]);
    }
  }, 64);
  std::vector<float> indices(cells.size(), NAN);
  for (std::size_t v = 0; v < cells.size(); ++v) {
    if (cells[v] == kNoCell) continue;
    indices[v] = cell_indices[std::lower_bound(distinct.begin(), distinct.end(), cells[v]) - distinct.begin()];
  }
  return indices;
}

std::vector<float> smoothedOverMesh(const SurfaceMesh& mesh, std::vector<float> values, int iterations) {
  if (values.size() != mesh.vertices.size()) {
    throw InputError("smoothing: " + std::to_string(values.size()) + " values for " + std::to_string(mesh.vertices.size()) +
                     " vertices");
  }
  // Each triangle adds each of its edges from both ends: an edge shared by two triangles
  // counts twice for both, which keeps every neighbour's weight equal on a closed mesh.
  for (int iteration = 0; iteration < iterations; ++iteration) {
    std::vector<double> sum(values.size(), 0.0);
    std::vector<int> count(values.size(), 0);
    for (std::size_t v = 0; v < values.size(); ++v) {
      if (std::isfinite(values[v])) sum[v] += values[v], ++count[v];
    }
    for (const std::array<std::uint32_t, 3>& triangle : mesh.triangles) {
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = triangle[k], b = triangle[(k + 1) % 3];
        if (std::isfinite(values[b])) sum[a] += values[b], ++count[a];
        if (std::isfinite(values[a])) sum[b] += values[a], ++count[b];
      }
    }
    for (std::size_t v = 0; v < values.size(); ++v) {
      if (std::isfinite(values[v])) values[v] = static_cast<float>(sum[v] / count[v]);
    }
  }
  return values;
}

double conditioningScaleTop(const std::vector<float>& indices) {
  std::vector<float> finite;
  for (float index : indices) {
    if (std::isfinite(index)) finite.push_back(index);
  }
  constexpr double kTops[] = {0.01, 0.02, 0.05, 0.1, 0.2, 0.5};
  if (finite.empty()) return 1.0;
  // The smallest index at or above 95 % of them.
  const auto at = finite.begin() + static_cast<std::ptrdiff_t>(std::ceil(0.95 * static_cast<double>(finite.size()))) - 1;
  std::nth_element(finite.begin(), at, finite.end());
  for (double top : kTops) {
    if (*at <= top) return top;
  }
  return 1.0;
}

std::array<std::uint8_t, 3> conditioningColour(double index, double top) {
  // matplotlib's viridis at nine evenly spaced points, linearly interpolated.
  static constexpr std::uint8_t kViridis[9][3] = {{68, 1, 84},    {71, 44, 122},  {59, 81, 139},
                                                  {44, 113, 142}, {33, 144, 141}, {39, 173, 129},
                                                  {92, 200, 99},  {170, 220, 50}, {253, 231, 37}};
  if (!std::isfinite(index)) return {128, 128, 128};
  const double at = 8.0 * std::clamp(index / top, 0.0, 1.0);
  const int low = std::min(7, static_cast<int>(at));
  const double t = at - low;
  std::array<std::uint8_t, 3> colour{};
  for (int c = 0; c < 3; ++c) {
    colour[c] = static_cast<std::uint8_t>(std::lround((1.0 - t) * kViridis[low][c] + t * kViridis[low + 1][c]));
  }
  return colour;
}

void colourByConditioning(const std::vector<float>& indices, double top, SurfaceMesh* mesh) {
  if (indices.size() != mesh->vertices.size()) {
    throw InputError("conditioning colours: " + std::to_string(indices.size()) + " indices for " +
                     std::to_string(mesh->vertices.size()) + " vertices");
  }
  mesh->colours.clear();
  for (float index : indices) mesh->colours.push_back(conditioningColour(index, top));
  mesh->quality = indices;
}

}  // namespace maximal_workspace
