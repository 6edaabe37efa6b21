#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>

#include "analysis_request.h"
#include "commands.h"
#include "maximal_workspace/io/plan_csv.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/planner/planning.h"

namespace maximal_workspace::cli {

namespace {

// Exit code of a plan that could not be made or did not verify: a result, not bad input.
constexpr int kNoVerifiedPlan = 3;
constexpr std::uint64_t kMostRandomGoals = 1000000;

// x,y,z (the rest of the pose from `fallback`) or x,y,z and three angles: ZYZ phi, theta,
// psi, or on a tilt-and-torsion analysis its azimuth, tilt and torsion (the grid's own).
Pose poseOption(const Arguments& arguments, const std::string& option, const Pose& fallback, const Grid& grid) {
  if (!arguments.has(option)) return fallback;
  const std::vector<double> values = arguments.numbers(option);
  if (values.size() != 3 && values.size() != 6) {
    throw InputError("option " + option + ": expected x,y,z (m) or x,y,z," +
                     (grid.tiltTorsion() ? "azimuth,tilt,torsion" : "phi,theta,psi") + " (m, rad)");
  }
  Pose pose = fallback;
  if (values.size() == 6 && grid.tiltTorsion()) {
    if (values[4] < 0.0) throw InputError("option " + option + ": the tilt must be >= 0");
    return grid.poseAt(values.data());
  }
  for (std::size_t k = 0; k < values.size(); ++k) pose.setValue(static_cast<OutputVariable>(k), values[k]);
  return pose;
}

// One limit per input from the option, else by kind: 1 rad/s and 2 rad/s^2 for cranks,
// 0.5 m/s and 1 m/s^2 for sliders.
std::vector<double> limitsOption(const Arguments& arguments, const std::string& option, const RobotModel& model,
                                 double revolute, double prismatic) {
  std::vector<double> limits;
  if (arguments.has(option)) {
    limits = arguments.numbers(option);
    if (static_cast<int>(limits.size()) != model.inputCount()) {
      throw InputError("option " + option + ": expected one value per input (" + std::to_string(model.inputCount()) + ")");
    }
  } else {
    for (const Input& input : model.inputs) limits.push_back(input.kind == InputKind::Revolute ? revolute : prismatic);
  }
  return limits;
}

// A number option that must lie in [low, high].
double boundedOption(const Arguments& arguments, const std::string& option, double fallback, double low, double high,
                     const std::string& range) {
  const double value = arguments.number(option, fallback);
  if (!(value >= low && value <= high)) throw InputError("option " + option + ": must be " + range);
  return value;
}

PlanRequest planRequest(const Arguments& arguments, const AnalysisRequest& request, const std::vector<WorkingMode>& modes) {
  const RobotModel& model = request.model;
  PlanRequest plan;
  const Grid grid(model, request.spec);
  plan.start = poseOption(arguments, "--from", request.spec.start, grid);
  plan.start_mode = arguments.has("--from-mode")
                        ? workingModeIndex(modes, arguments.required("--from-mode"), "option --from-mode")
                        : resolveStartMode(model, modes, plan.start, arguments.has("--from") ? "" : request.options.start_mode);
  if (!arguments.has("--random-goals")) {
    if (!arguments.has("--goal")) throw InputError("missing required option --goal (or --random-goals)");
    plan.goal = poseOption(arguments, "--goal", request.spec.start, grid);
  }
  if (arguments.has("--goal-mode")) plan.goal_mode = workingModeIndex(modes, arguments.required("--goal-mode"), "option --goal-mode");
  plan.clearance = arguments.number("--clearance", kDefaultPlanClearance);
  if (!(plan.clearance >= 0.0 && plan.clearance < 1.0)) throw InputError("option --clearance: must be in [0, 1)");
  plan.costs.transition = boundedOption(arguments, "--transition-cost", plan.costs.transition, 0.0, 1e3, "in [0, 1000] (m)");
  plan.time_limit = boundedOption(arguments, "--time-limit", kDefaultPlanTimeLimit, 1e-3, 3600.0, "in [0.001, 3600] (s)");
  if (arguments.flag("--single-mode")) plan.allowed_modes = {plan.start_mode};
  return plan;
}

// A pose as its position, or every grid variable when the grid turns the platform too.
std::string pointText(const Grid& grid, const Pose& pose) {
  return grid.isSpatial() ? vectorText(pose.position) : gridPointText(grid, pose);
}

void printPlan(const RobotModel& model, const Grid& grid, const std::vector<WorkingMode>& modes, const PlanOutcome& outcome) {
  const Plan& plan = outcome.plan;
  // Fixed decimals while they stay short: a tiny --max-velocity must not print 300 digits.
  const double duration = outcome.trajectory.time.back();
  std::printf(duration < 1e9 ? "%s, %s, length %.4f m, min |measure| %.4g at %s, duration %.3f s, assembly mode %c\n"
                             : "%s, %s, length %.4f m, min |measure| %.4g at %s, duration %.4g s, assembly mode %c\n",
              countText(plan.waypoints.size(), "waypoint").c_str(), countText(plan.transitions.size(), "transition").c_str(),
              plan.length, plan.min_measure, pointText(grid, plan.min_measure_at).c_str(), duration,
              plan.sign > 0 ? '+' : '-');
  std::fflush(stdout);
  for (const PlanTransition& t : plan.transitions) {
    const std::string& from = modes[t.from_mode].name;
    const std::string& to = modes[t.to_mode].name;
    std::cout << "  transition at waypoint " << t.waypoint << " " << pointText(grid, plan.waypoints[t.waypoint].pose)
              << ": " << model.inputs[t.input].name << " " << from[t.input] << "->" << to[t.input] << " (" << from
              << " -> " << to << ")\n";
  }
  std::cout << "verification: " << (outcome.verification.passed ? "passed, " : "FAILED, ") << outcome.verification.message
            << "\n";
  std::printf("planned in %.1f ms (search %.1f ms: %d routes, %d legs, %zu cells walked)\n", 1e3 * outcome.seconds,
              1e3 * plan.seconds, plan.routes, plan.legs, plan.expanded);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// Goals drawn with `seed` among the cells the analysis planned on calls reachable from the
// start (in the start's group, in a working mode allowed): their centres.
std::vector<Pose> reachableGoals(const WorkspaceAnalysis& analysis, const PlanRequest& request, std::uint64_t count,
                                 std::uint64_t seed) {
  const Grid& grid = analysis.grid();
  const std::vector<Region>& regions = analysis.regions();
  const std::vector<std::int32_t>& component = analysis.transitions().component;
  std::uint64_t start_cell = 0;
  const std::int32_t start = grid.cellOf(request.start, &start_cell) ? analysis.label(start_cell, request.start_mode) : -1;
  if (start < 0 || regions[start].debris) {
    throw InputError("option --random-goals: the start's voxel is in no region of its working mode at the clearance");
  }
  auto reachable = [&](std::uint64_t cell) {
    for (int m = 0; m < static_cast<int>(analysis.modes().size()); ++m) {
      const bool allowed = request.allowed_modes.empty() || request.allowed_modes.front() == m;
      const std::int32_t label = analysis.label(cell, m);
      if (allowed && label >= 0 && !regions[label].debris && component[label] == component[start]) return true;
    }
    return false;
  };
  std::mt19937_64 random(seed);
  std::uniform_int_distribution<std::uint64_t> any_cell(0, grid.cellCount() - 1);
  std::vector<Pose> goals;
  for (std::uint64_t tries = 0; goals.size() < count && tries < 1000 * count + 1000000; ++tries) {
    const std::uint64_t cell = any_cell(random);
    if (reachable(cell)) goals.push_back(grid.pose(cell));
  }
  if (goals.size() < count) throw InputError("option --random-goals: too few reachable cells found in the grid's box");
  return goals;
}

// The completeness harness: plans to goals the analysis calls reachable; every one must
// be planned and verified.
int runRandomGoals(std::uint64_t count, std::uint64_t seed, const RobotModel& model, const PathPlanner& planner,
                   PlanRequest request, const PlanSettings& settings) {
  const std::vector<WorkingMode>& modes = planner.analysis().modes();
  std::vector<double> total_ms, search_ms;
  std::uint64_t planned = 0, unresolved = 0, timed_out = 0;
  std::vector<std::string> failures;
  for (const Pose& goal : reachableGoals(planner.analysis(), request, count, seed)) {
    request.goal = goal;
    const PlanOutcome outcome = planPath(model, planner, request, settings);
    total_ms.push_back(1e3 * outcome.seconds);
    search_ms.push_back(1e3 * outcome.plan.seconds);
    const std::string where = "goal " + std::to_string(total_ms.size()) + " " + gridPointText(planner.analysis().grid(), goal);
    if (outcome.success) {
      ++planned;
      std::printf("%s: planned, %s, length %.3f m, %.1f ms\n", where.c_str(),
                  countText(outcome.plan.transitions.size(), "transition").c_str(), outcome.plan.length, total_ms.back());
      continue;
    }
    unresolved += outcome.plan.refusal == PlanRefusal::Unresolved;
    timed_out += outcome.plan.refusal == PlanRefusal::TimeLimit;
    failures.push_back(where + ": " + outcome.message);
    std::printf("%s: NOT PLANNED (%.1f ms): %s\n", where.c_str(), total_ms.back(), outcome.message.c_str());
  }
  std::printf("planned and verified %llu/%llu goals reachable at the clearance (%s analysis, start in %s); per plan: "
              "median %.1f ms, max %.1f ms (search median %.1f ms, max %.1f ms)\n",
              static_cast<unsigned long long>(planned), static_cast<unsigned long long>(count),
              marginText(planner.analysis().settings().margin).c_str(), modes[request.start_mode].name.c_str(),
              median(total_ms), *std::max_element(total_ms.begin(), total_ms.end()), median(search_ms),
              *std::max_element(search_ms.begin(), search_ms.end()));
  if (planned < count) {
    std::printf("not planned: %llu (the analysis joins them only across a singular layer thinner than the step: %llu; "
                "time limit: %llu; other: %llu)\n",
                static_cast<unsigned long long>(count - planned), static_cast<unsigned long long>(unresolved),
                static_cast<unsigned long long>(timed_out),
                static_cast<unsigned long long>(count - planned - unresolved - timed_out));
  }
  for (const std::string& failure : failures) std::printf("  failed: %s\n", failure.c_str());
  return planned == count ? 0 : kNoVerifiedPlan;
}

}  // namespace

int runPlan(const std::vector<std::string>& args) {
  const Arguments arguments(
      args,
      analysisValueOptions({"--from", "--from-mode", "--goal", "--goal-mode", "--clearance", "--max-velocity",
                            "--max-acceleration", "--transition-cost", "--time-limit", "--random-goals", "--seed", "--out"}),
      analysisFlags({"--single-mode"}));
  AnalysisRequest request = analysisRequest(arguments);
  const RobotModel& model = request.model;
  const std::vector<WorkingMode> modes = analysedWorkingModes(model, request.options);
  const PlanRequest plan_request = planRequest(arguments, request, modes);
  const std::uint64_t random_goals = arguments.count("--random-goals", 0, 1);
  if (random_goals > kMostRandomGoals) throw InputError("option --random-goals: at most " + std::to_string(kMostRandomGoals));
  const std::uint64_t seed = arguments.count("--seed", 1, 0);
  PlanSettings settings;
  settings.limits = InputLimits{limitsOption(arguments, "--max-velocity", model, 1.0, 0.5),
                                limitsOption(arguments, "--max-acceleration", model, 2.0, 1.0)};
  settings.request_margin = request.options.margin;

  ProgressBar bar;
  if (!arguments.flag("--quiet")) request.options.progress = [&bar](const AnalysisProgress& p) { bar.update(p); };
  settings.analysis_at = [&](double margin) {
    const std::shared_ptr<const WorkspaceAnalysis> analysis = loadedWorkspace(arguments, atMargin(request, margin), "plan");
    bar.finish();
    return analysis;
  };
  const PathPlanner planner(model, *settings.analysis_at(planningMargin(request.options.margin, plan_request.clearance)));
  if (random_goals > 0) return runRandomGoals(random_goals, seed, model, planner, plan_request, settings);

  const PlanOutcome outcome = planPath(model, planner, plan_request, settings);
  const Grid& grid = planner.analysis().grid();
  std::cout << "plan from " << pointText(grid, plan_request.start) << " in " << modes[plan_request.start_mode].name << " to "
            << pointText(grid, plan_request.goal) << " (step " << numberText(request.spec.steps[0]) << ", "
            << marginText(planner.analysis().settings().margin) << " analysis)\n";
  if (!outcome.plan.success) {
    std::cout << "no plan: " << outcome.message << "\n";
    return kNoVerifiedPlan;
  }
  printPlan(model, grid, modes, outcome);
  const std::string out = arguments.optional("--out", "");
  if (!out.empty()) {
    writeFileAtomically(out, planCsv(outcome.trajectory, modes));
    std::cout << "written to " << out << " (" << outcome.trajectory.time.size() << " samples)\n";
  }
  return outcome.success ? 0 : kNoVerifiedPlan;
}

int runVerify(const std::vector<std::string>& args) {
  const Arguments arguments(args, {"--robot", "--plan"}, {"--uncoupled"});
  const RobotModel model = loadRobotFile(arguments.required("--robot"));
  const std::vector<WorkingMode> modes =
      arguments.flag("--uncoupled") ? uncoupledWorkingModes(model) : coupledWorkingModes(model);
  const std::string path = arguments.required("--plan");
  std::ifstream in = openRegularFile(path, "plan file", kMaxPlanFileBytes);
  const InputTrajectory trajectory = readPlanCsv(in, path, model, modes);
  // The plan's assembly mode: the sign of det J_DKP where it starts.
  const IkpResult start = solveIkp(model, trajectory.poses.front());
  if (!start.assembled) throw InputError(path + ":2: the first pose cannot be assembled");
  const DkpSingularity singularity =
      dkpSingularity(model, configurationOf(trajectory.poses.front(), start, modes[trajectory.modes.front()]));
  const std::int8_t sign = singularity.det > 0 ? 1 : -1;
  const Verification verification = verifyByDkpContinuation(model, trajectory, sign);
  std::cout << (verification.passed ? "passed: " : "FAILED: ") << verification.message << "\n";
  return verification.passed ? 0 : kNoVerifiedPlan;
}

}  // namespace maximal_workspace::cli
