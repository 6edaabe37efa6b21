#pragma once
// One plan request end to end, the one function `mow plan` and /plan_path both call: the
// planner on the analysis whose margin is the clearance, the actuator trajectory and its
// verification by DKP continuation; and for a refusal, its witness. A goal that analysis
// calls reachable from the start gets a verified plan; a refusal names why: the goal's own
// |measure|, or the narrowest place (neck) of the widest route of the analysis at the
// request's margin, with the largest clearance that would plan (docs/planner.md).

#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include "maximal_workspace/planner/path_planner.h"
#include "maximal_workspace/planner/trajectory.h"
#include "maximal_workspace/planner/verification.h"

namespace maximal_workspace {

// The margin of the analysis plans with this clearance are made on, for an analysis
// asked with `margin`: its regions are then the cells the clearance allows.
inline double planningMargin(double margin, double clearance) { return margin > clearance ? margin : clearance; }

// The analysis of the plan's grid at a margin, computed or read from a cache by the caller.
using AnalysisAtMargin = std::function<std::shared_ptr<const WorkspaceAnalysis>(double margin)>;

struct PlanSettings {
  InputLimits limits;
  int samples_per_segment = 64;
  // What explains a refusal: the analysis at the margin the request asked for (0: the
  // exact one), when it is under the planner's; no neck is looked for without it.
  double request_margin = 0.0;
  AnalysisAtMargin analysis_at;
};

struct PlanOutcome {
  Plan plan;
  InputTrajectory trajectory;  // when planned
  Verification verification;   // when planned
  bool success = false;        // planned and verified
  std::string message;         // a refusal with its witness, or why the verification failed
  // A refusal's largest clearance that plans: the |measure| of the neck of the widest route
  // of the analysis at the request's margin, rounded down, and checked by a plan at it;
  // 0 when that analysis does not join them at all; NaN when not known (another refusal,
  // or the check's plan was not made: the step does not resolve the neck).
  double workable_clearance = NAN;
  double seconds = 0.0;  // the whole request: plan, trajectory, verification, witness
};

PlanOutcome planPath(const RobotModel& model, const PathPlanner& planner, const PlanRequest& request,
                     const PlanSettings& settings);

}  // namespace maximal_workspace
