#pragma once
// The planner's walk inside one singularity-free region, cell by cell, where a straight
// leg does not hold: an A* over the region's cells. A move goes to any of the 3^d - 1
// neighbours (to the 2d face neighbours on grids of more than three variables) without
// cutting a corner: every cell a diagonal move passes is in the region too, so the
// segment between two cell centres stays within the region's cells. Periodic variables
// wrap. The analysis's labels say which cells a region holds: each clear of DKP
// singularities by its margin at its centre. Between two cells, a layer of the other sign
// (or outside the workspace) thinner than a step can pass unseen by the analysis; so a
// move must also cross faces whose centres keep the region's sign: the face itself for a
// face move, the cell's faces it leaves through for a diagonal move. Internal to the library.

#include <array>
#include <cstdint>
#include <functional>
#include <set>
#include <utility>
#include <vector>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "planner_metric.h"

namespace maximal_workspace {

struct CellPath {
  std::vector<std::uint64_t> cells;  // from the first cell to the last; empty: none found
  std::size_t expanded = 0;
  bool stopped = false;  // the time budget ran out first
  // None found and not stopped: every cell the first reaches, sorted; the last is not one.
  std::vector<std::uint64_t> reached;
  // A face between two cells of the region whose centre does not keep its sign, if any was met.
  std::int64_t broken_from = -1, broken_to = -1;
};

// Moves (from cell, to cell) the search must not take: their segment failed its check.
using BlockedMoves = std::set<std::pair<std::uint64_t, std::uint64_t>>;

// The cells around a cell: on a grid of up to three variables its 3^d neighbourhood, entry
// k offset by (k / 3^j % 3 - 1) along variable j (the centre, k = (3^d - 1) / 2, is the
// cell itself); beyond three variables the cell and its 2d face neighbours, -d then +d in
// turn. -1 where the box ends.
constexpr int kMaxAround = 27;
struct CellsAround {
  std::array<std::int64_t, kMaxAround> cells{};
  int count = 0;
};
CellsAround cellsAround(const Grid& grid, std::uint64_t cell);

class RegionSearch {
 public:
  RegionSearch(const WorkspaceAnalysis& analysis, const PlannerMetric& metric, const PoseClassifier& classifier);

  // From cell `from` to cell `to`, both in `region`, over faces whose centres keep the
  // region's sign; the distance heuristic weighted by `heuristic_weight` (1: shortest on the
  // grid). Bounded by the region's cell count and by `stop`.
  CellPath search(std::uint64_t from, std::uint64_t to, std::int32_t region, double heuristic_weight,
                  const BlockedMoves& blocked, const std::function<bool()>& stop) const;

 private:
  struct Walk;
  // Calls visit(next cell, move length in m) for each move out of `cell` in the region.
  template <typename Visit>
  void forEachMove(Walk& walk, std::uint64_t cell, Visit&& visit) const;
  // Whether the face between two neighbouring cells of the walk's region keeps its sign at
  // its centre.
  bool passable(Walk& walk, std::uint64_t a, std::uint64_t b) const;
  // The metric distance between two cells' centres, from their lattice coordinates.
  double distance(const GridCell& a, const GridCell& b) const;

  const WorkspaceAnalysis& analysis_;
  const Grid& grid_;
  const PlannerMetric& metric_;
  const PoseClassifier& classifier_;
  std::array<double, kMaxGridDims> step_length_{};
};

}  // namespace maximal_workspace
