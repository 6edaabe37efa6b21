#include "maximal_workspace/planner/path_planner.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>
#include <utility>

#include "a_star.h"
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

bool refuse(Plan& plan, std::string message) {
  plan.message = std::move(message);
  return false;
}

// Where a pose is: its cell, and the measures of every working mode at the pose itself.
bool locate(const WorkspaceAnalysis& lookup, const PoseClassifier& classifier, const Pose& pose,
            std::vector<double>& measures, std::uint64_t* cell) {
  if (!lookup.grid().cellOf(pose, cell) || !lookup.inside(*cell)) return false;
  return classifier.classify(pose, measures.data());
}

// The singularity-free region of working mode `mode` at a cell in assembly mode `sign`, or -1.
std::int32_t regionOf(const WorkspaceAnalysis& lookup, std::uint64_t cell, int mode, std::int8_t sign) {
  const std::int32_t label = lookup.label(cell, mode);
  const std::vector<Region>& regions = lookup.regions();
  return label >= 0 && regions[label].sign == sign && !regions[label].debris ? label : -1;
}

std::string noPathMessage(const PlanRequest& request, const std::string& start_mode_name) {
  const std::string clearance = request.clearance > 0.0 ? " or coming closer to one than the clearance" : "";
  if (request.allowed_modes.size() == 1) {
    return "no path in working mode " + start_mode_name + " alone without crossing a DKP singularity" + clearance;
  }
  return "no path without crossing a DKP singularity" + clearance;
}

struct RouteStateHash {
  std::size_t operator()(const std::pair<int, std::int32_t>& state) const {
    return std::hash<std::uint64_t>()(static_cast<std::uint64_t>(static_cast<std::uint32_t>(state.first)) << 32 |
                                      static_cast<std::uint32_t>(state.second));
  }
};

// Calls visit(next cell, move length in steps) for the moves from a cell to its 26 (8 on a
// planar grid) neighbours in `region` of working mode `mode` that cut no corner: every cell
// a diagonal move passes is in the region too.
template <typename Visit>
void forEachRegionMove(const WorkspaceAnalysis& lookup, std::uint64_t from, int mode, std::int32_t region, Visit&& visit) {
  const Grid& grid = lookup.grid();
  const int dims = grid.dims();
  const GridCell cell = grid.cell(from);
  auto inRegion = [&](const int* offset) -> std::int64_t {
    GridCell next = cell;
    for (int d = 0; d < dims; ++d) {
      next[d] += offset[d];
      if (next[d] < 0 || next[d] >= grid.size(d)) return -1;
    }
    const std::uint64_t index = grid.index(next);
    return lookup.label(index, mode) == region ? static_cast<std::int64_t>(index) : -1;
  };
  const int z_reach = dims == 3 ? 1 : 0;
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -z_reach; dz <= z_reach; ++dz) {
        const int move[3] = {dx, dy, dz};
        if (!(dx || dy || dz)) continue;
        const std::int64_t next = inRegion(move);
        if (next < 0) continue;
        bool clear = true;
        for (int subset = 1; subset < 7 && clear; ++subset) {
          const int part[3] = {(subset & 1) ? dx : 0, (subset & 2) ? dy : 0, (subset & 4) ? dz : 0};
          const bool proper = (part[0] || part[1] || part[2]) && !(part[0] == dx && part[1] == dy && part[2] == dz);
          if (proper) clear = inRegion(part) >= 0;
        }
        if (clear) visit(static_cast<std::uint64_t>(next), std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz)));
      }
    }
  }
}

}  // namespace

// A request that passed validation, with what the later stages need of it.
struct PathPlanner::Query {
  explicit Query(const PlanRequest& request) : request(request) {}

  const PlanRequest& request;
  std::vector<bool> allowed;  // working modes the path may use
  double clearance = 0.0;     // the request's, at least the singular band
  std::int8_t sign = 0;       // the assembly mode
  std::int32_t start_region = -1;
  std::vector<std::pair<int, std::int32_t>> goal_regions;  // (working mode, region) the goal may be reached in

  int firstPortalNode() const { return 1 + static_cast<int>(goal_regions.size()); }
};

// The route's waypoints before shortcutting: route nodes and the voxel centres between them.
struct PathPlanner::RawPath {
  std::vector<PlanWaypoint> waypoints;
  std::vector<PlanTransition> transitions;
};

struct PathPlanner::LegResult {
  bool ok = false;
  std::vector<Pose> via;  // voxel centres between from and to (empty: straight)
  std::size_t expanded = 0;
};

