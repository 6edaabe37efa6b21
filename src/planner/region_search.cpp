#include "region_search.h"

#include <algorithm>
#include <cmath>

#include "a_star.h"

namespace maximal_workspace {

namespace {

constexpr int kNeighbourhoodDims = 3;  // diagonal moves up to three variables; faces only beyond

constexpr int kPower3[] = {1, 3, 9, 27};

// The offset along variable d of entry k of a 3^d neighbourhood.
int offsetOf(int k, int d) { return k / kPower3[d] % 3 - 1; }

// The cell at `at` moved by `offset` along d, wrapped along a periodic variable; false
// where the box ends.
bool moved(const Grid& grid, GridCell& at, int d, int offset) {
  at[d] += offset;
  if (at[d] >= 0 && at[d] < grid.size(d)) return true;
  if (!grid.periodic(d)) return false;
  at[d] = (at[d] + grid.size(d)) % grid.size(d);
  return true;
}

}  // namespace

CellsAround cellsAround(const Grid& grid, std::uint64_t cell) {
  const int dims = grid.dims();
  const GridCell centre = grid.cell(cell);
  CellsAround around;
  if (dims > kNeighbourhoodDims) {
    around.cells[around.count++] = static_cast<std::int64_t>(cell);
    for (int d = 0; d < dims; ++d) {
      for (int direction : {-1, 1}) {
        GridCell at = centre;
        around.cells[around.count++] = moved(grid, at, d, direction) ? static_cast<std::int64_t>(grid.index(at)) : -1;
      }
    }
    return around;
  }
  for (int k = 0; k < kPower3[dims]; ++k) {
    GridCell at = centre;
    bool within = true;
    for (int d = 0; d < dims && within; ++d) within = moved(grid, at, d, offsetOf(k, d));
    around.cells[around.count++] = within ? static_cast<std::int64_t>(grid.index(at)) : -1;
  }
  return around;
}

// One search's region and what it learnt of the faces it met.
struct RegionSearch::Walk {
  int mode = 0;
  std::int32_t region = 0;
  std::int8_t sign = 0;
  std::vector<double> measures;
  std::int64_t broken_from = -1, broken_to = -1;
};

RegionSearch::RegionSearch(const WorkspaceAnalysis& analysis, const PlannerMetric& metric, const PoseClassifier& classifier)
    : analysis_(analysis), grid_(analysis.grid()), metric_(metric), classifier_(classifier) {
  for (int d = 0; d < grid_.dims(); ++d) step_length_[d] = metric.stepLength(d);
}

double RegionSearch::distance(const GridCell& a, const GridCell& b) const {
  double squared = 0.0;
  for (int d = 0; d < grid_.dims(); ++d) {
    std::int64_t delta = std::abs(a[d] - b[d]);
    if (grid_.periodic(d)) delta = std::min(delta, grid_.size(d) - delta);
    const double length = static_cast<double>(delta) * step_length_[d];
    squared += length * length;
  }
  return std::sqrt(squared);
}

bool RegionSearch::passable(Walk& walk, std::uint64_t a, std::uint64_t b) const {
  // Not cached: classifying a face again from its other side costs less than a lookup.
  const Pose centre = metric_.interpolate(grid_.pose(a), grid_.pose(b), 0.5);
  const bool kept = classifier_.classify(centre, walk.measures.data()) &&
                    bandedSign(walk.measures[walk.mode], 0.0) == walk.sign;
  if (!kept && walk.broken_from < 0) {
    walk.broken_from = static_cast<std::int64_t>(a);
    walk.broken_to = static_cast<std::int64_t>(b);
  }
  return kept;
}

template <typename Visit>
void RegionSearch::forEachMove(Walk& walk, std::uint64_t cell, Visit&& visit) const {
  const int dims = grid_.dims();
  CellsAround around = cellsAround(grid_, cell);
  for (int k = 0; k < around.count; ++k) {
    const std::int64_t at = around.cells[k];
    if (at >= 0 && at != static_cast<std::int64_t>(cell) &&
        analysis_.label(static_cast<std::uint64_t>(at), walk.mode) != walk.region) {
      around.cells[k] = -1;
    }
  }
  if (dims > kNeighbourhoodDims) {
    for (int k = 1; k < around.count; ++k) {
      const std::int64_t next = around.cells[k];
      if (next >= 0 && passable(walk, cell, static_cast<std::uint64_t>(next))) {
        visit(static_cast<std::uint64_t>(next), step_length_[(k - 1) / 2]);
      }
    }
    return;
  }
  const int centre = (around.count - 1) / 2;
  // The cell's own faces, each checked once: a move must leave through those it crosses.
  bool leaves[kNeighbourhoodDims][2] = {};
  for (int d = 0; d < dims; ++d) {
    for (int side = 0; side < 2; ++side) {
      const std::int64_t next = around.cells[centre + (2 * side - 1) * kPower3[d]];
      leaves[d][side] = next >= 0 && passable(walk, cell, static_cast<std::uint64_t>(next));
    }
  }
  for (int k = 0; k < around.count; ++k) {
    if (k == centre || around.cells[k] < 0) continue;
    int moving = 0;
    double squared = 0.0;
    bool clear = true;
    for (int d = 0; d < dims; ++d) {
      const int offset = offsetOf(k, d);
      if (offset == 0) continue;
      moving |= 1 << d;
      squared += step_length_[d] * step_length_[d];
      clear = clear && leaves[d][offset > 0];
    }
    // The cells a diagonal move passes (the corners of its box, `subset` of its offsets
    // taken) must be in the region too. Its far faces are left to the check of the walk's
    // steps (PathPlanner::failedStep).
    for (int subset = (moving - 1) & moving; subset > 0 && clear; subset = (subset - 1) & moving) {
      int part = centre;
      for (int d = 0; d < dims; ++d) {
        if (subset >> d & 1) part += offsetOf(k, d) * kPower3[d];
      }
      clear = around.cells[part] >= 0;
    }
    if (clear) visit(static_cast<std::uint64_t>(around.cells[k]), std::sqrt(squared));
  }
}

CellPath RegionSearch::search(std::uint64_t from, std::uint64_t to, std::int32_t region, double heuristic_weight,
                              const BlockedMoves& blocked, const std::function<bool()>& stop) const {
  Walk walk;
  walk.mode = analysis_.regions()[region].mode;
  walk.region = region;
  walk.sign = analysis_.regions()[region].sign;
  walk.measures.resize(analysis_.modes().size());
  const GridCell target = grid_.cell(to);
  auto neighbours = [&](std::uint64_t cell, auto&& relax) {
    forEachMove(walk, cell, [&](std::uint64_t next, double length) {
      if (blocked.empty() || !blocked.count({cell, next})) relax(next, length);
    });
  };
  auto heuristic = [&](std::uint64_t cell) { return heuristic_weight * distance(grid_.cell(cell), target); };
  const std::size_t limit = analysis_.regions()[region].voxels + 1;
  CellPath path;
  const AStarResult<std::uint64_t> found =
      aStar(from, neighbours, heuristic, [to](std::uint64_t cell) { return cell == to; }, limit, stop, &path.reached);
  std::sort(path.reached.begin(), path.reached.end());
  path.cells = found.path;
  path.expanded = found.expanded;
  path.stopped = found.stopped;
  path.broken_from = walk.broken_from;
  path.broken_to = walk.broken_to;
  return path;
}

}  // namespace maximal_workspace
