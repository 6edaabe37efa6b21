#include "maximal_workspace/regions/necks.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/input_error.h"

namespace maximal_workspace {

namespace {

constexpr std::uint32_t kNone = 0xffffffffu;
constexpr double kPart = std::numeric_limits<double>::infinity();  // a part's cells are all over the margin

void checkComparable(const WorkspaceAnalysis& exact, const WorkspaceAnalysis& with_margin) {
  const GridSpec &a = exact.grid().spec(), &b = with_margin.grid().spec();
  if (a.variables != b.variables || a.steps != b.steps || exact.grid().cellCount() != with_margin.grid().cellCount() ||
      a.start.position != b.start.position) {
    throw InputError("necks: the two analyses are not on the same grid");
  }
  bool same_modes = exact.modes().size() == with_margin.modes().size();
  for (std::size_t m = 0; same_modes && m < exact.modes().size(); ++m) {
    same_modes = exact.modes()[m].name == with_margin.modes()[m].name;
  }
  if (!same_modes) throw InputError("necks: the two analyses differ in working modes");
  if (!(exact.settings().margin < with_margin.settings().margin)) {
    throw InputError("necks: the analysis with the margin must have the larger margin");
  }
}

// An edge of the exact analysis's route graph: two cells of one working mode that share a
// face, or the two working modes at a transition point. Its weight is the smallest
// |measure| it touches.
struct Edge {
  std::uint32_t a = 0, b = 0;
  double weight = 0.0;
  std::uint32_t point = kNone;       // transition point, or kNone for a face
  std::uint32_t transition = kNone;  // its transition in the exact analysis
  std::uint8_t mode_a = 0, mode_b = 0;
};

// One assembly mode's route graph between the groups of the analysis with the margin.
// Nodes: the cells under the margin (in a region of the exact analysis, in no non-debris
// region with the margin), one per working mode, and the non-debris regions with the
// margin ("parts"), each carrying its group. Kruskal's order (decreasing weight) joins
// them as the margin falls; a join of two group classes is a neck.
class RouteGraph {
 public:
  RouteGraph(const RobotModel& model, const WorkspaceAnalysis& exact, const WorkspaceAnalysis& with_margin,
             std::int8_t sign);
  std::vector<Neck> necks();
  // The narrowest place of the widest route from `from` (a cell in a working mode) to `to`
  // in any of `to_modes`; nothing when no route joins them.
  std::optional<Neck> widestRoute(std::uint64_t from, int from_mode, std::uint64_t to, const std::vector<int>& to_modes);

 private:
  std::uint64_t key(std::uint64_t cell, int mode) const { return cell * modes_ + static_cast<std::uint64_t>(mode); }
  std::uint64_t cellOf(std::uint32_t node) const { return keys_[node] / modes_; }
  int modeOf(std::uint32_t node) const { return static_cast<int>(keys_[node] % modes_); }
  bool isPart(std::uint32_t node) const { return node >= keys_.size(); }
  std::uint32_t partOf(std::int32_t label) const { return label < 0 ? kNone : part_of_region_[label]; }
  double weight(std::uint32_t node) const { return isPart(node) ? kPart : measures_[node]; }
  // The node of a cell in a working mode, or kNone (outside this assembly mode's regions).
  std::uint32_t node(std::uint64_t cell, int mode) const;
  // False across a face the exact analysis cuts for the mode (a layer thinner than the
  // step): a route crosses no face its regions do not.
  bool crosses(std::uint64_t cell, std::uint64_t next, int d, int direction, int mode) const {
    return !exact_.faceCut(direction > 0 ? cell : next, d, mode);
  }
  void collectCells();
  void measureCells();
  void collectEdges();
  // The neighbours of a cell node over edges of at least `level`: (node, cell, mode).
  template <typename Visit>
  void forEachNeighbour(std::uint32_t node, double level, const Visit& visit) const;
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  std::int32_t findGroup(std::int32_t g) {
    while (group_parent_[g] != g) g = group_parent_[g] = group_parent_[group_parent_[g]];
    return g;
  }
  std::int32_t smallestGroup(std::uint32_t root);
  Neck neckAt(const Edge& edge, std::uint32_t side_a, std::uint32_t side_b);
  // From `start`, an end of `edge`, to a part of `side` over edges of at least the edge's
  // weight: the cell nodes on the way, listed from the part's end, and the part's cell
  // where the route meets it.
  struct Route {
    std::vector<std::uint32_t> cells;
    NeckEnd end;
  };
  Route routeToSide(std::uint32_t start, std::uint32_t side, const Edge& edge);
  void crossSection(std::uint32_t node, Neck& neck) const;
  void usablePoints(const Edge& edge, Neck& neck) const;

