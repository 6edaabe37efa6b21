#include "maximal_workspace/regions/pose_query.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>

#include "maximal_workspace/regions/orientation_coverage.h"

namespace maximal_workspace {

namespace {

// The gap between two values of a variable, an angle's within a half turn.
double gap(OutputVariable variable, double a, double b) {
  return isRotational(variable) ? std::abs(std::remainder(a - b, 2.0 * M_PI)) : std::abs(a - b);
}

double weight(const RobotModel& model, OutputVariable variable) {
  return isRotational(variable) ? model.characteristic_length : 1.0;
}

// Gaps beyond this are divided by the largest before they are squared: squares overflow
// past 1.3e154, and every term infinite left a pose far away without a nearest point.
constexpr double kLargestSquaredGap = 1e150;

bool onGridSlice(const Grid& grid, const Pose& pose) {
  for (int v = 0; v < kOutputVariableCount; ++v) {
    const auto variable = static_cast<OutputVariable>(v);
    const auto& grid_variables = grid.spec().variables;
    if (std::find(grid_variables.begin(), grid_variables.end(), variable) != grid_variables.end()) continue;
    if (!(gap(variable, pose.value(variable), grid.spec().start.value(variable)) <= kOnGridTolerance)) return false;
  }
  return true;
}

// The nearest cell of the maximal workspace of one assembly mode, exact, by branch and
// bound over the analysis's blocks. The squared distance over the grid variables is a sum
// of one term per variable, and a block's cells in the box are a product of index ranges,
// so the block's smallest distance is the sum of each variable's smallest term over its
// range: a bound no cell of the block beats, and one of them reaches. Blocks are taken in
// order of that bound (each variable's block coordinates sorted by their term, and the
// rank tuples enumerated with a heap: each is reached once, raising ranks in variable
// order), and the search stops at the first bound beyond the best distance found. A
// uniform block answers at its nearest cell; another is scanned. Ties go to the smallest
// grid index.
class NearestCellSearch {
 public:
  NearestCellSearch(const RobotModel& model, const WorkspaceAnalysis& analysis, const Pose& pose, std::int8_t sign)
      : model_(model), analysis_(analysis), grid_(analysis.grid()), layout_(analysis.blocks()), sign_(sign) {
    double largest = 0.0;
    for (int d = 0; d < grid_.dims(); ++d) {
      value_[d] = grid_.coordinate(pose, d);
      for (const std::int64_t end : {std::int64_t{0}, grid_.size(d) - 1}) largest = std::max(largest, weightedGap(d, end));
    }
    // Terms compare the same divided by one scale; only a pose too far for its squares
    // gets one (others keep their exact terms).
    if (!(largest <= kLargestSquaredGap)) scale_ = largest;
  }

  // False when the maximal workspace has no cell.
  bool find(std::uint64_t* cell) {
    prepareAxes();
    std::priority_queue<Ranks, std::vector<Ranks>, std::greater<Ranks>> queue;
    queue.push(withBound(Ranks{}));
    while (!queue.empty() && queue.top().bound <= best_) {
      const Ranks ranks = queue.top();
      queue.pop();
      for (int d = ranks.raised; d < grid_.dims(); ++d) {
        if (ranks.rank[d] + 1 >= layout_.blocks(d)) continue;
        Ranks next = ranks;
        ++next.rank[d];
        next.raised = d;
        queue.push(withBound(next));
      }
      GridCell block_coords{}, nearest{};
      for (int d = 0; d < grid_.dims(); ++d) {
        block_coords[d] = order_[d][ranks.rank[d]];
        nearest[d] = axes_[d][block_coords[d]].index;
      }
      const std::uint64_t block = layout_.blockIndex(block_coords);
      if (analysis_.blockUniform(block)) {
        std::uint64_t same_block = 0;
        int in_block = 0;
        layout_.locate(nearest, &same_block, &in_block);
        if (analysis_.inMaximalWorkspace(block, in_block, sign_)) offer(ranks.bound, nearest);
      } else {
        scan(block);
      }
    }
    *cell = best_cell_;
    return best_ < INFINITY;
  }

 private:
  // Along one variable, a block's cell in the box whose term is the smallest.
  struct AxisNearest {
    std::int64_t index = 0;
    double term = 0.0;
  };
  struct Ranks {
    double bound = 0.0;
    std::array<std::int64_t, kMaxGridDims> rank{};  // into order_, per variable
    int raised = 0;  // the last variable whose rank was raised: only it and later ones are raised next
    bool operator>(const Ranks& other) const { return bound > other.bound; }
  };

