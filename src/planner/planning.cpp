#include "maximal_workspace/planner/planning.h"

#include <chrono>
#include <cmath>
#include <algorithm>
#include <optional>
#include <vector>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/regions/necks.h"

namespace maximal_workspace {

namespace {

// Plans made again after a failed verification, each avoiding where the last one failed.
constexpr int kRepairs = 3;

// Two significant digits, rounded down: a clearance written from it still plans.
double roundedDown(double value) {
  if (!(value > 0.0)) return 0.0;
  const double unit = std::pow(10.0, std::floor(std::log10(value)) - 1.0);
  double rounded = std::floor(value / unit) * unit;
  while (rounded > value) rounded -= unit;
  return rounded;
}

std::string neckPlace(const Neck& neck, const std::vector<WorkingMode>& modes) {
  const std::string at = " at " + vectorText(neck.pose.position);
  if (neck.kind == Neck::Kind::Transition) {
    return "the transition " + modes[neck.mode].name + " -> " + modes[neck.to_mode].name + at;
  }
  return "a region of working mode " + modes[neck.mode].name + at;
}

// The working modes a request lets the goal be reached in.
std::vector<int> goalModes(const PlanRequest& request, int mode_count) {
  std::vector<int> modes;
  for (int m = 0; m < mode_count; ++m) {
    const bool allowed = request.allowed_modes.empty() ||
                         std::find(request.allowed_modes.begin(), request.allowed_modes.end(), m) != request.allowed_modes.end();
    if (allowed && (request.goal_mode < 0 || request.goal_mode == m)) modes.push_back(m);
  }
  return modes;
}

// Why the analysis at the clearance does not join the goal to the start: the narrowest
// place of the widest route of the analysis at the request's margin, and the clearance it
// allows, checked by a plan at that clearance. The analysis joins two cells whatever lies
// between them, so a neck can be one only on the grid: then no clearance is named.
void explainNotJoined(const RobotModel& model, const PathPlanner& planner, const PlanRequest& request,
                      const PlanSettings& settings, PlanOutcome& outcome) {
  const WorkspaceAnalysis& planned_on = planner.analysis();
  std::uint64_t from = 0, to = 0;
  if (!settings.analysis_at || !(settings.request_margin < planned_on.settings().margin) ||
      !planned_on.grid().cellOf(request.start, &from) || !planned_on.grid().cellOf(request.goal, &to)) {
    return;
  }
  const std::shared_ptr<const WorkspaceAnalysis> wider = settings.analysis_at(settings.request_margin);
  const std::string analysis = "the " + marginText(settings.request_margin) + " analysis";
  const std::optional<Neck> neck =
      widestRouteNeck(model, *wider, planned_on, outcome.plan.sign, from, request.start_mode, to,
                      goalModes(request, static_cast<int>(planned_on.modes().size())));
  if (!neck) {
    outcome.workable_clearance = 0.0;
    outcome.message += "; " + analysis + " does not join them either: no clearance plans";
    return;
  }
  const double workable = roundedDown(neck->measure);
  outcome.message += "; the widest route of " + analysis + " narrows to |measure| " + numberText(neck->measure) +
                     " at " + neckPlace(*neck, planned_on.modes());
  PlanRequest at_neck = request;
  at_neck.clearance = workable;
  PlanSettings checking = settings;
  checking.analysis_at = nullptr;  // no witness of the witness
  const std::shared_ptr<const WorkspaceAnalysis> at_workable =
      settings.analysis_at(planningMargin(settings.request_margin, workable));
  const PlanOutcome check = planPath(model, PathPlanner(model, *at_workable), at_neck, checking);
  if (check.success) {
    outcome.workable_clearance = workable;
    outcome.message += ": a clearance of at most " + numberText(workable) + " plans";
  } else {
    outcome.message += ", but a plan at clearance " + numberText(workable) + " is not made either (" + check.message +
                       "): the step does not resolve the place";
  }
}

void explain(const RobotModel& model, const PathPlanner& planner, const PlanRequest& request,
             const PlanSettings& settings, PlanOutcome& outcome) {
  const Plan& plan = outcome.plan;
  outcome.message = plan.message;
  if (plan.refusal == PlanRefusal::GoalClearance && plan.goal_measure > 0.0) {
    outcome.message += "; no clearance above " + numberText(plan.goal_measure) + " (the goal's |measure|) reaches it";
  }
  if (plan.refusal == PlanRefusal::NotJoined || plan.refusal == PlanRefusal::GoalClearance) {
    explainNotJoined(model, planner, request, settings, outcome);
  }
}

// The trajectory of a plan and its verification; when it fails, where (in the working
// mode there): a place the next plan avoids.
bool verified(const RobotModel& model, const PathPlanner& planner, const PlanSettings& settings, PlanOutcome& outcome,
              PlanWaypoint& failed_at) {
  try {
    outcome.trajectory =
        inputTrajectory(model, planner.analysis(), outcome.plan, settings.limits, settings.samples_per_segment);
    outcome.verification = verifyByDkpContinuation(model, outcome.trajectory, outcome.plan.sign);
  } catch (const UnassembledPose& error) {
    outcome.verification = Verification();
    outcome.verification.message = error.what();
    failed_at = PlanWaypoint{error.pose, error.mode};
    return false;
  }
  const std::size_t k = outcome.verification.failed_sample;
  failed_at = PlanWaypoint{outcome.trajectory.poses[k], outcome.trajectory.modes[k]};
  return outcome.verification.passed;
}

}  // namespace

PlanOutcome planPath(const RobotModel& model, const PathPlanner& planner, const PlanRequest& request,
                     const PlanSettings& settings) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point started = Clock::now();
  checkInputLimits(model, settings.limits);
  PlanOutcome outcome;
  PlanRequest attempt = request;
  // A plan that fails its verification (a thin layer between the planner's samples) is
  // made again around the place where it failed, a few times, within the time budget.
  for (int repair = 0;; ++repair) {
    const std::string failed_before = outcome.verification.message;
    outcome.plan = planner.plan(attempt);
    if (!outcome.plan.success) {
      explain(model, planner, request, settings, outcome);
      if (repair > 0) {
        outcome.message = "a plan was made but failed its verification (" + failed_before + "), and no other was made: " +
                          outcome.message;
      }
      break;
    }
    PlanWaypoint failed_at;
    outcome.success = verified(model, planner, settings, outcome, failed_at);
    const double left = request.time_limit - std::chrono::duration<double>(Clock::now() - started).count();
    if (outcome.success || repair == kRepairs || !(left > 0.0)) {
      if (!outcome.success) outcome.message = "the plan failed its verification: " + outcome.verification.message;
      break;
    }
    attempt.avoid.push_back(failed_at);
    attempt.time_limit = left;
  }
  outcome.seconds = std::chrono::duration<double>(Clock::now() - started).count();
  return outcome;
}

}  // namespace maximal_workspace