  const WorkspaceAnalysis& exact_;
  const WorkspaceAnalysis& with_margin_;
  const Grid& grid_;
  const std::int8_t sign_;
  const std::uint64_t modes_;
  const PoseClassifier classifier_;
  // The part of a region with the margin (kNone: debris, or the other sign), and each
  // part's group.
  std::vector<std::uint32_t> part_of_region_;
  std::vector<std::int32_t> part_group_;
  std::vector<std::uint64_t> keys_;                   // cell nodes, sorted: cell * modes + mode
  std::vector<double> measures_;                      // |measure| per cell node
  std::vector<Edge> edges_;
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> transition_edges_;  // node -> edges
  std::vector<std::uint32_t> parent_;
  std::vector<std::int32_t> group_;  // per root: a group of its class, or -1
  std::map<std::int32_t, std::int32_t> group_parent_;
};

RouteGraph::RouteGraph(const RobotModel& model, const WorkspaceAnalysis& exact, const WorkspaceAnalysis& with_margin,
                       std::int8_t sign)
    : exact_(exact),
      with_margin_(with_margin),
      grid_(exact.grid()),
      sign_(sign),
      modes_(exact.modes().size()),
      classifier_(model, exact.modes(), exact.grid().spec().start, exact.grid().isSpatial()) {
  part_of_region_.assign(with_margin.regions().size(), kNone);
  for (const Region& part : with_margin.regions()) {
    if (part.debris || part.sign != sign) continue;
    const std::int32_t group = with_margin.transitions().component[part.id];
    part_of_region_[part.id] = static_cast<std::uint32_t>(part_group_.size());
    part_group_.push_back(group);
    group_parent_.emplace(group, group);
  }
  collectCells();
  measureCells();
  collectEdges();
  parent_.resize(keys_.size() + part_group_.size());
  std::iota(parent_.begin(), parent_.end(), 0u);
  group_.assign(keys_.size(), -1);
  group_.insert(group_.end(), part_group_.begin(), part_group_.end());
}

std::uint32_t RouteGraph::node(std::uint64_t cell, int mode) const {
  const std::uint32_t part = partOf(with_margin_.label(cell, mode));
  if (part != kNone) return static_cast<std::uint32_t>(keys_.size() + part);
  const auto it = std::lower_bound(keys_.begin(), keys_.end(), key(cell, mode));
  return it != keys_.end() && *it == key(cell, mode) ? static_cast<std::uint32_t>(it - keys_.begin()) : kNone;
}

void RouteGraph::collectCells() {
  const BlockLayout& layout = exact_.blocks();
  const int per_block = layout.cellsPerBlock();
  std::vector<std::int32_t> exact_labels(per_block), margin_labels(per_block);
  const auto of_sign = [&](std::int32_t label) { return label >= 0 && exact_.regions()[label].sign == sign_; };
  for (int mode = 0; mode < static_cast<int>(modes_); ++mode) {
    for (std::uint64_t block = 0; block < layout.blockCount(); ++block) {
      if (exact_.blockUniform(block) && !of_sign(exact_.label(block, 0, mode))) continue;
      if (with_margin_.blockUniform(block) && partOf(with_margin_.label(block, 0, mode)) != kNone) continue;
      exact_.blockLabels(block, mode, exact_labels.data());
      with_margin_.blockLabels(block, mode, margin_labels.data());
      for (int cell = 0; cell < per_block; ++cell) {
        if (of_sign(exact_labels[cell]) && partOf(margin_labels[cell]) == kNone) {
          keys_.push_back(key(layout.gridIndex(block, cell), mode));
        }
      }
    }
  }
  std::sort(keys_.begin(), keys_.end());
}

void RouteGraph::measureCells() {
  std::vector<double> measures(modes_);
  measures_.resize(keys_.size());
  std::uint64_t classified = std::numeric_limits<std::uint64_t>::max();
  for (std::size_t i = 0; i < keys_.size(); ++i) {
    const std::uint64_t cell = cellOf(static_cast<std::uint32_t>(i));
    // Every cell of an exact region is assembled; keys of one cell are consecutive.
    if (cell != classified) classifier_.classify(grid_.pose(cell), measures.data());
    classified = cell;
    measures_[i] = std::abs(measures[modeOf(static_cast<std::uint32_t>(i))]);
  }
}

void RouteGraph::collectEdges() {
  for (std::uint32_t u = 0; u < keys_.size(); ++u) {
    for (int d = 0; d < grid_.dims(); ++d) {
      for (int direction : {-1, 1}) {
        std::uint64_t next = 0;
        if (!grid_.neighbour(cellOf(u), d, direction, &next) || !crosses(cellOf(u), next, d, direction, modeOf(u))) continue;
        const std::uint32_t v = node(next, modeOf(u));
        // A face between two cell nodes is added once, from its lower side.
        if (v == kNone || (!isPart(v) && direction < 0)) continue;
        const auto mode = static_cast<std::uint8_t>(modeOf(u));
        edges_.push_back({u, v, std::min(weight(u), weight(v)), kNone, kNone, mode, mode});
      }
    }
  }
  const TransitionGraph& graph = exact_.transitions();
  std::vector<double> measures(modes_);
  for (std::uint32_t index = 0; index < graph.transitions.size(); ++index) {
    const Transition& t = graph.transitions[index];
    const Region &from = exact_.regions()[t.from_region], &to = exact_.regions()[t.to_region];
    if (t.sign != sign_ || from.debris || to.debris) continue;
    for (const std::uint32_t p : t.points) {
      const std::uint64_t cell = graph.points[p].cell;
      const std::uint32_t a = node(cell, from.mode), b = node(cell, to.mode);
      if (a == kNone || b == kNone || a == b) continue;
      double w = std::min(weight(a), weight(b));
      if (classifier_.classify(graph.pose(p), measures.data())) {
        w = std::min({w, std::abs(measures[from.mode]), std::abs(measures[to.mode])});
      }
      if (!isPart(a)) transition_edges_[a].push_back(static_cast<std::uint32_t>(edges_.size()));
      if (!isPart(b)) transition_edges_[b].push_back(static_cast<std::uint32_t>(edges_.size()));
      edges_.push_back({a, b, w, p, index, static_cast<std::uint8_t>(from.mode), static_cast<std::uint8_t>(to.mode)});
    }
  }
}

template <typename Visit>
void RouteGraph::forEachNeighbour(std::uint32_t u, double level, const Visit& visit) const {
  const std::uint64_t cell = cellOf(u);
  const int mode = modeOf(u);
  for (int d = 0; d < grid_.dims(); ++d) {
    for (int direction : {-1, 1}) {
      std::uint64_t next = 0;
      if (!grid_.neighbour(cell, d, direction, &next) || !crosses(cell, next, d, direction, mode)) continue;
      const std::uint32_t v = node(next, mode);
      if (v != kNone && std::min(weight(u), weight(v)) >= level) visit(v, next, mode);
    }
  }
  const auto transitions = transition_edges_.find(u);
  if (transitions == transition_edges_.end()) return;
  for (const std::uint32_t e : transitions->second) {
    const Edge& edge = edges_[e];
    if (edge.weight < level) continue;
    if (edge.a == u) visit(edge.b, cell, int(edge.mode_b));
    else visit(edge.a, cell, int(edge.mode_a));
  }
}

std::int32_t RouteGraph::smallestGroup(std::uint32_t root) {
  const std::int32_t cls = findGroup(group_[root]);
  std::int32_t smallest = cls;
  for (const auto& [group, parent] : group_parent_) {
    if (findGroup(group) == cls) smallest = std::min(smallest, group);
  }
  return smallest;
}

std::vector<Neck> RouteGraph::necks() {
  std::vector<std::uint32_t> order(edges_.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return edges_[x].weight > edges_[y].weight; });
  std::vector<Neck> necks;
  for (const std::uint32_t e : order) {
    const std::uint32_t a = find(edges_[e].a), b = find(edges_[e].b);
    if (a == b) continue;
    if (group_[a] >= 0 && group_[b] >= 0 && findGroup(group_[a]) != findGroup(group_[b])) {
      necks.push_back(neckAt(edges_[e], a, b));
      group_parent_[findGroup(group_[b])] = findGroup(group_[a]);
    }
    parent_[b] = a;
    if (group_[a] < 0) group_[a] = group_[b];
  }
  return necks;
}

std::optional<Neck> RouteGraph::widestRoute(std::uint64_t from, int from_mode, std::uint64_t to,
                                            const std::vector<int>& to_modes) {
  const std::uint32_t start = node(from, from_mode);
  std::vector<std::uint32_t> ends;
  for (const int mode : to_modes) {
    const std::uint32_t end = node(to, mode);
    if (end != kNone) ends.push_back(end);
  }
  if (start == kNone || ends.empty()) return std::nullopt;
  std::vector<std::uint32_t> order(edges_.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return edges_[x].weight > edges_[y].weight; });
  auto joined = [&] {
    return std::any_of(ends.begin(), ends.end(), [&](std::uint32_t end) { return find(end) == find(start); });
  };
  if (joined()) {  // one part holds both: the route's narrowest place is one of its ends
    Neck neck;
    neck.sign = sign_;
    neck.measure = std::min(weight(start), weight(ends.front()));
    neck.pose = grid_.pose(from);
    neck.mode = from_mode;
    return neck;
  }
  for (const std::uint32_t e : order) {
    const Edge& edge = edges_[e];
    const std::uint32_t a = find(edge.a), b = find(edge.b);
    if (a == b) continue;
    parent_[b] = a;
    if (!joined()) continue;
    Neck neck;
    neck.sign = sign_;
    neck.measure = edge.weight;
    neck.mode = edge.mode_a;
    if (edge.point != kNone) {
      neck.kind = Neck::Kind::Transition;
      neck.to_mode = edge.mode_b;
      neck.pose = exact_.transitions().pose(edge.point);
    } else {
      const std::uint32_t low = isPart(edge.b) || (!isPart(edge.a) && measures_[edge.a] <= measures_[edge.b]) ? edge.a : edge.b;
      neck.pose = grid_.pose(cellOf(low));
    }
    return neck;
  }
  return std::nullopt;
}