  // The squared, weighted gap along variable d between the pose and cell index i's centre
  // (divided by scale_ first).
  double term(int d, std::int64_t i) const {
    const double g = weightedGap(d, i) / scale_;
    return g * g;
  }
  double weightedGap(int d, std::int64_t i) const {
    return weight(model_, grid_.variable(d)) * gap(grid_.variable(d), value_[d], grid_.centre(d, i));
  }

  // Centres are evenly spaced, so rounding and clamping finds the nearest index in
  // [first, last]; an angle is tried at its turn below, at and above the range, which
  // covers every turn that can be nearest (the range spans at most a turn).
  AxisNearest axisNearest(int d, std::int64_t first, std::int64_t last) const {
    const auto at = [&](double value) {
      const double position = std::round((value - grid_.centre(d, 0)) / grid_.step(d));
      AxisNearest nearest;
      nearest.index = static_cast<std::int64_t>(std::clamp(position, double(first), double(last)));
      nearest.term = term(d, nearest.index);
      return nearest;
    };
    if (!isRotational(grid_.variable(d))) return at(value_[d]);
    const double low = grid_.centre(d, first);
    const double near_low = low + std::remainder(value_[d] - low, 2.0 * M_PI);
    AxisNearest best = at(near_low);
    for (const double turn : {-2.0 * M_PI, 2.0 * M_PI}) {
      const AxisNearest other = at(near_low + turn);
      if (other.term < best.term) best = other;
    }
    return best;
  }

  void prepareAxes() {
    const int side = layout_.side();
    const GridCell origin = layout_.cellCoords(0, 0);  // grid coordinates of block 0's first cell
    for (int d = 0; d < grid_.dims(); ++d) {
      for (std::int64_t b = 0; b < layout_.blocks(d); ++b) {
        const std::int64_t first = std::max<std::int64_t>(0, origin[d] + b * side);
        const std::int64_t last = std::min<std::int64_t>(grid_.size(d) - 1, origin[d] + (b + 1) * side - 1);
        axes_[d].push_back(axisNearest(d, first, last));
        order_[d].push_back(b);
      }
      std::sort(order_[d].begin(), order_[d].end(),
                [&](std::int64_t a, std::int64_t b) { return axes_[d][a].term < axes_[d][b].term; });
    }
  }

  Ranks withBound(Ranks ranks) const {
    ranks.bound = 0.0;
    for (int d = 0; d < grid_.dims(); ++d) ranks.bound += axes_[d][order_[d][ranks.rank[d]]].term;
    return ranks;
  }

  // A block that is not uniform: its cells of the maximal workspace, from every working
  // mode's labels at once, then their distances, from a term per variable and in-block
  // coordinate.
  void scan(std::uint64_t block) {
    const int cells = layout_.cellsPerBlock();
    const std::vector<Region>& regions = analysis_.regions();
    in_maximal_.assign(cells, false);
    labels_.resize(cells);
    for (int m = 0; m < static_cast<int>(analysis_.modes().size()); ++m) {
      analysis_.blockLabels(block, m, labels_.data());
      for (int cell = 0; cell < cells; ++cell) {
        const std::int32_t region = labels_[cell];
        if (region >= 0 && regions[region].sign == sign_ && !regions[region].debris) in_maximal_[cell] = true;
      }
    }
    const GridCell first = layout_.cellCoords(block, 0);
    std::array<std::array<double, 8>, kMaxGridDims> terms;  // a block's side is at most 8
    for (int d = 0; d < grid_.dims(); ++d) {
      for (int k = 0; k < layout_.side(); ++k) terms[d][k] = term(d, first[d] + k);
    }
    for (int cell = 0; cell < cells; ++cell) {
      if (!in_maximal_[cell]) continue;
      GridCell coords = first;
      double squared = 0.0;
      for (int d = 0; d < grid_.dims(); ++d) {
        coords[d] += layout_.cellCoord(cell, d);
        squared += terms[d][layout_.cellCoord(cell, d)];
      }
      offer(squared, coords);
    }
  }

  void offer(double squared, const GridCell& coords) {
    if (squared > best_) return;
    const std::uint64_t index = grid_.index(coords);
    if (squared < best_ || index < best_cell_) {
      best_ = squared;
      best_cell_ = index;
    }
  }

