#include "maximal_workspace/workspace/workspace_map.h"

#include <chrono>
#include <cmath>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/workspace/parallel.h"

namespace maximal_workspace {

std::uint64_t startCell(const Grid& grid, const PoseClassifier& classifier, double* measures) {
  std::uint64_t start_cell = 0;
  if (!grid.cellOf(grid.spec().start, &start_cell)) throw InputError("grid: the start pose is outside the grid's box");
  const Pose start_centre = grid.pose(start_cell);
  if (!classifier.classify(start_centre, measures)) {
    std::string where;
    for (int d = 0; d < grid.dims(); ++d) where += std::string(d ? " " : "") + outputVariableName(grid.variable(d)) + "=" + numberText(start_centre.value(grid.variable(d)));
    throw InputError("grid: the start pose is outside the workspace (the centre of its cell, " + where +
                     ", cannot be assembled)");
  }
  return start_cell;
}

namespace {

using Clock = std::chrono::steady_clock;

// Classifies the grid cells cells[0 .. count): inside[i] is 1 or 0, and measures[i * modes
// + m] is set where inside. In batches of TCP positions (the classifier's vectorised path)
// when the orientation is fixed, else pose by pose.
void classifyCells(const Grid& grid, const PoseClassifier& classifier, const std::uint32_t* cells, std::size_t count,
                   std::uint8_t* inside, double* measures) {
  const std::size_t modes = classifier.modes().size();
  if (!classifier.orientationFixed()) {
    for (std::size_t i = 0; i < count; ++i) inside[i] = classifier.classify(grid.pose(cells[i]), measures + i * modes);
    return;
  }
  constexpr std::size_t kBatch = 1024;
  std::vector<double> x(std::min(count, kBatch)), y(x.size()), z(x.size());
  for (std::size_t begin = 0; begin < count; begin += kBatch) {
    const std::size_t n = std::min(kBatch, count - begin);
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d position = grid.pose(cells[begin + i]).position;
      x[i] = position.x(), y[i] = position.y(), z[i] = position.z();
    }
    classifier.classify(PointBatch{x.data(), y.data(), z.data(), n}, inside + begin, measures + begin * modes);
  }
}

// Inside cells in a sparse, evenly strided sample of the box, scaled up: a progress
// denominator for a wave front whose size is not known until it ends.
std::uint64_t estimateInside(const Grid& grid, const PoseClassifier& classifier, int threads) {
  const double target_samples = 20000.0;
  const std::uint64_t stride = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(grid.cellCount() / target_samples));
  const std::size_t samples = static_cast<std::size_t>(grid.cellCount() / stride);
  std::vector<std::uint8_t> inside(samples, 0);
  parallelFor(samples, threads, [&](std::size_t begin, std::size_t end) {
    std::vector<std::uint32_t> cells;
    for (std::size_t i = begin; i < end; ++i) cells.push_back(static_cast<std::uint32_t>(i * stride));
    std::vector<double> measures(cells.size() * classifier.modes().size());
    classifyCells(grid, classifier, cells.data(), cells.size(), &inside[begin], measures.data());
  });
  std::uint64_t count = 0;
  for (std::uint8_t flag : inside) count += flag;
  return count * stride;
}

}  // namespace

WorkspaceMap propagateWaveFront(const Grid& grid, const PoseClassifier& classifier, const WaveFrontOptions& options) {
  const Clock::time_point started = Clock::now();
  const int modes = static_cast<int>(classifier.modes().size());
  WorkspaceMap map;
  map.mode_count = modes;

  std::vector<double> start_measures(modes);
  const std::uint64_t start_cell = startCell(grid, classifier, start_measures.data());
  WaveFrontProgress progress;
  progress.estimated_inside = estimateInside(grid, classifier, options.threads);

  map.cell_voxel.assign(grid.cellCount(), kCellNotVisited);
  auto accept = [&](std::uint64_t cell, const double* measures) {
    map.cell_voxel[cell] = static_cast<std::uint32_t>(map.voxel_cell.size());
    map.voxel_cell.push_back(static_cast<std::uint32_t>(cell));
    for (int m = 0; m < modes; ++m) map.signs.push_back(bandedSign(measures[m], options.singular_threshold));
  };
  accept(start_cell, start_measures.data());
  map.evaluated = 1;

  std::vector<std::uint32_t> frontier = {static_cast<std::uint32_t>(start_cell)}, candidates, next;
  std::vector<std::uint8_t> assembled;
  std::vector<double> measures;
  while (!frontier.empty()) {
    // Candidates: unvisited neighbours of the frontier, in a fixed order.
    candidates.clear();
    for (std::uint32_t cell : frontier) {
      for (int d = 0; d < grid.dims(); ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t neighbour = 0;
          if (!grid.neighbour(cell, d, direction, &neighbour) || map.cell_voxel[neighbour] != kCellNotVisited) continue;
          map.cell_voxel[neighbour] = kCellOutside;  // until proven inside; also marks it queued
          candidates.push_back(static_cast<std::uint32_t>(neighbour));
        }
      }
    }
    assembled.assign(candidates.size(), 0);
    measures.resize(candidates.size() * modes);
    parallelFor(candidates.size(), options.threads, [&](std::size_t begin, std::size_t end) {
      classifyCells(grid, classifier, &candidates[begin], end - begin, &assembled[begin], &measures[begin * modes]);
    });
    next.clear();
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (!assembled[i]) continue;
      accept(candidates[i], &measures[i * modes]);
      next.push_back(candidates[i]);
    }
    map.evaluated += candidates.size();
    frontier.swap(next);
    if (options.progress) {
      progress.evaluated = map.evaluated;
      progress.inside = map.voxelCount();
      progress.elapsed_seconds = std::chrono::duration<double>(Clock::now() - started).count();
      options.progress(progress);
    }
  }
  return map;
}

}  // namespace maximal_workspace