Neck RouteGraph::neckAt(const Edge& edge, std::uint32_t side_a, std::uint32_t side_b) {
  Neck neck;
  neck.sign = sign_;
  neck.measure = edge.weight;
  neck.groups = {smallestGroup(side_a), smallestGroup(side_b)};
  // The passage: from side a's part to the edge, then on to side b's part.
  const Route to_a = routeToSide(edge.a, side_a, edge);
  Route to_b = routeToSide(edge.b, side_b, edge);
  std::vector<std::uint32_t> cells = to_a.cells;
  cells.insert(cells.end(), to_b.cells.rbegin(), to_b.cells.rend());
  for (const std::uint32_t c : cells) neck.passage.push_back({grid_.pose(cellOf(c)), modeOf(c), measures_[c]});
  neck.ends = {to_a.end, to_b.end};
  if (neck.groups[0] > neck.groups[1]) {  // listed from the smaller group's side
    std::swap(neck.groups[0], neck.groups[1]);
    std::swap(neck.ends[0], neck.ends[1]);
    std::reverse(neck.passage.begin(), neck.passage.end());
  }
  neck.mode = edge.mode_a;
  if (edge.point != kNone) {
    neck.kind = Neck::Kind::Transition;
    neck.to_mode = edge.mode_b;
    neck.pose = exact_.transitions().pose(edge.point);
    usablePoints(edge, neck);
    return neck;
  }
  // A face: the neck is its cell node with the smaller |measure|.
  const std::uint32_t low = isPart(edge.b) || (!isPart(edge.a) && measures_[edge.a] <= measures_[edge.b]) ? edge.a : edge.b;
  neck.pose = grid_.pose(cellOf(low));
  crossSection(low, neck);
  return neck;
}