  const RobotModel& model_;
  const WorkspaceAnalysis& analysis_;
  const Grid& grid_;
  const BlockLayout& layout_;
  const std::int8_t sign_;
  std::array<double, kMaxGridDims> value_{};  // the pose's grid variables
  std::array<std::vector<AxisNearest>, kMaxGridDims> axes_;     // per variable and block coordinate
  std::array<std::vector<std::int64_t>, kMaxGridDims> order_;  // block coordinates by their term
  double scale_ = 1.0;      // the gaps' divisor (kLargestSquaredGap)
  double best_ = INFINITY;  // squared
  std::uint64_t best_cell_ = 0;
  std::vector<std::int32_t> labels_;
  std::vector<bool> in_maximal_;
};

}  // namespace

double gridDistance(const RobotModel& model, const Grid& grid, const Pose& a, const Pose& b) {
  std::array<double, kMaxGridDims> gaps{};
  double largest = 0.0;
  for (int d = 0; d < grid.dims(); ++d) {
    const OutputVariable variable = grid.variable(d);
    gaps[d] = weight(model, variable) * gap(variable, grid.coordinate(a, d), grid.coordinate(b, d));
    largest = std::max(largest, gaps[d]);
  }
  const double scale = largest > kLargestSquaredGap ? largest : 1.0;
  double sum = 0.0;
  for (int d = 0; d < grid.dims(); ++d) sum += (gaps[d] / scale) * (gaps[d] / scale);
  return std::sqrt(sum) * scale;
}

PoseQuery queryPose(const RobotModel& model, const WorkspaceAnalysis& analysis, const Pose& pose) {
  PoseQuery query;
  query.kinematics = analysePose(model, pose, analysis.modes());
  const int mode_count = static_cast<int>(analysis.modes().size());
  query.regions.assign(mode_count, -1);
  query.on_grid = onGridSlice(analysis.grid(), pose) && analysis.grid().cellOf(pose, &query.cell);
  if (query.on_grid) {
    query.in_workspace = analysis.inside(query.cell);
    for (int m = 0; m < mode_count; ++m) query.regions[m] = analysis.label(query.cell, m);
  }
  const std::vector<Region>& regions = analysis.regions();
  const std::vector<std::int32_t>& component = analysis.transitions().component;
  // The pose's position at the set's first orientation (the reference's): its cell's x y z.
  std::uint64_t position_cell = 0;
  bool has_coverage = false;
  std::array<std::array<double, 2>, 2> shares{};
  if (hasOrientationSet(analysis.grid())) {
    Pose at_reference = analysis.grid().spec().start;
    at_reference.position = pose.position;
    has_coverage = analysis.grid().cellOf(at_reference, &position_cell);
    if (has_coverage) {
      const GridCell cell = analysis.grid().cell(position_cell);
      shares = coverageAt(analysis, cell[0], cell[1], cell[2]);
    }
  }
  for (std::size_t a = 0; a < query.assembly_modes.size(); ++a) {
    AssemblyModeAtPose& at = query.assembly_modes[a];
    at.sign = analysis.assemblyModes()[a].sign;
    const std::int32_t traditional = analysis.assemblyModes()[a].traditional_region;
    for (int m = 0; m < mode_count; ++m) {
      const std::int32_t region = query.regions[m];
      if (region < 0 || regions[region].sign != at.sign || regions[region].debris) continue;
      at.modes.push_back(m);
      at.regions.push_back(region);
      at.reachable = at.reachable || (traditional >= 0 && component[region] == component[traditional]);
    }
    at.in_maximal = !at.modes.empty();
    at.has_coverage = has_coverage;
    at.coverage = shares[a][0];
    at.traditional_coverage = shares[a][1];
    if (at.in_maximal) {
      at.has_nearest = true;
      at.nearest = pose;
      at.distance = 0.0;
    } else if (analysis.assemblyModes()[a].maximal_voxels > 0 && pose.position.allFinite() &&
               pose.euler_zyz.allFinite() && NearestCellSearch(model, analysis, pose, at.sign).find(&at.nearest_cell)) {
      at.has_nearest = true;
      at.nearest = analysis.grid().pose(at.nearest_cell);
      at.distance = gridDistance(model, analysis.grid(), pose, at.nearest);
    }
  }
  return query;
}

}  // namespace maximal_workspace
