#include "maximal_workspace/planner/path_planner.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <queue>
#include <set>
#include <tuple>
#include <unordered_map>

#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

constexpr std::size_t kPortalsPerTransition = 16;
// Routes tried with straight legs only, then with voxel searches allowed.
constexpr int kStraightRouteAttempts = 60;
constexpr int kRouteAttempts = 25;
constexpr std::size_t kExpansionLimit = 5'000'000;

Pose lerp(const Pose& a, const Pose& b, double t) {
  Pose result;
  result.position = a.position + t * (b.position - a.position);
  result.euler_zyz = a.euler_zyz + t * (b.euler_zyz - a.euler_zyz);
  return result;
}

std::string positionText(const Pose& pose) { return vectorText(pose.position); }

char signChar(std::int8_t sign) { return sign > 0 ? '+' : '-'; }

// Up to `count` of `points`, spread out: farthest-point sampling from the first.
std::vector<std::uint32_t> spreadOut(const std::vector<std::uint32_t>& points, const std::vector<TransitionPoint>& all,
                                     std::size_t count) {
  if (points.size() <= count) return points;
  std::vector<std::uint32_t> chosen = {points.front()};
  std::vector<double> distance(points.size(), INFINITY);
  while (chosen.size() < count) {
    const Eigen::Vector3d& last = all[chosen.back()].pose.position;
    std::size_t farthest = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      distance[i] = std::min(distance[i], (all[points[i]].pose.position - last).norm());
      if (distance[i] > distance[farthest]) farthest = i;
    }
    chosen.push_back(points[farthest]);
  }
  return chosen;
}

}  // namespace

// A stretch of the route inside one region, between two poses.
struct PathPlanner::Leg {
  Pose from, to;
  int mode;
  std::int32_t region;
  int from_node, to_node;  // route nodes, to strike the leg if it cannot be made
};

struct PathPlanner::LegResult {
  bool ok = false;
  std::vector<Pose> via;  // voxel centres between from and to (empty: straight)
  std::size_t expanded = 0;
};

PathPlanner::PathPlanner(const RobotModel& model, WorkspaceAnalysis analysis)
    : analysis_(std::move(analysis)),
      classifier_(model, analysis_.modes(), analysis_.grid().spec().start, analysis_.grid().isSpatial()),
      singular_threshold_(analysis_.settings().singular_threshold) {
  const std::vector<Region>& regions = analysis_.regions();
  const TransitionGraph& graph = analysis_.transitions();
  for (const Transition& transition : graph.transitions) {
    const Region& from = regions[transition.from_region];
    const Region& to = regions[transition.to_region];
    if (from.debris || to.debris) continue;
    for (std::uint32_t p : spreadOut(transition.points, graph.points, kPortalsPerTransition)) {
      const std::uint32_t index = static_cast<std::uint32_t>(portals_.size());
      portals_.push_back(Portal{p,
                                {static_cast<std::int32_t>(transition.from_region), static_cast<std::int32_t>(transition.to_region)},
                                {from.mode, to.mode},
                                transition.input});
      portals_by_region_[transition.from_region].push_back(index);
      portals_by_region_[transition.to_region].push_back(index);
    }
  }
}

double PathPlanner::checkSegment(const Pose& from, const Pose& to, int mode, std::int8_t sign, double clearance) const {
  const double spacing = 0.25 * analysis_.grid().step(0);
  const int samples = std::max(1, static_cast<int>(std::ceil((to.position - from.position).norm() / spacing)));
  std::vector<double> measures(analysis_.modes().size());
  double smallest = INFINITY;
  for (int k = 0; k <= samples; ++k) {
    if (!classifier_.classify(lerp(from, to, static_cast<double>(k) / samples), measures.data())) return -1.0;
    const double measure = measures[mode];
    if (bandedSign(measure, singular_threshold_) != sign || std::abs(measure) < clearance) return -1.0;
    smallest = std::min(smallest, std::abs(measure));
  }
  return smallest;
}