// Breadth first, before the two sides are joined: every edge of at least the weight is
// already inside a side or another component, so the first part of `side` reached ends
// the route.
RouteGraph::Route RouteGraph::routeToSide(std::uint32_t start, std::uint32_t side, const Edge& edge) {
  Route route;
  if (isPart(start)) {
    // The edge itself meets the part: at the transition point's cell, or across the face.
    const std::uint32_t other = start == edge.a ? edge.b : edge.a;
    const int mode = start == edge.a ? edge.mode_a : edge.mode_b;
    std::uint64_t cell = edge.point != kNone ? exact_.transitions().points[edge.point].cell : cellOf(other);
    if (edge.point == kNone) {
      for (int d = 0; d < grid_.dims(); ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t next = 0;
          if (grid_.neighbour(cellOf(other), d, direction, &next) && crosses(cellOf(other), next, d, direction, mode) &&
              node(next, mode) == start) {
            cell = next;
          }
        }
      }
    }
    route.end = {grid_.pose(cell), mode};
    return route;
  }
  std::unordered_map<std::uint32_t, std::uint32_t> came_from{{start, start}};
  std::deque<std::uint32_t> queue{start};
  std::uint32_t end = kNone;
  while (!queue.empty() && end == kNone) {
    const std::uint32_t at = queue.front();
    queue.pop_front();
    forEachNeighbour(at, edge.weight, [&](std::uint32_t v, std::uint64_t cell, int mode) {
      if (end != kNone) return;
      if (isPart(v)) {
        if (find(v) != side) return;
        end = at;
        route.end = {grid_.pose(cell), mode};
      } else if (came_from.emplace(v, at).second) {
        queue.push_back(v);
      }
    });
  }
  for (std::uint32_t at = end == kNone ? start : end;; at = came_from.at(at)) {
    route.cells.push_back(at);
    if (at == start) break;
  }
  return route;
}

