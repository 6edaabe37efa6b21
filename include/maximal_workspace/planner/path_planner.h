#pragma once
// Paths in the maximal operational workspace (issue 5), inside one assembly mode, on an
// analysis whose margin is the plan's clearance: its regions are the cells at least that
// far from every DKP singularity of their working mode, so the planner is complete
// relative to it: a goal that analysis calls reachable from the start gets a path.
// Within a region a path keeps the working mode; it changes working mode only at the exact
// transition points of the transition graph (IKP singularities). Two levels keep fine grids
// fast: a route over the transition graph (its nodes a few representative points per
// transition, plus start and goal; a leg joins two nodes of one region), whose legs are
// made lazily: each leg the cheapest route uses is made once, as a checked straight
// segment or else a walk over the region's cells, and the route is searched again while a
// leg made costs more than its estimate (docs/planner.md). Everything is bounded by the
// grid and by the request's time budget. The path is then shortened while every
// constraint still holds on a fine sampling of each segment.

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

class PlannerMetric;
class RegionSearch;

struct PlannerCosts {
  double transition = 0.05;  // m added per working-mode change
};

// The clearance plans keep from DKP singularities unless asked otherwise: the exact
// workspace reaches |measure| 0, a controller should not (docs/kinematics.md, margins).
constexpr double kDefaultPlanClearance = 1e-3;
// Seconds a plan request may search before it answers that its budget ran out.
constexpr double kDefaultPlanTimeLimit = 5.0;

struct PlanWaypoint {
  Pose pose;
  int mode = 0;
};

struct PlanRequest {
  Pose start;
  int start_mode = 0;   // index into the analysis's working modes
  Pose goal;
  int goal_mode = -1;   // -1: any
  // Minimum |normalised det J_DKP| at the path's cells and on its straight segments: the
  // margin of the analysis planned on (planningMargin, planner/planning.h).
  double clearance = kDefaultPlanClearance;
  // Working modes the path may use (indices); empty: all. {start_mode} plans the
  // traditional way, in one working mode.
  std::vector<int> allowed_modes;
  PlannerCosts costs;
  // Weight of the distance-to-goal heuristic of the walks inside regions: 1 finds the
  // shortest walk on the grid; above 1 (weighted A*) expands far fewer cells for a walk
  // at most that many times longer, which shortcutting then straightens.
  double heuristic_weight = 1.5;
  double time_limit = kDefaultPlanTimeLimit;  // s
  // Places (with the working mode there) a path must keep clear of: where an earlier plan
  // failed its verification. A segment passing within a tenth of a step of one fails.
  std::vector<PlanWaypoint> avoid;
};

struct PlanTransition {
  std::size_t waypoint = 0;  // the waypoint where the mode changes (its mode is the new one)
  int input = 0;             // the couple changing branch
  int from_mode = 0;
  int to_mode = 0;
};

// Why a plan was refused, for a caller that explains it further (planner/planning.h).
enum class PlanRefusal : std::uint8_t {
  None,
  Request,          // the request itself: modes, clearance, time budget
  Start,            // the start: outside, a limit, too close to a DKP singularity
  GoalOutside,      // outside the workspace or breaking a limit in every mode allowed
  GoalOtherAssemblyMode,
  GoalClearance,    // closer to a DKP singularity than the clearance in every mode allowed
  NotJoined,        // the goal's regions are not joined to the start's at the clearance
  TimeLimit,        // the budget ran out before a path was made
  Unresolved,       // joined on the grid only: a singular layer thinner than the step lies between cells
  NoPath,           // joined, but no path was made
};

struct Plan {
  bool success = false;
  std::string message;  // why not, when it failed
  PlanRefusal refusal = PlanRefusal::None;
  std::int8_t sign = 0;  // the assembly mode
  // Straight segments between waypoints; at a transition two consecutive waypoints share
  // the exact point, the second one in the new working mode.
  std::vector<PlanWaypoint> waypoints;
  std::vector<PlanTransition> transitions;
  double length = 0.0;       // m (rotations scaled by the characteristic length)
  double min_measure = 0.0;  // smallest |measure| of the working mode in use, on the sampled path
  Pose min_measure_at;       // where: through a neck of a region, the price of the route
  std::size_t expanded = 0;  // cells expanded by the walks inside regions, all legs
  int routes = 0;            // routes searched over the transition graph
  int legs = 0;              // legs made (straight or walked), kept or not
  double seconds = 0.0;      // spent planning
  // For explaining a refusal: the goal's largest |measure| among the working modes allowed
  // with the start's sign.
  double goal_measure = 0.0;
};

