#include "maximal_workspace/planner/path_planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>

#include "a_star.h"
#include "maximal_workspace/model/vector_text.h"
#include "planner_metric.h"
#include "region_search.h"

namespace maximal_workspace {

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::size_t kPortalsPerTransition = 16;
// Walks of one leg: a walk whose step between two cell centres fails its check (a sign
// flip between them) is searched again without that step.
constexpr int kWalkAttempts = 8;
// A leg made is kept in its route while it costs at most this much more than estimated:
// re-routing for less would make many walks through a curved region for little gain.
constexpr double kAcceptedDetour = 1.25;
// Where two samples of a segment differ by more than this times the smaller |measure|,
// the measure changes fast enough there to dip to zero and back between them (a thin
// singular layer): the interval is halved, down to kFinestCheck m.
constexpr double kRefineRatio = 1.0;
constexpr double kFinestCheck = 1e-5;

// Halves [t0, t1] while its ends' |measure| m0, m1 could hide a dip between them; false
// when a sample fails. `measureAt` gives NaN where it fails.
template <typename MeasureAt>
bool refinedHolds(MeasureAt& measureAt, double t0, double m0, double t1, double m1, double length) {
  if (std::min(m0, m1) >= kRefineRatio * std::abs(m1 - m0) || (t1 - t0) * length <= kFinestCheck) return true;
  const double t = 0.5 * (t0 + t1);
  const double m = measureAt(t);
  return !std::isnan(m) && refinedHolds(measureAt, t0, m0, t, m, length) && refinedHolds(measureAt, t, m, t1, m1, length);
}

// Samples of the segment from a transition point to its cell's centre (the trajectory's
// own count).
constexpr int kAnchorSamples = 64;

// Fractions of a segment from either end also checked (PathPlanner::checkSegment).
constexpr double kEndSamples[] = {1e-6, 1e-3};

std::string positionText(const Pose& pose) { return vectorText(pose.position); }

char signChar(std::int8_t sign) { return sign > 0 ? '+' : '-'; }

// Empty when the pose keeps every variable the grid does not vary at the grid's value;
// else which one differs. The planner moves only along the grid's variables.
std::string offGrid(const Grid& grid, const Pose& pose) {
  const std::vector<OutputVariable>& varied = grid.spec().variables;
  for (int v = 0; v < kOutputVariableCount; ++v) {
    const auto variable = static_cast<OutputVariable>(v);
    if (std::find(varied.begin(), varied.end(), variable) != varied.end()) continue;
    const double fixed = grid.spec().start.value(variable), value = pose.value(variable);
    if (std::abs(value - fixed) <= 1e-9) continue;
    std::string names;
    for (OutputVariable g : varied) names += std::string(names.empty() ? "" : " ") + outputVariableName(g);
    return std::string(outputVariableName(variable)) + " is " + numberText(value) + " but the analysis fixes it at " +
           numberText(fixed) + " (it varies " + names + " only)";
  }
  return "";
}

// Up to `count` of `points`, spread out: farthest-point sampling from the first.
std::vector<std::uint32_t> spreadOut(const std::vector<std::uint32_t>& points, const std::vector<TransitionPoint>& all,
                                     std::size_t count) {
  if (points.size() <= count) return points;
  std::vector<std::uint32_t> chosen = {points.front()};
  std::vector<double> distance(points.size(), INFINITY);
  while (chosen.size() < count) {
    const Eigen::Vector3d& last = all[chosen.back()].position;
    std::size_t farthest = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      distance[i] = std::min(distance[i], (all[points[i]].position - last).norm());
      if (distance[i] > distance[farthest]) farthest = i;
    }
    chosen.push_back(points[farthest]);
  }
  return chosen;
}

bool refuse(Plan& plan, PlanRefusal refusal, std::string message) {
  plan.refusal = refusal;
  plan.message = std::move(message);
  return false;
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

}  // namespace

// A leg made: its cost (infinite when it cannot be made) and the cell centres between its
// ends (none: straight).
struct PathPlanner::Leg {
  bool ok = false;
  double cost = INFINITY;
  std::vector<Pose> via;
  std::size_t expanded = 0;
};