PathPlanner::PathPlanner(const RobotModel& model, WorkspaceAnalysis analysis)
    : model_(model),
      constraints_(model),
      analysis_(std::move(analysis)),
      classifier_(model, analysis_.modes(), analysis_.grid().spec().start, analysis_.grid().isSpatial()),
      margin_(analysis_.settings().margin) {
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

double PathPlanner::checkSegment(const Pose& from, const Pose& to, int mode, std::int8_t sign, double clearance,
                                 Pose* smallest_at) const {
  const double spacing = 0.25 * analysis_.grid().step(0);
  const int samples = std::max(1, static_cast<int>(std::ceil((to.position - from.position).norm() / spacing)));
  std::vector<double> measures(analysis_.modes().size());
  double smallest = INFINITY;
  for (int k = 0; k <= samples; ++k) {
    const Pose pose = lerp(from, to, static_cast<double>(k) / samples);
    if (!classifier_.classify(pose, measures.data())) return -1.0;
    const double measure = measures[mode];
    if (bandedSign(measure, margin_) != sign || std::abs(measure) < clearance) return -1.0;
    if (std::abs(measure) < smallest && smallest_at != nullptr) *smallest_at = pose;
    smallest = std::min(smallest, std::abs(measure));
  }
  return smallest;
}

Plan PathPlanner::plan(const PlanRequest& request) const {
  Plan plan;
  Query query(request);
  if (!validate(query, plan)) return plan;
  RawPath path;
  if (!findPath(query, path, plan)) {
    plan.message = noPathMessage(request, analysis_.modes()[request.start_mode].name);
    return plan;
  }
  if (!shortcut(query, path, plan)) return plan;
  measure(query, plan);
  plan.success = true;
  return plan;
}

bool PathPlanner::validate(Query& query, Plan& plan) const {
  const PlanRequest& request = query.request;
  const int mode_count = static_cast<int>(analysis_.modes().size());
  if (!analysis_.grid().isSpatial()) {
    return refuse(plan, "the planner needs a workspace over x y z (or x y for a planar robot)");
  }
  if (request.start_mode < 0 || request.start_mode >= mode_count) return refuse(plan, "unknown start working mode");
  query.allowed.assign(mode_count, request.allowed_modes.empty());
  for (int m : request.allowed_modes) {
    if (m >= 0 && m < mode_count) query.allowed[m] = true;
  }
  if (!query.allowed[request.start_mode]) return refuse(plan, "the start working mode is not among the allowed ones");
  query.clearance = std::max(request.clearance, margin_);
  std::vector<double> start_measures(mode_count), goal_measures(mode_count);
  std::uint64_t start_cell = 0, goal_cell = 0;
  if (!locate(analysis_, classifier_, request.start, start_measures, &start_cell)) {
    const std::string limits = limitReasons(query, request.start, request.start_mode);
    return refuse(plan, "the start " + positionText(request.start) + " is outside the workspace" +
                            (limits.empty() ? "" : ": it " + limits));
  }
  if (!locate(analysis_, classifier_, request.goal, goal_measures, &goal_cell)) {
    const std::string limits = limitReasons(query, request.goal, request.goal_mode);
    return refuse(plan, "the goal " + positionText(request.goal) + " is outside the workspace" +
                            (limits.empty() ? "" : ": it " + limits));
  }
  return validateStart(query, start_measures, start_cell, plan) && validateGoal(query, goal_measures, goal_cell, plan);
}

// The start fixes the assembly mode, and must be clear of DKP singularities, in a region.
bool PathPlanner::validateStart(Query& query, const std::vector<double>& measures, std::uint64_t cell,
                                Plan& plan) const {
  const int mode = query.request.start_mode;
  const std::string& name = analysis_.modes()[mode].name;
  const double measure = std::abs(measures[mode]);
  if (!modeAdmissible(measures[mode])) return refuse(plan, "the start " + limitReasons(query, query.request.start, mode));
  query.sign = plan.sign = bandedSign(measures[mode], margin_);
  if (query.sign == 0) {
    return refuse(plan, "the start is on a DKP singularity of working mode " + name + " (|measure| " +
                            numberText(measure) + " < " + numberText(std::max(margin_, kMeasureTolerance)) + ")");
  }
  if (measure < query.clearance) {
    return refuse(plan, "the start is closer to a DKP singularity of working mode " + name +
                            " than the clearance (|measure| " + numberText(measure) + " < " +
                            numberText(query.clearance) + ")");
  }
  query.start_region = regionOf(analysis_, cell, mode, query.sign);
  if (query.start_region < 0) {
    return refuse(plan, "the start is too close to a DKP singularity of working mode " + name +
                            ": its voxel is not in a singularity-free region of that working mode");
  }
  return true;
}

// The goal's regions, one per working mode it may be reached in, or why there are none;
// and one of them must be joined to the start's region.
bool PathPlanner::validateGoal(Query& query, const std::vector<double>& measures, std::uint64_t cell,
                               Plan& plan) const {
  const int goal_mode = query.request.goal_mode;
  bool other_assembly_mode = false;
  for (int m = 0; m < static_cast<int>(measures.size()); ++m) {
    if (!query.allowed[m] || (goal_mode >= 0 && m != goal_mode)) continue;
    const std::int8_t sign = bandedSign(measures[m], margin_);
    other_assembly_mode = other_assembly_mode || sign == -query.sign;
    const std::int32_t region = regionOf(analysis_, cell, m, query.sign);
    if (region >= 0 && sign == query.sign && std::abs(measures[m]) >= query.clearance) {
      query.goal_regions.push_back({m, region});
    }
  }
  if (query.goal_regions.empty()) {
    const std::string limits = limitReasons(query, query.request.goal, goal_mode);
    if (!limits.empty()) return refuse(plan, "the goal " + limits);
    if (other_assembly_mode) {
      return refuse(plan, std::string("the goal is only in the other assembly mode (") + signChar(-query.sign) +
                              ") of the working modes allowed: reaching it requires crossing a DKP singularity");
    }
    return refuse(plan, "the goal is on or too close to a DKP singularity in every working mode allowed");
  }
  const std::vector<std::int32_t>& component = analysis_.transitions().component;
  if (std::none_of(query.goal_regions.begin(), query.goal_regions.end(),
                   [&](const auto& goal) { return component[goal.second] == component[query.start_region]; })) {
    return refuse(plan, "no path without crossing a DKP singularity: the goal's regions are not joined to the start's "
                        "by IKP-singularity transitions");
  }
  return true;
}

std::string PathPlanner::limitReasons(const Query& query, const Pose& pose, int only_mode) const {
  if (!constraints_.active()) return {};
  std::string reasons;
  int broken = 0;
  const IkpResult ikp = solveIkp(model_, pose);
  if (!ikp.assembled) return {};
  for (int m = 0; m < static_cast<int>(analysis_.modes().size()); ++m) {
    if (!query.allowed[m] || (only_mode >= 0 && m != only_mode)) continue;
    const WorkingMode& mode = analysis_.modes()[m];
    const std::string why = constraints_.violationText(pose, ikp, mode);
    if (why.empty()) return {};
    // The first few reasons say enough.
    if (++broken <= 3) reasons += (reasons.empty() ? "" : "; ") + mode.name + ": " + why;
  }
  if (broken == 0) return {};
  if (broken > 3) reasons += "; ...";
  return std::string(only_mode >= 0 ? "breaks a limit of the robot in working mode " + analysis_.modes()[only_mode].name
                                    : "breaks a limit of the robot in every working mode allowed") +
         " (" + reasons + ")";
}

// Routes, and their legs made: a leg that cannot be made is struck and the route searched
// again. Routes whose legs are all straight come first (cheap to check, many portals to
// choose from); only when none is left, legs searched voxel by voxel. False when no route
// could be made.
bool PathPlanner::findPath(const Query& query, RawPath& path, Plan& plan) const {
  StruckLegs struck;
  for (plan.routes = 1; plan.routes <= kStraightRouteAttempts + kRouteAttempts; ++plan.routes) {
    const bool straight_only = plan.routes <= kStraightRouteAttempts;
    if (plan.routes == kStraightRouteAttempts + 1) struck.clear();
    const std::vector<RouteState> states = route(query, struck);
    if (states.empty()) {
      if (!straight_only) return false;
      plan.routes = kStraightRouteAttempts;  // the loop's increment starts the second phase
      continue;
    }
    if (realiseLegs(query, states, straight_only, struck, path, plan.expanded)) return true;
  }
  return false;
}

// The cheapest route from the start to a goal node over legs not struck: a leg joins two
// nodes of one region and costs their distance, plus the transition cost into a portal
// (which leaves the robot in the portal's other region). Empty when there is none.
std::vector<PathPlanner::RouteState> PathPlanner::route(const Query& query, const StruckLegs& struck) const {
  const TransitionGraph& graph = analysis_.transitions();
  const Eigen::Vector3d& goal = query.request.goal.position;
  const int goals = static_cast<int>(query.goal_regions.size());
  auto neighbours = [&](const RouteState& state, auto&& relax) {
    const int node = state.first;
    const std::int32_t region = state.second;
    const Eigen::Vector3d here = nodePose(query, node).position;
    for (int g = 0; g < goals; ++g) {
      if (query.goal_regions[g].second == region && !struck.count({node, g + 1, region})) {
        relax(RouteState{g + 1, region}, (goal - here).norm());
      }
    }
    const auto portals = portals_by_region_.find(region);
    if (portals == portals_by_region_.end()) return;
    for (std::uint32_t index : portals->second) {
      const Portal& portal = portals_[index];
      const int side = portal.regions[0] == region ? 0 : 1;
      if (!query.allowed[portal.modes[1 - side]]) continue;
      const int next = static_cast<int>(index) + query.firstPortalNode();
      if (next == node || struck.count({node, next, region})) continue;
      const Eigen::Vector3d& there = graph.points[portal.point].pose.position;
      relax(RouteState{next, portal.regions[1 - side]}, (there - here).norm() + query.request.costs.transition);
    }
  };
  auto heuristic = [&](const RouteState& state) { return (nodePose(query, state.first).position - goal).norm(); };
  auto atGoal = [goals](const RouteState& state) { return state.first >= 1 && state.first <= goals; };
  return aStar<RouteState, RouteStateHash>(RouteState{0, query.start_region}, neighbours, heuristic, atGoal).path;
}

// The route's legs inside their regions, and its working-mode changes at portals. A leg that
// cannot be made is struck, and the route fails.
bool PathPlanner::realiseLegs(const Query& query, const std::vector<RouteState>& route, bool straight_only,
                              StruckLegs& struck, RawPath& path, std::size_t& expanded) const {
  const std::vector<Region>& regions = analysis_.regions();
  path.waypoints = {{query.request.start, query.request.start_mode}};
  path.transitions.clear();
  for (std::size_t i = 0; i + 1 < route.size(); ++i) {
    const std::int32_t region = route[i].second;
    const int mode = regions[region].mode;
    const Pose to = nodePose(query, route[i + 1].first);
    const LegResult leg = walkRegion(query, nodePose(query, route[i].first), to, region, straight_only);
    expanded += leg.expanded;
    if (!leg.ok) {
      struck.insert({route[i].first, route[i + 1].first, region});
      return false;
    }
    for (const Pose& pose : leg.via) path.waypoints.push_back({pose, mode});
    path.waypoints.push_back({to, mode});
    if (i + 2 < route.size()) {  // a portal: the same point, left in the other region's mode
      const int new_mode = regions[route[i + 1].second].mode;
      path.waypoints.push_back({to, new_mode});
      path.transitions.push_back(
          PlanTransition{path.waypoints.size() - 1, portalAt(query, route[i + 1].first).input, mode, new_mode});
    }
  }
  return true;
}

// Shortcutting, within each stretch of one working mode (transitions stay where they are).
bool PathPlanner::shortcut(const Query& query, const RawPath& path, Plan& plan) const {
  const std::vector<PlanWaypoint>& raw = path.waypoints;
  std::vector<std::size_t> boundaries = {0};  // first and last waypoint of each stretch
  for (const PlanTransition& t : path.transitions) {
    boundaries.push_back(t.waypoint - 1);
    boundaries.push_back(t.waypoint);
  }
  boundaries.push_back(raw.size() - 1);
  std::vector<std::size_t> kept;
  for (std::size_t b = 0; b + 1 < boundaries.size(); b += 2) {
    if (!shortcutStretch(query, raw, boundaries[b], boundaries[b + 1], kept)) {
      return refuse(plan, "a segment of the path found fails its check near " + positionText(raw[kept.back()].pose));
    }
  }
  for (std::size_t k : kept) plan.waypoints.push_back(raw[k]);
  for (const PlanTransition& t : path.transitions) {
    PlanTransition moved = t;
    moved.waypoint = static_cast<std::size_t>(std::find(kept.begin(), kept.end(), t.waypoint) - kept.begin());
    plan.transitions.push_back(moved);
  }
  return true;
}

// Appends to `kept` the waypoints kept of raw[first..last]: from each, the farthest later one
// a checked straight segment reaches (doubling, then bisection). False when not even the
// next one is reached (between a pose and its voxel centre, near a singularity).
bool PathPlanner::shortcutStretch(const Query& query, const std::vector<PlanWaypoint>& raw, std::size_t first,
                                  std::size_t last, std::vector<std::size_t>& kept) const {
  auto reaches = [&](std::size_t i, std::size_t j) {
    return checkSegment(raw[i].pose, raw[j].pose, raw[i].mode, query.sign, query.clearance) >= 0.0;
  };
  std::size_t i = first;
  kept.push_back(i);
  while (i < last) {
    if (!reaches(i, i + 1)) return false;
    std::size_t good = i + 1, span = 2;
    while (i + span <= last && reaches(i, i + span)) {
      good = i + span;
      span *= 2;
    }
    std::size_t bad = std::min(i + span, last + 1);
    while (bad - good > 1) {
      const std::size_t middle = (good + bad) / 2;
      (reaches(i, middle) ? good : bad) = middle;
    }
    i = good;
    kept.push_back(i);
  }
  return true;
}

// The plan's length, and the smallest |measure| on its segments (those within one working mode).
void PathPlanner::measure(const Query& query, Plan& plan) const {
  plan.min_measure = INFINITY;
  for (std::size_t w = 0; w + 1 < plan.waypoints.size(); ++w) {
    const PlanWaypoint& a = plan.waypoints[w];
    const PlanWaypoint& b = plan.waypoints[w + 1];
    plan.length += (b.pose.position - a.pose.position).norm();
    if (a.mode != b.mode) continue;
    Pose at;
    const double smallest = checkSegment(a.pose, b.pose, a.mode, query.sign, query.clearance, &at);
    if (smallest < plan.min_measure) plan.min_measure = smallest, plan.min_measure_at = at;
  }
}

Pose PathPlanner::nodePose(const Query& query, int node) const {
  if (node == 0) return query.request.start;
  if (node < query.firstPortalNode()) return query.request.goal;
  return analysis_.transitions().points[portalAt(query, node).point].pose;
}

const PathPlanner::Portal& PathPlanner::portalAt(const Query& query, int node) const {
  return portals_[node - query.firstPortalNode()];
}

PathPlanner::LegResult PathPlanner::walkRegion(const Query& query, const Pose& from, const Pose& to,
                                               std::int32_t region, bool straight_only) const {
  if (checkSegment(from, to, analysis_.regions()[region].mode, query.sign, query.clearance) >= 0.0) {
    LegResult straight;
    straight.ok = true;
    return straight;
  }
  return straight_only ? LegResult() : searchRegion(query, from, to, region);
}

// A* over the region's voxels, each metre costing more near DKP singularities.
PathPlanner::LegResult PathPlanner::searchRegion(const Query& query, const Pose& from, const Pose& to,
                                                 std::int32_t region) const {
  LegResult result;
  const Grid& grid = analysis_.grid();
  std::uint64_t start = 0, goal = 0;  // cells
  if (!grid.cellOf(from, &start) || !grid.cellOf(to, &goal) || !analysis_.inside(start) || !analysis_.inside(goal)) {
    return result;
  }
  const int mode = analysis_.regions()[region].mode;
  const PlannerCosts& costs = query.request.costs;
  const bool penalise = costs.clearance_weight > 0.0 && costs.clearance_soft > 0.0;
  std::vector<double> measures(analysis_.modes().size());
  std::unordered_map<std::uint64_t, double> weights;  // a cell is a neighbour many times: classify it once
  // Cost per metre in a cell; < 0: not allowed there.
  auto weight = [&](std::uint64_t cell) -> double {
    if (!penalise && query.clearance <= margin_) return 1.0;
    const auto known = weights.find(cell);
    if (known != weights.end()) return known->second;
    classifier_.classify(grid.pose(cell), measures.data());
    const double measure = std::abs(measures[mode]);
    const double w =
        measure < query.clearance
            ? -1.0
            : 1.0 + (penalise ? costs.clearance_weight * std::max(0.0, 1.0 - measure / costs.clearance_soft) : 0.0);
    weights.emplace(cell, w);
    return w;
  };
  auto centre = [&](std::uint64_t cell) { return grid.pose(cell).position; };
  const Eigen::Vector3d target = centre(goal);
  const double step = grid.step(0);
  auto neighbours = [&](std::uint64_t cell, auto&& relax) {
    forEachRegionMove(analysis_, cell, mode, region, [&](std::uint64_t next, double length) {
      const double w = weight(next);
      if (w >= 0.0) relax(next, w * step * length);
    });
  };
  auto heuristic = [&](std::uint64_t cell) { return query.request.heuristic_weight * (centre(cell) - target).norm(); };
  const AStarResult<std::uint64_t> found =
      aStar(start, neighbours, heuristic, [goal](std::uint64_t cell) { return cell == goal; }, kExpansionLimit);
  result.expanded = found.expanded;
  result.ok = !found.path.empty();
  for (std::uint64_t cell : found.path) {
    Pose pose = from;
    pose.position = centre(cell);
    result.via.push_back(pose);
  }
  return result;
}

}  // namespace maximal_workspace