// A* over one region's voxels in one working mode, 26- (or 8-) connected without cutting
// corners, each metre costing more near DKP singularities.
PathPlanner::LegResult PathPlanner::walkRegion(const Pose& from, const Pose& to, int mode, std::int32_t region,
                                               std::int8_t sign, const PlanRequest& request, double clearance,
                                               bool straight_only) const {
  LegResult result;
  if (checkSegment(from, to, mode, sign, clearance) >= 0.0) {
    result.ok = true;
    return result;
  }
  if (straight_only) return result;
  const Grid& grid = analysis_.grid();
  const int dims = grid.dims();
  std::uint64_t start = 0, goal = 0;  // cells
  if (!grid.cellOf(from, &start) || !grid.cellOf(to, &goal) || !analysis_.inside(start) || !analysis_.inside(goal)) {
    return result;
  }
  const bool penalise = request.costs.clearance_weight > 0.0 && request.costs.clearance_soft > 0.0;
  std::vector<double> measures(analysis_.modes().size());
  std::unordered_map<std::uint64_t, double> weights;  // a cell is a neighbour many times: classify it once
  // Cost per metre in a cell; < 0: not allowed there.
  auto weight = [&](std::uint64_t cell) -> double {
    if (!penalise && clearance <= singular_threshold_) return 1.0;
    const auto known = weights.find(cell);
    if (known != weights.end()) return known->second;
    classifier_.classify(grid.pose(cell), measures.data());
    const double measure = std::abs(measures[mode]);
    const double w = measure < clearance ? -1.0
                     : 1.0 + (penalise ? request.costs.clearance_weight *
                                             std::max(0.0, 1.0 - measure / request.costs.clearance_soft)
                                       : 0.0);
    weights.emplace(cell, w);
    return w;
  };
  auto centre = [&](std::uint64_t cell) { return grid.pose(cell).position; };
  const Eigen::Vector3d target = centre(goal);
  struct Visit {
    double cost;
    std::uint64_t parent;
    bool closed;
  };
  std::unordered_map<std::uint64_t, Visit> visits;
  using Entry = std::pair<double, std::uint64_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  visits[start] = Visit{0.0, start, false};
  open.push({request.heuristic_weight * (centre(start) - target).norm(), start});
  const double step = grid.step(0);
  auto inRegion = [&](const GridCell& cell, const int* offset) -> std::int64_t {
    GridCell next = cell;
    for (int d = 0; d < dims; ++d) {
      next[d] += offset[d];
      if (next[d] < 0 || next[d] >= grid.size(d)) return -1;
    }
    const std::uint64_t index = grid.index(next);
    return analysis_.label(index, mode) == region ? static_cast<std::int64_t>(index) : -1;
  };
  while (!open.empty() && result.expanded < kExpansionLimit) {
    const std::uint64_t current = open.top().second;
    open.pop();
    Visit& visit = visits[current];
    if (visit.closed) continue;
    visit.closed = true;
    ++result.expanded;
    if (current == goal) {
      for (std::uint64_t v = goal; v != start; v = visits[v].parent) {
        Pose pose = from;
        pose.position = centre(v);
        result.via.push_back(pose);
      }
      Pose first = from;
      first.position = centre(start);
      result.via.push_back(first);
      std::reverse(result.via.begin(), result.via.end());
      result.ok = true;
      return result;
    }
    const double cost = visit.cost;
    const GridCell cell = grid.cell(current);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = (dims == 3 ? -1 : 0); dz <= (dims == 3 ? 1 : 0); ++dz) {
          const int move[3] = {dx, dy, dz};
          if (!(dx || dy || dz)) continue;
          const std::int64_t next = inRegion(cell, move);
          if (next < 0) continue;
          // No corner cutting: every cell between must be in the region too.
          bool clear = true;
          for (int subset = 1; subset < 7 && clear; ++subset) {
            const int part[3] = {(subset & 1) ? dx : 0, (subset & 2) ? dy : 0, (subset & 4) ? dz : 0};
            const bool proper = (part[0] || part[1] || part[2]) && !(part[0] == dx && part[1] == dy && part[2] == dz);
            if (proper) clear = inRegion(cell, part) >= 0;
          }
          if (!clear) continue;
          auto [it, inserted] = visits.try_emplace(static_cast<std::uint64_t>(next));
          if (!inserted && it->second.closed) continue;
          const double w = weight(static_cast<std::uint64_t>(next));
          if (w < 0.0) continue;
          const double next_cost = cost + w * step * std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz));
          if (!inserted && it->second.cost <= next_cost) continue;
          it->second = Visit{next_cost, current, false};
          open.push({next_cost + request.heuristic_weight * (centre(static_cast<std::uint64_t>(next)) - target).norm(),
                     static_cast<std::uint64_t>(next)});
        }
      }
    }
  }
  return result;
}

