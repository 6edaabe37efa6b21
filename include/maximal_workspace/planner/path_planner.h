#pragma once
// Paths in the maximal operational workspace (issue 5), inside one assembly mode. Grid
// moves keep the working mode and the sign of det J_DKP; the working mode changes only at
// the exact transition points of the transition graph (IKP singularities).
// Two levels, so fine grids stay fast: a search over the transition graph first (its
// nodes a few representative transition points per transition, plus start and goal; a
// leg joins two nodes of one region and costs their distance), then each leg inside its
// region: a checked straight segment when it holds, else an A* over the region's voxels
// (26-connected, no corner cutting, with the clearance penalty). A leg that cannot be
// made is struck and the route searched again; routes of straight legs only are tried
// first, as they are cheap to check. The path is then shortened while every
// constraint still holds on a fine sampling of each segment.

#include <cstdint>
#include <set>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

struct PlannerCosts {
  double transition = 0.05;       // m added per working-mode change
  double clearance_weight = 1.0;  // extra cost per m travelled where |measure| < clearance_soft
  double clearance_soft = 0.05;   // |measure| under which the penalty grows
};

// The clearance plans keep from DKP singularities unless asked otherwise: the exact
// workspace reaches |measure| 0, a controller should not (docs/kinematics.md, margins).
constexpr double kDefaultPlanClearance = 1e-3;

struct PlanRequest {
  Pose start;
  int start_mode = 0;   // index into the analysis's working modes
  Pose goal;
  int goal_mode = -1;   // -1: any
  // Minimum |normalised det J_DKP| along the path; the analysis's margin applies anyway.
  double clearance = kDefaultPlanClearance;
  // Working modes the path may use (indices); empty: all. {start_mode} plans the
  // traditional way, in one working mode.
  std::vector<int> allowed_modes;
  PlannerCosts costs;
  // Weight of the distance-to-goal heuristic: 1 finds the cheapest path on the grid;
  // above 1 (weighted A*) expands far fewer nodes for a path at most that many times
  // dearer, which shortcutting then straightens.
  double heuristic_weight = 1.0;
};

struct PlanWaypoint {
  Pose pose;
  int mode = 0;
};

struct PlanTransition {
  std::size_t waypoint = 0;  // the waypoint where the mode changes (its mode is the new one)
  int input = 0;             // the couple changing branch
  int from_mode = 0;
  int to_mode = 0;
};

struct Plan {
  bool success = false;
  std::string message;  // why not, when it failed
  std::int8_t sign = 0;  // the assembly mode
  // Straight segments between waypoints; at a transition two consecutive waypoints share
  // the exact point, the second one in the new working mode.
  std::vector<PlanWaypoint> waypoints;
  std::vector<PlanTransition> transitions;
  double length = 0.0;       // m
  double min_measure = 0.0;  // smallest |measure| of the working mode in use, on the sampled path
  Pose min_measure_at;       // where: through a neck of a region, the price of the route
  std::size_t expanded = 0;  // voxel-search nodes expanded, all legs
  int routes = 0;            // transition-graph routes tried
};

// The planner keeps what it builds once per analysis: the portals by region. The
// analysis is shared with the planner (a copy of it costs nothing).
class PathPlanner {
 public:
  PathPlanner(const RobotModel& model, WorkspaceAnalysis analysis);

  Plan plan(const PlanRequest& request) const;
  // Checks a straight segment in one working mode: assembled, the sign kept, and |measure|
  // at least `clearance`, on samples every quarter step. Returns the smallest |measure|
  // seen, or a negative value when a constraint fails.
  double checkSegment(const Pose& from, const Pose& to, int mode, std::int8_t sign, double clearance,
                      Pose* smallest_at = nullptr) const;

 private:
  // A representative transition point: a node of the route search, in two regions.
  struct Portal {
    std::uint32_t point;
    std::int32_t regions[2];
    int modes[2];
    int input;
  };
  struct Query;
  struct RawPath;
  struct LegResult;
  // A state of the route search: a route node (0 the start, then the goal in each of its
  // regions, then the portals) and the region the robot is in there.
  using RouteState = std::pair<int, std::int32_t>;
  // Legs (from node, to node, region) that could not be made.
  using StruckLegs = std::set<std::tuple<int, int, std::int32_t>>;

  // The stages of plan(); each that can fail says why in plan.message.
  bool validate(Query& query, Plan& plan) const;
  bool validateStart(Query& query, const std::vector<double>& measures, std::uint64_t cell, Plan& plan) const;
  bool validateGoal(Query& query, const std::vector<double>& measures, std::uint64_t cell, Plan& plan) const;
  bool findPath(const Query& query, RawPath& path, Plan& plan) const;
  std::vector<RouteState> route(const Query& query, const StruckLegs& struck) const;
  bool realiseLegs(const Query& query, const std::vector<RouteState>& route, bool straight_only, StruckLegs& struck,
                   RawPath& path, std::size_t& expanded) const;
  bool shortcut(const Query& query, const RawPath& path, Plan& plan) const;
  bool shortcutStretch(const Query& query, const std::vector<PlanWaypoint>& raw, std::size_t first, std::size_t last,
                       std::vector<std::size_t>& kept) const;
  void measure(const Query& query, Plan& plan) const;
  // "breaks a limit of the robot in ... (why, per working mode)" when every working mode
  // allowed (or `only_mode` when >= 0) breaks one at the pose; empty otherwise.
  std::string limitReasons(const Query& query, const Pose& pose, int only_mode) const;

  Pose nodePose(const Query& query, int node) const;
  const Portal& portalAt(const Query& query, int node) const;
  // A leg inside a region: a checked straight segment, else (unless straight_only) a
  // voxel search.
  LegResult walkRegion(const Query& query, const Pose& from, const Pose& to, std::int32_t region,
                       bool straight_only) const;
  LegResult searchRegion(const Query& query, const Pose& from, const Pose& to, std::int32_t region) const;

  const RobotModel& model_;
  RobotConstraints constraints_;
  WorkspaceAnalysis analysis_;
  PoseClassifier classifier_;
  double margin_;  // the analysis's
  std::vector<Portal> portals_;
  std::unordered_map<std::int32_t, std::vector<std::uint32_t>> portals_by_region_;
};

}  // namespace maximal_workspace