// A request that passed validation, with what the later stages need of it.
struct PathPlanner::Query {
  explicit Query(const PlanRequest& request)
      : request(request),
        deadline(Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(std::min(request.time_limit, 1e6)))) {}

  const PlanRequest& request;
  std::vector<bool> allowed;  // working modes the path may use
  double clearance = 0.0;     // the request's, at least the analysis's margin
  std::int8_t sign = 0;       // the assembly mode
  Anchor start;
  std::int32_t start_group = -1;  // the start region's component
  std::vector<Anchor> goals;  // one per region of the start's group the goal may be reached in
  int goal_anchors = 0;       // the goal's regions of the start's sign, of any group
  Clock::time_point deadline;
  std::map<LegKey, Leg> legs;  // made so far
  BlockedMoves blocked;        // walk steps whose segment failed its check
  // Regions found split by a layer the analysis does not resolve: per walk that found no
  // way, the cells its start reached (sorted).
  std::vector<std::pair<std::int32_t, std::vector<std::uint64_t>>> splits;
  std::int64_t broken_from = -1, broken_to = -1;  // the first face found failing its check
  double avoid_radius = 0.0;  // a tenth of the smallest step length
  // Per region, the smallest ratio of a walk's length to the distance between its ends:
  // legs not made yet are estimated that much longer than their distance.
  std::unordered_map<std::int32_t, double> detour;

  double estimate(double distance, std::int32_t region) const {
    const auto found = detour.find(region);
    return found == detour.end() ? distance : distance * found->second;
  }
  int firstPortalNode() const { return 1 + static_cast<int>(goals.size()); }
  bool expired() const { return Clock::now() >= deadline; }
};

// The route's waypoints before shortcutting: route nodes and the cell centres between them.
struct PathPlanner::RawPath {
  std::vector<PlanWaypoint> waypoints;
  std::vector<PlanTransition> transitions;
};

PathPlanner::PathPlanner(const RobotModel& model, WorkspaceAnalysis analysis)
    : model_(model),
      constraints_(model),
      analysis_(std::move(analysis)),
      classifier_(model, analysis_.modes(), analysis_.grid().spec().start, analysis_.grid().isSpatial()),
      metric_(std::make_unique<PlannerMetric>(analysis_.grid(), model.characteristic_length)),
      region_search_(std::make_unique<RegionSearch>(analysis_, *metric_, classifier_)),
      margin_(analysis_.settings().margin) {
  const std::vector<Region>& regions = analysis_.regions();
  const TransitionGraph& graph = analysis_.transitions();
  for (const Transition& transition : graph.transitions) {
    const Region& from = regions[transition.from_region];
    const Region& to = regions[transition.to_region];
    if (from.debris || to.debris) continue;
    for (std::uint32_t p : spreadOut(transition.points, graph.points, kPortalsPerTransition)) {
      Portal portal{p,
                    {static_cast<std::int32_t>(transition.from_region), static_cast<std::int32_t>(transition.to_region)},
                    {from.mode, to.mode},
                    {0, 0},
                    transition.input};
      // A point whose segment to a cell of either region fails its check is no portal.
      bool anchored = true;
      for (int side = 0; side < 2 && anchored; ++side) {
        const std::vector<Anchor> found =
            anchors(graph.pose(p), portal.modes[side], transition.sign, portal.regions[side], graph.points[p].cell);
        anchored = !found.empty();
        if (anchored) portal.cells[side] = found.front().cell;
      }
      if (!anchored) continue;
      const std::uint32_t index = static_cast<std::uint32_t>(portals_.size());
      portals_.push_back(portal);
      portals_by_region_[transition.from_region].push_back(index);
      portals_by_region_[transition.to_region].push_back(index);
    }
  }
}

PathPlanner::~PathPlanner() = default;