Plan PathPlanner::plan(const PlanRequest& request) const {
  Plan plan;
  const Grid& grid = analysis_.grid();
  const std::vector<WorkingMode>& modes = analysis_.modes();
  const std::vector<Region>& regions = analysis_.regions();
  const TransitionGraph& graph = analysis_.transitions();
  const int mode_count = static_cast<int>(modes.size());
  auto fail = [&plan](const std::string& message) {
    plan.success = false;
    plan.message = message;
    return plan;
  };
  if (!grid.isSpatial()) return fail("the planner needs a workspace over x y z (or x y for a planar robot)");
  if (request.start_mode < 0 || request.start_mode >= mode_count) return fail("unknown start working mode");
  std::vector<bool> allowed(mode_count, request.allowed_modes.empty());
  for (int m : request.allowed_modes) {
    if (m >= 0 && m < mode_count) allowed[m] = true;
  }
  if (!allowed[request.start_mode]) return fail("the start working mode is not among the allowed ones");
  const double clearance = std::max(request.clearance, singular_threshold_);

  // Where a pose is: its cell, and the measures of every working mode at the pose itself.
  std::vector<double> start_measures(mode_count), goal_measures(mode_count);
  auto locate = [&](const Pose& pose, std::vector<double>& measures, std::uint64_t* cell) {
    if (!grid.cellOf(pose, cell) || !analysis_.inside(*cell)) return false;
    return classifier_.classify(pose, measures.data());
  };
  std::uint64_t start_cell = 0, goal_cell = 0;
  if (!locate(request.start, start_measures, &start_cell)) {
    return fail("the start " + positionText(request.start) + " is outside the workspace");
  }
  if (!locate(request.goal, goal_measures, &goal_cell)) {
    return fail("the goal " + positionText(request.goal) + " is outside the workspace");
  }
  const int m0 = request.start_mode;
  const std::string m0_name = modes[m0].name;
  plan.sign = bandedSign(start_measures[m0], singular_threshold_);
  if (plan.sign == 0) {
    return fail("the start is on a DKP singularity of working mode " + m0_name + " (|measure| " +
                numberText(std::abs(start_measures[m0])) + " < " + numberText(singular_threshold_) + ")");
  }
  if (std::abs(start_measures[m0]) < clearance) {
    return fail("the start is closer to a DKP singularity of working mode " + m0_name + " than the clearance (|measure| " +
                numberText(std::abs(start_measures[m0])) + " < " + numberText(clearance) + ")");
  }
  auto regionOf = [&](std::uint64_t cell, int mode) -> std::int32_t {
    const std::int32_t label = analysis_.label(cell, mode);
    return label >= 0 && regions[label].sign == plan.sign && !regions[label].debris ? label : -1;
  };
  const std::int32_t start_region = regionOf(start_cell, m0);
  if (start_region < 0) {
    return fail("the start is too close to a DKP singularity of working mode " + m0_name +
                ": its voxel is not in a singularity-free region of that working mode");
  }
  // The goal's regions, one per working mode it may be reached in, and why there are none.
  std::vector<std::pair<int, std::int32_t>> goal_regions;  // (mode, region)
  bool other_assembly_mode = false;
  for (int m = 0; m < mode_count; ++m) {
    if (!allowed[m] || (request.goal_mode >= 0 && m != request.goal_mode)) continue;
    const std::int8_t sign = bandedSign(goal_measures[m], singular_threshold_);
    other_assembly_mode = other_assembly_mode || sign == -plan.sign;
    const std::int32_t region = regionOf(goal_cell, m);
    if (region >= 0 && sign == plan.sign && std::abs(goal_measures[m]) >= clearance) goal_regions.push_back({m, region});
  }
  if (goal_regions.empty()) {
    if (other_assembly_mode) {
      return fail(std::string("the goal is only in the other assembly mode (") + signChar(-plan.sign) +
                  ") of the working modes allowed: reaching it requires crossing a DKP singularity");
    }
    return fail("the goal is on or too close to a DKP singularity in every working mode allowed");
  }
  const std::int32_t start_component = graph.component[start_region];
  if (std::none_of(goal_regions.begin(), goal_regions.end(),
                   [&](const auto& goal) { return graph.component[goal.second] == start_component; })) {
    return fail("no path without crossing a DKP singularity: the goal's regions are not joined to the start's by "
                "IKP-singularity transitions");
  }

  // Route nodes: 0 the start, 1..G the goal in each of its regions, then the portals. A
  // route state is a node and the region the robot is in there.
  const int goals = static_cast<int>(goal_regions.size());
  auto nodePose = [&](int node) -> Pose {
    if (node == 0) return request.start;
    if (node <= goals) return request.goal;
    return graph.points[portals_[node - 1 - goals].point].pose;
  };
  std::set<std::tuple<int, int, std::int32_t>> struck;  // legs (from node, to node, region) that failed
  const Eigen::Vector3d goal_position = request.goal.position;
  // First routes whose legs are all straight (cheap to check, many portals to choose
  // from); only when none is found, legs searched voxel by voxel.
  for (plan.routes = 1; plan.routes <= kStraightRouteAttempts + kRouteAttempts; ++plan.routes) {
    const bool straight_only = plan.routes <= kStraightRouteAttempts;
    if (plan.routes == kStraightRouteAttempts + 1) struck.clear();
    using State = std::pair<int, std::int32_t>;
    struct RouteVisit {
      double cost;
      State parent;
      bool closed;
    };
    std::map<State, RouteVisit> visits;
    using Entry = std::pair<double, State>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
    const State origin{0, start_region};
    visits[origin] = RouteVisit{0.0, origin, false};
    open.push({(request.start.position - goal_position).norm(), origin});
    State reached{-1, -1};
    while (!open.empty()) {
      const State state = open.top().second;
      open.pop();
      RouteVisit& visit = visits[state];
      if (visit.closed) continue;
      visit.closed = true;
      if (state.first >= 1 && state.first <= goals) {
        reached = state;
        break;
      }
      const double cost = visit.cost;
      const Eigen::Vector3d here = nodePose(state.first).position;
      auto relax = [&](State next, double next_cost) {
        auto [it, inserted] = visits.try_emplace(next, RouteVisit{next_cost, state, false});
        if (!inserted) {
          if (it->second.closed || it->second.cost <= next_cost) return;
          it->second = RouteVisit{next_cost, state, false};
        }
        open.push({next_cost + (nodePose(next.first).position - goal_position).norm(), next});
      };
      for (int g = 0; g < goals; ++g) {
        if (goal_regions[g].second == state.second && !struck.count({state.first, g + 1, state.second})) {
          relax({g + 1, state.second}, cost + (goal_position - here).norm());
        }
      }
      const auto portals = portals_by_region_.find(state.second);
      if (portals == portals_by_region_.end()) continue;
      for (std::uint32_t index : portals->second) {
        const Portal& portal = portals_[index];
        const int side = portal.regions[0] == state.second ? 0 : 1;
        if (!allowed[portal.modes[1 - side]]) continue;
        const int node = static_cast<int>(index) + 1 + goals;
        if (node == state.first || struck.count({state.first, node, state.second})) continue;
        const Eigen::Vector3d there = graph.points[portal.point].pose.position;
        relax({node, portal.regions[1 - side]}, cost + (there - here).norm() + request.costs.transition);
      }
    }
    if (reached.first < 0) {
      if (straight_only) {
        plan.routes = kStraightRouteAttempts;  // the loop's increment starts the second phase
        continue;
      }
      break;
    }

    // The route, as legs inside regions and transitions at portals.
    std::vector<State> route = {reached};
    while (route.back() != origin) route.push_back(visits[route.back()].parent);
    std::reverse(route.begin(), route.end());
    std::vector<PlanWaypoint> raw = {{request.start, m0}};
    std::vector<PlanTransition> transitions;
    bool made = true;
    for (std::size_t i = 0; i + 1 < route.size() && made; ++i) {
      const std::int32_t region = route[i].second;
      const int mode = regions[region].mode;
      const Pose from = nodePose(route[i].first), to = nodePose(route[i + 1].first);
      const LegResult leg = walkRegion(from, to, mode, region, plan.sign, request, clearance, straight_only);
      plan.expanded += leg.expanded;
      if (!leg.ok) {
        struck.insert({route[i].first, route[i + 1].first, region});
        made = false;
        break;
      }
      for (const Pose& pose : leg.via) raw.push_back({pose, mode});
      raw.push_back({to, mode});
      if (i + 2 < route.size()) {  // a portal: the same point, left in the other region's mode
        const int new_mode = regions[route[i + 1].second].mode;
        raw.push_back({to, new_mode});
        transitions.push_back(PlanTransition{raw.size() - 1, portals_[route[i + 1].first - 1 - goals].input, mode, new_mode});
      }
    }
    if (!made) continue;

    // Shortcutting, within each stretch of one working mode: from each kept waypoint, the
    // farthest later one a checked straight segment reaches (doubling, then bisection).
    auto valid = [&](std::size_t i, std::size_t j) {
      return checkSegment(raw[i].pose, raw[j].pose, raw[i].mode, plan.sign, clearance) >= 0.0;
    };
    std::vector<std::size_t> boundaries = {0};
    for (const PlanTransition& t : transitions) {
      boundaries.push_back(t.waypoint - 1);
      boundaries.push_back(t.waypoint);
    }
    boundaries.push_back(raw.size() - 1);
    std::vector<std::size_t> kept;
    for (std::size_t b = 0; b + 1 < boundaries.size() && made; b += 2) {
      const std::size_t first = boundaries[b], last = boundaries[b + 1];
      std::size_t i = first;
      kept.push_back(i);
      while (i < last) {
        if (!valid(i, i + 1)) {  // between a pose and its voxel centre, near a singularity
          made = false;
          break;
        }
        std::size_t good = i + 1, span = 2;
        while (i + span <= last && valid(i, i + span)) {
          good = i + span;
          span *= 2;
        }
        std::size_t bad = std::min(i + span, last + 1);
        while (bad - good > 1) {
          const std::size_t middle = (good + bad) / 2;
          (valid(i, middle) ? good : bad) = middle;
        }
        i = good;
        kept.push_back(i);
      }
    }
    if (!made) return fail("a segment of the path found fails its check near " + positionText(raw[kept.back()].pose));
    for (std::size_t k : kept) plan.waypoints.push_back(raw[k]);
    for (const PlanTransition& t : transitions) {
      PlanTransition moved = t;
      moved.waypoint = static_cast<std::size_t>(std::find(kept.begin(), kept.end(), t.waypoint) - kept.begin());
      plan.transitions.push_back(moved);
    }
    plan.min_measure = INFINITY;
    for (std::size_t w = 0; w + 1 < plan.waypoints.size(); ++w) {
      const PlanWaypoint& a = plan.waypoints[w];
      const PlanWaypoint& b = plan.waypoints[w + 1];
      plan.length += (b.pose.position - a.pose.position).norm();
      if (a.mode == b.mode) plan.min_measure = std::min(plan.min_measure, checkSegment(a.pose, b.pose, a.mode, plan.sign, clearance));
    }
    plan.success = true;
    return plan;
  }
  if (request.allowed_modes.size() == 1) {
    return fail("no path in working mode " + m0_name + " alone without crossing a DKP singularity" +
                std::string(request.clearance > 0.0 ? " or coming closer to one than the clearance" : ""));
  }
  return fail("no path without crossing a DKP singularity" +
              std::string(request.clearance > 0.0 ? " or coming closer to one than the clearance" : ""));
}

}  // namespace maximal_workspace