// The planner keeps what it builds once per analysis: the portals by region. The
// analysis is shared with the planner (a copy of it costs nothing). plan() may be called
// from several threads at once.
class PathPlanner {
 public:
  PathPlanner(const RobotModel& model, WorkspaceAnalysis analysis);
  ~PathPlanner();

  const WorkspaceAnalysis& analysis() const { return analysis_; }
  Plan plan(const PlanRequest& request) const;
  // Checks a straight segment in one working mode: assembled, the sign kept, and |measure|
  // at least `clearance`, on samples every quarter step (at least `min_samples`), near both
  // ends, and more densely where the measure changes fast. Returns the smallest |measure|
  // seen, or a negative value when a constraint fails.
  double checkSegment(const Pose& from, const Pose& to, int mode, std::int8_t sign, double clearance,
                      Pose* smallest_at = nullptr, int min_samples = 1) const;

 private:
  // Where a pose meets a region: a cell of the region whose centre a checked segment from
  // the pose reaches.
  struct Anchor {
    int mode = 0;
    std::int32_t region = -1;
    std::uint64_t cell = 0;
  };
  // A representative transition point: a node of the route search, in two regions.
  struct Portal {
    std::uint32_t point;
    std::int32_t regions[2];
    int modes[2];
    std::uint64_t cells[2];  // its anchor cell in each region
    int input;
  };
  struct Query;
  struct RawPath;
  struct Leg;
  // A state of the route search: a route node (0 the start, then the goal in each of its
  // regions, then the portals) and the region the robot is in there.
  using RouteState = std::pair<int, std::int32_t>;
  using LegKey = std::tuple<int, int, std::int32_t>;  // from node, to node, region

  // The stages of plan(); each that can fail says why in plan.message.
  bool validate(Query& query, Plan& plan) const;
  bool validateStart(Query& query, const std::vector<double>& measures, Plan& plan) const;
  bool validateGoal(Query& query, const std::vector<double>& measures, Plan& plan) const;
  bool refuseGoal(const Query& query, const std::vector<double>& measures, Plan& plan) const;
  bool findPath(Query& query, RawPath& path, Plan& plan) const;
  std::vector<RouteState> route(const Query& query) const;
  // Makes the route's legs not made yet, in order; false at the first that costs more
  // than its estimate (or cannot be made): the route must be searched again.
  bool settleLegs(Query& query, const std::vector<RouteState>& states, Plan& plan) const;
  Leg makeLeg(Query& query, int from, int to, std::int32_t region) const;
  bool splitApart(const Query& query, std::uint64_t a, std::uint64_t b, std::int32_t region) const;
  std::size_t failedStep(const Query& query, const std::vector<std::uint64_t>& cells, const Pose& near, int mode) const;
  bool holds(const Query& query, const Pose& from, const Pose& to, int mode, double clearance) const;
  std::string unresolvedMessage(const Query& query) const;
  void assemble(const Query& query, const std::vector<RouteState>& states, RawPath& path) const;
  void shortcut(const Query& query, const RawPath& path, Plan& plan) const;
  void shortcutStretch(const Query& query, const std::vector<PlanWaypoint>& raw, std::size_t first, std::size_t last,
                       std::vector<std::size_t>& kept) const;
  void measure(const Query& query, Plan& plan) const;
  // "breaks a limit of the robot in ... (why, per working mode)" when every working mode
  // allowed (or `only_mode` when >= 0) breaks one at the pose; empty otherwise.
  std::string limitReasons(const Query& query, const Pose& pose, int only_mode) const;
  // The regions of `mode` with sign `sign` that the pose reaches: its own cell's first (the
  // cell holding it, or `own_cell` when >= 0: a transition point's, inward of the IKP
  // boundary it lies on, checked densely), then those of the cells around it, one anchor per region. With
  // `only_region` >= 0, the first anchor in that region alone.
  std::vector<Anchor> anchors(const Pose& pose, int mode, std::int8_t sign, std::int32_t only_region = -1,
                              std::int64_t own_cell = -1) const;

  Pose nodePose(const Query& query, int node) const;
  std::uint64_t nodeCell(const Query& query, int node, std::int32_t region) const;
  const Portal& portalAt(const Query& query, int node) const;

  const RobotModel& model_;
  RobotConstraints constraints_;
  WorkspaceAnalysis analysis_;
  PoseClassifier classifier_;
  std::unique_ptr<const PlannerMetric> metric_;
  std::unique_ptr<const RegionSearch> region_search_;
  double margin_;  // the analysis's
  std::vector<Portal> portals_;
  std::unordered_map<std::int32_t, std::vector<std::uint32_t>> portals_by_region_;
};

}  // namespace maximal_workspace