double PathPlanner::checkSegment(const Pose& from, const Pose& to, int mode, std::int8_t sign, double clearance,
                                 Pose* smallest_at, int min_samples) const {
  double spacing = INFINITY;
  for (int d = 0; d < analysis_.grid().dims(); ++d) spacing = std::min(spacing, 0.25 * metric_->stepLength(d));
  const double length = metric_->distance(from, to);
  const int samples = std::max(min_samples, static_cast<int>(std::ceil(length / spacing)));
  std::vector<double> measures(analysis_.modes().size());
  double smallest = INFINITY;
  const Pose end = metric_->nearestTurn(from, to);
  // The measure at fraction t of the segment, NaN where it fails (not assembled, a limit
  // broken, the other sign, under the clearance).
  auto measureAt = [&](double t) -> double {
    const Pose pose = PlannerMetric::along(from, end, t);
    if (!classifier_.classify(pose, measures.data())) return NAN;
    const double measure = measures[mode];
    if (bandedSign(measure, 0.0) != sign || std::abs(measure) < clearance) return NAN;
    if (std::abs(measure) < smallest && smallest_at != nullptr) *smallest_at = pose;
    smallest = std::min(smallest, std::abs(measure));
    return std::abs(measure);
  };
  // Close to each end too: from a transition point, on the IKP boundary, a segment that
  // leaves the workspace at once would pass between the regular samples (the trajectory
  // starts and ends each segment with tiny steps).
  for (const double t : kEndSamples) {
    if (std::isnan(measureAt(t)) || std::isnan(measureAt(1.0 - t))) return -1.0;
  }
  double previous = measureAt(0.0);
  if (std::isnan(previous)) return -1.0;
  for (int k = 1; k <= samples; ++k) {
    const double t0 = static_cast<double>(k - 1) / samples, t1 = static_cast<double>(k) / samples;
    const double next = measureAt(t1);
    if (std::isnan(next) || !refinedHolds(measureAt, t0, previous, t1, next, length)) return -1.0;
    previous = next;
  }
  return smallest;
}

Plan PathPlanner::plan(const PlanRequest& request) const {
  const Clock::time_point started = Clock::now();
  Plan plan;
  Query query(request);
  RawPath path;
  if (validate(query, plan) && findPath(query, path, plan)) {
    shortcut(query, path, plan);
    measure(query, plan);
    plan.success = true;
  }
  plan.seconds = std::chrono::duration<double>(Clock::now() - started).count();
  return plan;
}

bool PathPlanner::validate(Query& query, Plan& plan) const {
  const PlanRequest& request = query.request;
  const int mode_count = static_cast<int>(analysis_.modes().size());
  if (request.start_mode < 0 || request.start_mode >= mode_count) {
    return refuse(plan, PlanRefusal::Request, "unknown start working mode");
  }
  query.allowed.assign(mode_count, request.allowed_modes.empty());
  for (int m : request.allowed_modes) {
    if (m >= 0 && m < mode_count) query.allowed[m] = true;
  }
  if (!query.allowed[request.start_mode]) {
    return refuse(plan, PlanRefusal::Request, "the start working mode is not among the allowed ones");
  }
  if (!(request.time_limit > 0.0)) return refuse(plan, PlanRefusal::Request, "the time limit must be > 0 s");
  if (!(request.clearance >= 0.0 && request.clearance < 1.0)) {
    return refuse(plan, PlanRefusal::Request, "the clearance must be in [0, 1)");
  }
  // The planner is complete relative to its analysis only when the analysis's regions
  // are the cells the clearance allows.
  if (request.clearance > margin_ * (1.0 + 1e-9)) {
    return refuse(plan, PlanRefusal::Request,
                  "the clearance " + numberText(request.clearance) + " is above the margin of the analysis planned on (" +
                      numberText(margin_) + "): plan on the analysis at margin " + numberText(request.clearance));
  }
  query.clearance = std::max(request.clearance, margin_);
  for (const auto& [what, pose] : {std::pair<const char*, const Pose&>{"start", request.start}, {"goal", request.goal}}) {
    const std::string off = offGrid(analysis_.grid(), pose);
    if (!off.empty()) return refuse(plan, PlanRefusal::Request, std::string("the ") + what + "'s " + off);
  }
  query.avoid_radius = INFINITY;
  for (int d = 0; d < analysis_.grid().dims(); ++d) query.avoid_radius = std::min(query.avoid_radius, 0.1 * metric_->stepLength(d));
  std::vector<double> start_measures(mode_count), goal_measures(mode_count);
  if (!classifier_.classify(request.start, start_measures.data())) {
    return refuse(plan, PlanRefusal::Start, "the start " + positionText(request.start) + " is outside the workspace");
  }
  if (!validateStart(query, start_measures, plan)) return false;
  if (!classifier_.classify(request.goal, goal_measures.data())) {
    return refuse(plan, PlanRefusal::GoalOutside, "the goal " + positionText(request.goal) + " is outside the workspace");
  }
  return validateGoal(query, goal_measures, plan);
}

