#include "maximal_workspace/regions/necks.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/input_error.h"

namespace maximal_workspace {

namespace {

constexpr std::uint32_t kNone = 0xffffffffu;

void checkComparable(const WorkspaceAnalysis& exact, const WorkspaceAnalysis& with_margin) {
  const GridSpec &a = exact.grid().spec(), &b = with_margin.grid().spec();
  if (a.variables != b.variables || a.steps != b.steps || exact.grid().cellCount() != with_margin.grid().cellCount() ||
      a.start.position != b.start.position) {
    throw InputError("necks: the two analyses are not on the same grid");
  }
  if (exact.modes().size() != with_margin.modes().size()) throw InputError("necks: the two analyses differ in working modes");
  for (std::size_t m = 0; m < exact.modes().size(); ++m) {
    if (exact.modes()[m].name != with_margin.modes()[m].name) throw InputError("necks: the two analyses differ in working modes");
  }
  if (!(exact.settings().margin < with_margin.settings().margin)) {
    throw InputError("necks: the analysis with the margin must have the larger margin");
  }
}

// One exact region that holds parts of several groups: its parts (the non-debris regions
// of the analysis with the margin inside it) and its cells that are in none of them, each
// with its |measure|.
struct SplitRegion {
  std::uint32_t exact_region = 0;
  std::map<std::int32_t, std::int32_t> part_group;  // part (region with the margin) -> its group
  std::vector<std::uint64_t> cells;                 // sorted grid indices
  std::vector<double> measures;                     // |measure| of cells[i]
  std::int32_t index(std::uint64_t cell) const {
    const auto it = std::lower_bound(cells.begin(), cells.end(), cell);
    return it != cells.end() && *it == cell ? static_cast<std::int32_t>(it - cells.begin()) : -1;
  }
};

// The exact regions of working mode `mode` whose parts belong to two groups or more.
std::map<std::int32_t, SplitRegion> splitRegions(const WorkspaceAnalysis& exact, const WorkspaceAnalysis& with_margin,
                                                 int mode) {
  std::map<std::int32_t, SplitRegion> split;
  for (const Region& part : with_margin.regions()) {
    if (part.debris || part.mode != mode) continue;
    const std::int32_t parent = exact.label(part.seed_cell, mode);
    split[parent].exact_region = static_cast<std::uint32_t>(parent);
    split[parent].part_group[static_cast<std::int32_t>(part.id)] = with_margin.transitions().component[part.id];
  }
  for (auto it = split.begin(); it != split.end();) {
    std::vector<std::int32_t> groups;
    for (const auto& [part, group] : it->second.part_group) groups.push_back(group);
    std::sort(groups.begin(), groups.end());
    const bool several = std::unique(groups.begin(), groups.end()) - groups.begin() > 1;
    it = several ? std::next(it) : split.erase(it);
  }
  return split;
}

// Fills each split region's cells: those of the exact region in no part.
void collectCells(const WorkspaceAnalysis& exact, const WorkspaceAnalysis& with_margin, int mode,
                  std::map<std::int32_t, SplitRegion>& split) {
  const BlockLayout& layout = exact.blocks();
  const int per_block = layout.cellsPerBlock();
  std::vector<std::int32_t> exact_labels(per_block), margin_labels(per_block);
  const auto in_part = [&](std::int32_t label, const SplitRegion& region) { return region.part_group.count(label) > 0; };
  for (std::uint64_t block = 0; block < layout.blockCount(); ++block) {
    if (exact.blockUniform(block) && !split.count(exact.label(block, 0, mode))) continue;
    exact.blockLabels(block, mode, exact_labels.data());
    with_margin.blockLabels(block, mode, margin_labels.data());
    for (int cell = 0; cell < per_block; ++cell) {
      const auto it = split.find(exact_labels[cell]);
      if (it == split.end() || in_part(margin_labels[cell], it->second)) continue;
      it->second.cells.push_back(layout.gridIndex(block, cell));
    }
  }
  for (auto& [label, region] : split) std::sort(region.cells.begin(), region.cells.end());
}

void measureCells(const PoseClassifier& classifier, const Grid& grid, int mode, SplitRegion& region) {
  std::vector<double> measures(classifier.modes().size());
  region.measures.resize(region.cells.size());
  for (std::size_t i = 0; i < region.cells.size(); ++i) {
    // Every cell of an exact region is assembled; a failure would be a classifier bug.
    region.measures[i] = classifier.classify(grid.pose(region.cells[i]), measures.data()) ? std::abs(measures[mode]) : 0.0;
  }
}

// Union-find over a split region's cells (0 .. n - 1) and its parts (n ..), each root
// with the group class it joins (-1: none yet); group classes are a second union-find.
class NeckSearch {
 public:
  NeckSearch(const WorkspaceAnalysis& with_margin, const SplitRegion& region, int mode)
      : with_margin_(with_margin), grid_(with_margin.grid()), region_(region), mode_(mode) {
    const std::size_t n = region.cells.size();
    for (const auto& [part, group] : region.part_group) part_node_[part] = static_cast<std::uint32_t>(n + part_node_.size());
    parent_.resize(n + part_node_.size());
    std::iota(parent_.begin(), parent_.end(), 0u);
    group_.assign(parent_.size(), -1);
    for (const auto& [part, group] : region.part_group) {
      group_[part_node_[part]] = group;
      group_parent_.emplace(group, group);
    }
    active_.assign(n, false);
  }