// Floods, in each axis plane through the neck, the cell nodes of its working mode at
// least half as far from the singularity as the neck; keeps the smallest flood.
void RouteGraph::crossSection(std::uint32_t neck_node, Neck& neck) const {
  const int dims = grid_.dims();
  if (dims < 2) return;
  const int mode = modeOf(neck_node);
  neck.cross_section_cells = std::numeric_limits<std::uint64_t>::max();
  for (int normal = 0; normal < dims; ++normal) {
    std::unordered_set<std::uint32_t> seen{neck_node};
    std::deque<std::uint32_t> queue{neck_node};
    GridCell low = grid_.cell(cellOf(neck_node)), high = low;
    while (!queue.empty() && seen.size() < kMaxCrossSectionCells) {
      const std::uint64_t at = cellOf(queue.front());
      queue.pop_front();
      for (int d = 0; d < dims; ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t next = 0;
          if (d == normal || !grid_.neighbour(at, d, direction, &next)) continue;
          const std::uint32_t v = node(next, mode);
          if (v == kNone || isPart(v) || measures_[v] < 0.5 * neck.measure || !seen.insert(v).second) continue;
          queue.push_back(v);
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

// A transition neck's width: the points of its transition whose edges are at least half
// as wide, joined to the neck's point through points in neighbouring cells; their count
// and the extent of their box.
void RouteGraph::usablePoints(const Edge& neck_edge, Neck& neck) const {
  const TransitionGraph& graph = exact_.transitions();
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> by_cell;  // cell -> points
  for (const Edge& edge : edges_) {
    if (edge.transition == neck_edge.transition && edge.weight >= 0.5 * neck_edge.weight) {
      by_cell[graph.points[edge.point].cell].push_back(edge.point);
    }
  }
  const int dims = grid_.dims();
  std::unordered_set<std::uint32_t> seen{neck_edge.point};
  std::deque<std::uint32_t> queue{neck_edge.point};
  std::vector<double> low(dims, std::numeric_limits<double>::infinity()), high(dims, -low[0]);
  while (!queue.empty()) {
    const std::uint32_t point = queue.front();
    queue.pop_front();
    const Pose pose = graph.pose(point);
    for (int d = 0; d < dims; ++d) {
      low[d] = std::min(low[d], grid_.coordinate(pose, d));
      high[d] = std::max(high[d], grid_.coordinate(pose, d));
    }
    // Points in the same cell or a face neighbour's, then theirs: the boundary surface.
    std::vector<std::uint64_t> cells{graph.points[point].cell};
    for (int d = 0; d < dims; ++d) {
      for (int direction : {-1, 1}) {
        std::uint64_t next = 0;
        if (grid_.neighbour(graph.points[point].cell, d, direction, &next)) cells.push_back(next);
      }
    }
    for (const std::uint64_t cell : cells) {
      const auto found = by_cell.find(cell);
      if (found == by_cell.end()) continue;
      for (const std::uint32_t other : found->second) {
        if (seen.insert(other).second) queue.push_back(other);
      }
    }
  }
  neck.cross_section_cells = seen.size();
  neck.cross_section_extent.resize(dims);
  for (int d = 0; d < dims; ++d) neck.cross_section_extent[d] = high[d] - low[d];
}

}  // namespace

std::optional<Neck> widestRouteNeck(const RobotModel& model, const WorkspaceAnalysis& exact,
                                    const WorkspaceAnalysis& with_margin, std::int8_t sign, std::uint64_t from, int from_mode,
                                    std::uint64_t to, const std::vector<int>& to_modes) {
  checkComparable(exact, with_margin);
  return RouteGraph(model, exact, with_margin, sign).widestRoute(from, from_mode, to, to_modes);
}

std::vector<Neck> findNecks(const RobotModel& model, const WorkspaceAnalysis& exact, const WorkspaceAnalysis& with_margin) {
  checkComparable(exact, with_margin);
  std::vector<Neck> necks;
  for (const std::int8_t sign : {std::int8_t{1}, std::int8_t{-1}}) {
    std::vector<Neck> of_sign = RouteGraph(model, exact, with_margin, sign).necks();
    std::stable_sort(of_sign.begin(), of_sign.end(), [](const Neck& a, const Neck& b) { return a.measure > b.measure; });
    for (Neck& neck : of_sign) necks.push_back(std::move(neck));
  }
  return necks;
}

}  // namespace maximal_workspace