// The start fixes the assembly mode, and must be clear of DKP singularities, in a region.
bool PathPlanner::validateStart(Query& query, const std::vector<double>& measures, Plan& plan) const {
  const int mode = query.request.start_mode;
  const std::string& name = analysis_.modes()[mode].name;
  const double measure = std::abs(measures[mode]);
  if (!modeAdmissible(measures[mode])) {
    return refuse(plan, PlanRefusal::Start, "the start " + limitReasons(query, query.request.start, mode));
  }
  query.sign = plan.sign = bandedSign(measures[mode], 0.0);
  if (query.sign == 0) {
    return refuse(plan, PlanRefusal::Start,
                  "the start is on a DKP singularity of working mode " + name + " (|measure| " + numberText(measure) +
                      " < " + numberText(kMeasureTolerance) + ")");
  }
  if (measure < query.clearance) {
    return refuse(plan, PlanRefusal::Start,
                  "the start is closer to a DKP singularity of working mode " + name + " than the clearance (|measure| " +
                      numberText(measure) + " < " + numberText(query.clearance) + ")");
  }
  const std::vector<Anchor> found = anchors(query.request.start, mode, query.sign);
  if (found.empty()) {
    return refuse(plan, PlanRefusal::Start,
                  "the start " + positionText(query.request.start) + " is in no region of working mode " + name +
                      " at the clearance: neither its voxel nor those around it are");
  }
  query.start = found.front();
  query.start_group = analysis_.transitions().component[query.start.region];
  return true;
}

// The goal's regions, one per working mode it may be reached in and region it reaches, of
// the start's group; or why there are none.
bool PathPlanner::validateGoal(Query& query, const std::vector<double>& measures, Plan& plan) const {
  const int goal_mode = query.request.goal_mode;
  const std::vector<std::int32_t>& component = analysis_.transitions().component;
  for (int m = 0; m < static_cast<int>(measures.size()); ++m) {
    if (!query.allowed[m] || (goal_mode >= 0 && m != goal_mode) || bandedSign(measures[m], 0.0) != query.sign) continue;
    plan.goal_measure = std::max(plan.goal_measure, std::abs(measures[m]));
    if (std::abs(measures[m]) < query.clearance) continue;
    for (const Anchor& anchor : anchors(query.request.goal, m, query.sign)) {
      ++query.goal_anchors;
      if (component[anchor.region] == query.start_group) query.goals.push_back(anchor);
    }
  }
  return !query.goals.empty() || refuseGoal(query, measures, plan);
}