  std::vector<Neck> run();

 private:
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  std::int32_t findGroup(std::int32_t g) {
    while (group_parent_[g] != g) g = group_parent_[g] = group_parent_[group_parent_[g]];
    return g;
  }
  // The node of a grid cell: an active cell of the region or a part; kNone otherwise.
  std::uint32_t node(std::uint64_t cell) const;
  std::vector<std::uint32_t> neighbourNodes(std::uint64_t cell) const;
  Neck neckAt(std::uint32_t index, std::uint32_t side_a, std::uint32_t side_b);
  std::vector<NeckSample> passage(std::uint32_t index, std::uint32_t side_a, std::uint32_t side_b);
  void crossSection(std::uint32_t index, Neck& neck) const;

  const WorkspaceAnalysis& with_margin_;
  const Grid& grid_;
  const SplitRegion& region_;
  int mode_;
  std::map<std::int32_t, std::uint32_t> part_node_;
  std::vector<std::uint32_t> parent_;
  std::vector<std::int32_t> group_;  // per root: a group of its class, or -1
  std::map<std::int32_t, std::int32_t> group_parent_;
  std::vector<bool> active_;
};

std::uint32_t NeckSearch::node(std::uint64_t cell) const {
  const std::int32_t index = region_.index(cell);
  if (index >= 0) return active_[index] ? static_cast<std::uint32_t>(index) : kNone;
  const auto part = part_node_.find(with_margin_.label(cell, mode_));
  return part == part_node_.end() ? kNone : part->second;
}

std::vector<std::uint32_t> NeckSearch::neighbourNodes(std::uint64_t cell) const {
  std::vector<std::uint32_t> nodes;
  for (int d = 0; d < grid_.dims(); ++d) {
    for (int direction : {-1, 1}) {
      std::uint64_t next = 0;
      if (!grid_.neighbour(cell, d, direction, &next)) continue;
      const std::uint32_t n = node(next);
      if (n != kNone) nodes.push_back(n);
    }
  }
  return nodes;
}

// Cells join in decreasing |measure| (Kruskal's order for a widest path): a cell that
// first joins two sides of different group classes is a neck.
std::vector<Neck> NeckSearch::run() {
  std::vector<std::uint32_t> order(region_.cells.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return region_.measures[a] > region_.measures[b]; });
  std::vector<Neck> necks;
  for (const std::uint32_t index : order) {
    active_[index] = true;
    for (const std::uint32_t n : neighbourNodes(region_.cells[index])) {
      const std::uint32_t here = find(index), there = find(n);
      if (here == there) continue;
      if (group_[here] >= 0 && group_[there] >= 0 && findGroup(group_[here]) != findGroup(group_[there])) {
        necks.push_back(neckAt(index, here, there));
        group_parent_[findGroup(group_[there])] = findGroup(group_[here]);
      }
      parent_[there] = here;
      if (group_[here] < 0) group_[here] = group_[there];
    }
  }
  return necks;
}

Neck NeckSearch::neckAt(std::uint32_t index, std::uint32_t side_a, std::uint32_t side_b) {
  Neck neck;
  neck.mode = mode_;
  neck.exact_region = region_.exact_region;
  neck.measure = region_.measures[index];
  neck.pose = grid_.pose(region_.cells[index]);
  const auto smallest = [&](std::uint32_t root) {
    const std::int32_t cls = findGroup(group_[root]);
    std::int32_t best = cls;
    for (const auto& [group, parent] : group_parent_) {
      if (findGroup(group) == cls) best = std::min(best, group);
    }
    return best;
  };
  neck.groups = {smallest(side_a), smallest(side_b)};
  if (neck.groups[0] > neck.groups[1]) std::swap(neck.groups[0], neck.groups[1]);
  neck.passage = passage(index, side_a, side_b);
  crossSection(index, neck);
  return neck;
}

// Breadth first from the neck over the active cells (all at least as far from the
// singularity as the neck) to each side's part, before the two sides are joined.
std::vector<NeckSample> NeckSearch::passage(std::uint32_t index, std::uint32_t side_a, std::uint32_t side_b) {
  std::unordered_map<std::uint32_t, std::uint32_t> came_from{{index, index}};
  std::deque<std::uint32_t> queue{index};
  std::uint32_t end_a = kNone, end_b = kNone;
  while (!queue.empty() && (end_a == kNone || end_b == kNone)) {
    const std::uint32_t at = queue.front();
    queue.pop_front();
    for (const std::uint32_t n : neighbourNodes(region_.cells[at])) {
      const bool part = n >= region_.cells.size();
      const std::uint32_t root = find(n);
      if (part) {
        if (root == side_a && end_a == kNone) end_a = at;
        if (root == side_b && end_b == kNone) end_b = at;
      } else if (!came_from.count(n)) {
        came_from[n] = at;
        queue.push_back(n);
      }
    }
  }
  const auto trail = [&](std::uint32_t end) {
    std::vector<std::uint32_t> cells{end};
    while (cells.back() != index) cells.push_back(came_from.at(cells.back()));
    return cells;  // from the side's part to the neck
  };
  std::vector<std::uint32_t> cells = trail(end_a);
  std::vector<std::uint32_t> other = trail(end_b);
  cells.insert(cells.end(), other.rbegin() + 1, other.rend());
  std::vector<NeckSample> samples;
  for (const std::uint32_t c : cells) samples.push_back({grid_.pose(region_.cells[c]), region_.measures[c]});
  return samples;
}

// Floods, in each axis plane through the neck, the region's cells in no part; keeps the
// smallest flood.
void NeckSearch::crossSection(std::uint32_t index, Neck& neck) const {
  const int dims = grid_.dims();
  if (dims < 2) return;
  neck.cross_section_cells = std::numeric_limits<std::uint64_t>::max();
  for (int normal = 0; normal < dims; ++normal) {
    std::unordered_set<std::uint32_t> seen{index};
    std::deque<std::uint32_t> queue{index};
    GridCell low = grid_.cell(region_.cells[index]), high = low;
    while (!queue.empty() && seen.size() < kMaxCrossSectionCells) {
      const std::uint64_t at = region_.cells[queue.front()];
      queue.pop_front();
      for (int d = 0; d < dims; ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t next = 0;
          if (d == normal || !grid_.neighbour(at, d, direction, &next)) continue;
          const std::int32_t n = region_.index(next);
          if (n < 0 || !seen.insert(static_cast<std::uint32_t>(n)).second) continue;
          queue.push_back(static_cast<std::uint32_t>(n));
          const GridCell c = grid_.cell(next);
          for (int k = 0; k < dims; ++k) low[k] = std::min(low[k], c[k]), high[k] = std::max(high[k], c[k]);
        }
      }
    }
    if (seen.size() >= neck.cross_section_cells) continue;
    neck.cross_section_normal = normal;
    neck.cross_section_cells = seen.size();
    neck.cross_section_bounded = queue.empty();
    neck.cross_section_extent.assign(dims, 0.0);
    for (int k = 0; k < dims; ++k) {
      if (k != normal) neck.cross_section_extent[k] = static_cast<double>(high[k] - low[k] + 1) * grid_.step(k);
    }
  }
}

}  // namespace

std::vector<Neck> findNecks(const RobotModel& model, const WorkspaceAnalysis& exact, const WorkspaceAnalysis& with_margin) {
  checkComparable(exact, with_margin);
  const PoseClassifier classifier(model, exact.modes(), exact.grid().spec().start, exact.grid().isSpatial());
  std::vector<Neck> necks;
  for (int mode = 0; mode < static_cast<int>(exact.modes().size()); ++mode) {
    std::map<std::int32_t, SplitRegion> split = splitRegions(exact, with_margin, mode);
    if (split.empty()) continue;
    collectCells(exact, with_margin, mode, split);
    for (auto& [label, region] : split) {
      measureCells(classifier, exact.grid(), mode, region);
      for (Neck& neck : NeckSearch(with_margin, region, mode).run()) {
        neck.sign = exact.regions()[label].sign;
        necks.push_back(std::move(neck));
      }
    }
  }
  std::stable_sort(necks.begin(), necks.end(), [](const Neck& a, const Neck& b) {
    return a.sign != b.sign ? a.sign > b.sign : a.measure > b.measure;
  });
  return necks;
}

}  // namespace maximal_workspace