bool PathPlanner::refuseGoal(const Query& query, const std::vector<double>& measures, Plan& plan) const {
  const int goal_mode = query.request.goal_mode;
  const std::string limits = limitReasons(query, query.request.goal, goal_mode);
  if (!limits.empty()) {
    return refuse(plan, PlanRefusal::GoalOutside,
                  "the goal " + positionText(query.request.goal) + " is outside the workspace: it " + limits);
  }
  bool same_sign = false, other_sign = false;
  for (int m = 0; m < static_cast<int>(measures.size()); ++m) {
    if (!query.allowed[m] || (goal_mode >= 0 && m != goal_mode)) continue;
    same_sign = same_sign || bandedSign(measures[m], 0.0) == query.sign;
    other_sign = other_sign || bandedSign(measures[m], 0.0) == -query.sign;
  }
  if (!same_sign && other_sign) {
    return refuse(plan, PlanRefusal::GoalOtherAssemblyMode,
                  std::string("the goal is only in the other assembly mode (") + signChar(-query.sign) +
                      ") of the working modes allowed: reaching it requires crossing a DKP singularity");
  }
  if (plan.goal_measure < query.clearance) {
    return refuse(plan, PlanRefusal::GoalClearance,
                  "the goal is closer to a DKP singularity than the clearance in every working mode allowed (its largest "
                  "|measure| " + numberText(plan.goal_measure) + " < " + numberText(query.clearance) + ")");
  }
  std::uint64_t cell = 0;
  if (!analysis_.grid().cellOf(query.request.goal, &cell) || !analysis_.inside(cell)) {
    return refuse(plan, PlanRefusal::GoalOutside,
                  "the goal " + positionText(query.request.goal) + " is outside the workspace the analysis covers");
  }
  if (query.goal_anchors == 0) {
    return refuse(plan, PlanRefusal::GoalClearance,
                  "the goal is in no region of the working modes allowed at the clearance " +
                      numberText(query.clearance) + ": its voxel and those around it are closer to a DKP singularity");
  }
  return refuse(plan, PlanRefusal::NotJoined,
                noPathMessage(query.request, analysis_.modes()[query.request.start_mode].name) +
                    ": the goal's regions are not joined to the start's by IKP-singularity transitions");
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

std::vector<PathPlanner::Anchor> PathPlanner::anchors(const Pose& pose, int mode, std::int8_t sign,
                                                      std::int32_t only_region, std::int64_t own_cell) const {
  const Grid& grid = analysis_.grid();
  std::uint64_t own = static_cast<std::uint64_t>(own_cell);
  if (own_cell < 0 && !grid.cellOf(pose, &own)) return {};
  // The pose's own cell first, then the nearest around it.
  std::vector<std::pair<double, std::uint64_t>> candidates;
  const CellsAround around = cellsAround(grid, own);
  for (int k = 0; k < around.count; ++k) {
    const std::int64_t cell = around.cells[k];
    if (cell < 0) continue;
    const auto at = static_cast<std::uint64_t>(cell);
    candidates.push_back({at == own ? -1.0 : metric_->distance(pose, grid.pose(at)), at});
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<Anchor> found;
  for (const auto& [distance, cell] : candidates) {
    const std::int32_t region = regionOf(analysis_, cell, mode, sign);
    if (region < 0 || (only_region >= 0 && region != only_region)) continue;
    if (std::any_of(found.begin(), found.end(), [region](const Anchor& a) { return a.region == region; })) continue;
    // Between a pose and its cell's centre, as between neighbouring cells, the sign alone
    // (docs/planner.md); densely from a transition point (own_cell given), as there the
    // measure changes like the square root of the distance to it.
    const int samples = own_cell >= 0 ? kAnchorSamples : 1;
    if (checkSegment(pose, grid.pose(cell), mode, sign, 0.0, nullptr, samples) < 0.0) continue;
    found.push_back(Anchor{mode, region, cell});
    if (only_region >= 0) break;
  }
  return found;
}

// The cheapest route over legs not known to fail, searched again while a leg it uses
// turns out dearer than its estimate (lazy evaluation: every leg is made at most once, so
// the search ends). Bounded by the time budget.
bool PathPlanner::findPath(Query& query, RawPath& path, Plan& plan) const {
  for (;;) {
    if (query.expired()) {
      return refuse(plan, PlanRefusal::TimeLimit,
                    "the time limit of " + numberText(query.request.time_limit) + " s ran out after " +
                        std::to_string(plan.routes) + " routes and " +
                        std::to_string(plan.legs) + " legs made (" + std::to_string(plan.expanded) +
                        " cells walked); the goal's regions are joined to the start's: a larger time limit may plan");
    }
    const std::vector<RouteState> states = route(query);
    ++plan.routes;
    if (states.empty()) {
      return refuse(plan, query.broken_from >= 0 ? PlanRefusal::Unresolved : PlanRefusal::NoPath, unresolvedMessage(query));
    }
    if (settleLegs(query, states, plan)) {
      assemble(query, states, path);
      return true;
    }
  }
}

// Why no route could be made although the analysis joins the goal's regions to the start's.
std::string PathPlanner::unresolvedMessage(const Query& query) const {
  std::string message = "no path keeps the sign of det J_DKP although the analysis joins the goal's regions to the start's";
  if (query.broken_from < 0) return message + ": no leg of the routes between them could be made";
  const Grid& grid = analysis_.grid();
  return message + ": between cells it puts in one region lies a DKP singularity (or the workspace's edge) thinner "
                   "than the step " + numberText(grid.step(0)) + ", first met between " +
         positionText(grid.pose(static_cast<std::uint64_t>(query.broken_from))) + " and " +
         positionText(grid.pose(static_cast<std::uint64_t>(query.broken_to))) + "; a finer step may plan";
}

// The cheapest route from the start to a goal node: a leg joins two nodes of one region
// and costs what it cost when made, or before that their distance; entering a portal adds
// the transition cost (and leaves the robot in the portal's other region). Empty when there
// is none.
std::vector<PathPlanner::RouteState> PathPlanner::route(const Query& query) const {
  const Pose goal = query.request.goal;
  const int goals = static_cast<int>(query.goals.size());
  auto legCost = [&](int from, int to, std::int32_t region, double distance) {
    const auto made = query.legs.find(LegKey{from, to, region});
    if (made != query.legs.end()) return made->second.cost;
    return splitApart(query, nodeCell(query, from, region), nodeCell(query, to, region), region)
               ? INFINITY
               : query.estimate(distance, region);
  };
  auto neighbours = [&](const RouteState& state, auto&& relax) {
    const auto [node, region] = state;
    const Pose here = nodePose(query, node);
    for (int g = 0; g < goals; ++g) {
      if (query.goals[g].region != region) continue;
      const double cost = legCost(node, g + 1, region, metric_->distance(here, goal));
      if (std::isfinite(cost)) relax(RouteState{g + 1, region}, cost);
    }
    const auto portals = portals_by_region_.find(region);
    if (portals == portals_by_region_.end()) return;
    for (std::uint32_t index : portals->second) {
      const Portal& portal = portals_[index];
      const int side = portal.regions[0] == region ? 0 : 1;
      const int next = static_cast<int>(index) + query.firstPortalNode();
      if (!query.allowed[portal.modes[1 - side]] || next == node) continue;
      const double cost = legCost(node, next, region, metric_->distance(here, nodePose(query, next)));
      if (std::isfinite(cost)) relax(RouteState{next, portal.regions[1 - side]}, cost + query.request.costs.transition);
    }
  };
  auto heuristic = [&](const RouteState& state) { return metric_->distance(nodePose(query, state.first), goal); };
  auto atGoal = [goals](const RouteState& state) { return state.first >= 1 && state.first <= goals; };
  return aStar<RouteState, RouteStateHash>(RouteState{0, query.start.region}, neighbours, heuristic, atGoal).path;
}

bool PathPlanner::settleLegs(Query& query, const std::vector<RouteState>& states, Plan& plan) const {
  for (std::size_t i = 0; i + 1 < states.size(); ++i) {
    const LegKey key{states[i].first, states[i + 1].first, states[i].second};
    if (query.legs.count(key)) continue;
    if (query.expired()) return false;
    const std::int32_t region = states[i].second;
    const double distance = metric_->distance(nodePose(query, states[i].first), nodePose(query, states[i + 1].first));
    const double estimate = query.estimate(distance, region);
    Leg leg = makeLeg(query, states[i].first, states[i + 1].first, region);
    ++plan.legs;
    plan.expanded += leg.expanded;
    if (leg.ok && !leg.via.empty() && distance > 0.0) {
      double& detour = query.detour.try_emplace(region, INFINITY).first->second;
      detour = std::min(detour, leg.cost / distance);
    }
    const bool dearer = !leg.ok || leg.cost > kAcceptedDetour * estimate + 1e-12;
    query.legs.emplace(key, std::move(leg));
    if (dearer) return false;
  }
  return true;
}

// A leg inside a region: a straight segment that keeps the clearance, else a walk over
// the region's cells whose every step keeps the sign. A walk that finds no way learns which
// of the region's cells its start reaches: a later leg between those and the others fails
// at once, so a region that a thin singular layer splits is walked through once.
PathPlanner::Leg PathPlanner::makeLeg(Query& query, int from, int to, std::int32_t region) const {
  const int mode = analysis_.regions()[region].mode;
  const Pose a = nodePose(query, from), b = metric_->nearestTurn(a, nodePose(query, to));
  Leg leg;
  if (holds(query, a, b, mode, query.clearance)) {
    leg.ok = true;
    leg.cost = metric_->distance(a, b);
    return leg;
  }
  const std::uint64_t first = nodeCell(query, from, region), last = nodeCell(query, to, region);
  if (splitApart(query, first, last, region)) return leg;
  // The ends' segments to their cells: checked with the anchors, but not against the
  // places to avoid.
  const Grid& grid = analysis_.grid();
  if (!query.request.avoid.empty() && (!holds(query, a, metric_->nearestTurn(a, grid.pose(first)), mode, 0.0) ||
                                       !holds(query, metric_->nearestTurn(b, grid.pose(last)), b, mode, 0.0))) {
    return leg;
  }
  for (int attempt = 0; attempt < kWalkAttempts; ++attempt) {
    CellPath walk = region_search_->search(first, last, region, query.request.heuristic_weight, query.blocked,
                                           [&query] { return query.expired(); });
    leg.expanded += walk.expanded;
    if (walk.broken_from >= 0 && query.broken_from < 0) {
      query.broken_from = walk.broken_from;
      query.broken_to = walk.broken_to;
    }
    if (walk.cells.empty()) {
      if (!walk.stopped) query.splits.emplace_back(region, std::move(walk.reached));
      return leg;
    }
    const std::size_t failed = failedStep(query, walk.cells, a, mode);
    if (failed > 0) {
      query.blocked.insert({walk.cells[failed - 1], walk.cells[failed]});
      continue;
    }
    leg.via.clear();
    Pose previous = a;
    for (std::uint64_t cell : walk.cells) leg.via.push_back(previous = metric_->nearestTurn(previous, grid.pose(cell)));
    leg.cost = metric_->distance(a, leg.via.front()) + metric_->distance(leg.via.back(), b);
    for (std::size_t k = 0; k + 1 < leg.via.size(); ++k) leg.cost += metric_->distance(leg.via[k], leg.via[k + 1]);
    leg.ok = true;
    return leg;
  }
  return leg;
}

// Whether a walk found the two cells of the region apart: one reached from its start, the
// other not.
bool PathPlanner::splitApart(const Query& query, std::uint64_t a, std::uint64_t b, std::int32_t region) const {
  for (const auto& [split_region, reached] : query.splits) {
    if (split_region == region &&
        std::binary_search(reached.begin(), reached.end(), a) != std::binary_search(reached.begin(), reached.end(), b)) {
      return true;
    }
  }
  return false;
}

// The first step of a walk (index of its second cell) whose segment fails its check, or 0.
// The ends' segments to their cells were checked with the anchors.
std::size_t PathPlanner::failedStep(const Query& query, const std::vector<std::uint64_t>& cells, const Pose& near,
                                    int mode) const {
  Pose previous = metric_->nearestTurn(near, analysis_.grid().pose(cells.front()));
  for (std::size_t k = 1; k < cells.size(); ++k) {
    const Pose next = metric_->nearestTurn(previous, analysis_.grid().pose(cells[k]));
    // The analysis vouches for cell centres only: between two, the sign alone (asking the
    // clearance there would refuse goals it joins through a pinch; docs/planner.md).
    if (!holds(query, previous, next, mode, 0.0)) return k;
    previous = next;
  }
  return 0;
}

// checkSegment with the request's places to avoid: a segment that passes within a tenth
// of a step of one, in the same working mode, fails.
bool PathPlanner::holds(const Query& query, const Pose& from, const Pose& to, int mode, double clearance) const {
  for (const PlanWaypoint& avoid : query.request.avoid) {
    if (avoid.mode != mode) continue;
    const double t = metric_->nearestFraction(from, to, avoid.pose);
    if (metric_->distance(metric_->interpolate(from, to, t), avoid.pose) < query.avoid_radius) return false;
  }
  return checkSegment(from, to, mode, query.sign, clearance) >= 0.0;
}

// The route's legs one after the other, and its working-mode changes at portals.
void PathPlanner::assemble(const Query& query, const std::vector<RouteState>& states, RawPath& path) const {
  const std::vector<Region>& regions = analysis_.regions();
  path.waypoints = {{query.request.start, query.request.start_mode}};
  for (std::size_t i = 0; i + 1 < states.size(); ++i) {
    const int mode = regions[states[i].second].mode;
    const Leg& leg = query.legs.at(LegKey{states[i].first, states[i + 1].first, states[i].second});
    auto add = [&](const Pose& pose, int in_mode) {
      path.waypoints.push_back({metric_->nearestTurn(path.waypoints.back().pose, pose), in_mode});
    };
    for (const Pose& pose : leg.via) add(pose, mode);
    add(nodePose(query, states[i + 1].first), mode);
    if (i + 2 < states.size()) {  // a portal: the same point, left in the other region's mode
      const int new_mode = regions[states[i + 1].second].mode;
      add(path.waypoints.back().pose, new_mode);
      path.transitions.push_back(
          PlanTransition{path.waypoints.size() - 1, portalAt(query, states[i + 1].first).input, mode, new_mode});
    }
  }
}

// Shortcutting, within each stretch of one working mode (transitions stay where they are).
void PathPlanner::shortcut(const Query& query, const RawPath& path, Plan& plan) const {
  const std::vector<PlanWaypoint>& raw = path.waypoints;
  std::vector<std::size_t> boundaries = {0};  // first and last waypoint of each stretch
  for (const PlanTransition& t : path.transitions) {
    boundaries.push_back(t.waypoint - 1);
    boundaries.push_back(t.waypoint);
  }
  boundaries.push_back(raw.size() - 1);
  std::vector<std::size_t> kept;
  for (std::size_t b = 0; b + 1 < boundaries.size(); b += 2) {
    shortcutStretch(query, raw, boundaries[b], boundaries[b + 1], kept);
  }
  // Each kept waypoint's angles within half a turn of the previous one's: the trajectory
  // interpolates the angles between them, and must take the segment that was checked.
  for (std::size_t k : kept) {
    plan.waypoints.push_back(raw[k]);
    if (plan.waypoints.size() > 1) plan.waypoints.back().pose = metric_->nearestTurn(plan.waypoints.rbegin()[1].pose, raw[k].pose);
  }
  for (const PlanTransition& t : path.transitions) {
    PlanTransition moved = t;
    moved.waypoint = static_cast<std::size_t>(std::find(kept.begin(), kept.end(), t.waypoint) - kept.begin());
    plan.transitions.push_back(moved);
  }
}

// Appends to `kept` the waypoints kept of raw[first..last]: from each, the farthest later one
// a straight segment keeping the clearance reaches (doubling, then bisection); the next one
// is always reached, as the legs were checked when made. Once the time budget has run out
// the rest is kept as it is: a longer path, but a valid one.
void PathPlanner::shortcutStretch(const Query& query, const std::vector<PlanWaypoint>& raw, std::size_t first,
                                  std::size_t last, std::vector<std::size_t>& kept) const {
  auto reaches = [&](std::size_t i, std::size_t j) { return holds(query, raw[i].pose, raw[j].pose, raw[i].mode, query.clearance); };
  std::size_t i = first;
  kept.push_back(i);
  while (i < last) {
    if (query.expired()) {
      while (i < last) kept.push_back(++i);
      return;
    }
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
}

// The plan's length, and the smallest |measure| on its segments (those within one working mode).
void PathPlanner::measure(const Query& query, Plan& plan) const {
  plan.min_measure = INFINITY;
  for (std::size_t w = 0; w + 1 < plan.waypoints.size(); ++w) {
    const PlanWaypoint& a = plan.waypoints[w];
    const PlanWaypoint& b = plan.waypoints[w + 1];
    plan.length += metric_->distance(a.pose, b.pose);
    if (a.mode != b.mode) continue;
    Pose at;
    const double smallest = checkSegment(a.pose, b.pose, a.mode, query.sign, 0.0, &at);
    if (smallest < plan.min_measure) plan.min_measure = smallest, plan.min_measure_at = at;
  }
}

Pose PathPlanner::nodePose(const Query& query, int node) const {
  if (node == 0) return query.request.start;
  if (node < query.firstPortalNode()) return query.request.goal;
  return analysis_.transitions().pose(portalAt(query, node).point);
}

std::uint64_t PathPlanner::nodeCell(const Query& query, int node, std::int32_t region) const {
  if (node == 0) return query.start.cell;
  if (node < query.firstPortalNode()) return query.goals[node - 1].cell;
  const Portal& portal = portalAt(query, node);
  return portal.cells[portal.regions[0] == region ? 0 : 1];
}

const PathPlanner::Portal& PathPlanner::portalAt(const Query& query, int node) const {
  return portals_[node - query.firstPortalNode()];
}

}  // namespace maximal_workspace
