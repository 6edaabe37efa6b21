#include <cstdio>
#include <fstream>
#include <iostream>

#include "analysis_request.h"
#include "commands.h"
#include "maximal_workspace/io/plan_csv.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/planner/verification.h"

namespace maximal_workspace::cli {

namespace {

// Exit code of a plan that could not be made or did not verify: a result, not bad input.
constexpr int kNoVerifiedPlan = 3;

Pose poseOption(const Arguments& arguments, const std::string& option, const Pose& fallback) {
  if (!arguments.has(option)) return fallback;
  const std::vector<double> values = arguments.numbers(option);
  if (values.size() != 3) throw InputError("option " + option + ": expected x,y,z (m)");
  Pose pose = fallback;
  pose.position = Eigen::Vector3d(values[0], values[1], values[2]);
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

}  // namespace

int runPlan(const std::vector<std::string>& args) {
  const Arguments arguments(args,
                            analysisValueOptions({"--from", "--from-mode", "--goal", "--goal-mode", "--clearance",
                                                  "--max-velocity", "--max-acceleration", "--transition-cost", "--out"}),
                            analysisFlags({"--single-mode"}));
  AnalysisRequest request = analysisRequest(arguments);
  const RobotModel& model = request.model;
  const std::vector<WorkingMode> modes = analysedWorkingModes(model, request.options);
  PlanRequest plan_request;
  plan_request.start = poseOption(arguments, "--from", request.spec.start);
  plan_request.start_mode = arguments.has("--from-mode")
                                ? workingModeIndex(modes, arguments.required("--from-mode"), "option --from-mode")
                                : resolveStartMode(model, modes, plan_request.start, arguments.has("--from") ? "" : request.options.start_mode);
  if (!arguments.has("--goal")) throw InputError("missing required option --goal");
  plan_request.goal = poseOption(arguments, "--goal", request.spec.start);
  if (arguments.has("--goal-mode")) plan_request.goal_mode = workingModeIndex(modes, arguments.required("--goal-mode"), "option --goal-mode");
  plan_request.clearance = arguments.number("--clearance", kDefaultPlanClearance);
  if (plan_request.clearance < 0.0 || plan_request.clearance >= 1.0) throw InputError("option --clearance: must be in [0, 1)");
  plan_request.costs.transition = arguments.number("--transition-cost", plan_request.costs.transition);
  if (arguments.flag("--single-mode")) plan_request.allowed_modes = {plan_request.start_mode};
  const InputLimits limits{limitsOption(arguments, "--max-velocity", model, 1.0, 0.5),
                           limitsOption(arguments, "--max-acceleration", model, 2.0, 1.0)};

  ProgressBar bar;
  if (!arguments.flag("--quiet")) request.options.progress = [&bar](const AnalysisProgress& p) { bar.update(p); };
  const std::shared_ptr<const WorkspaceAnalysis> analysis = loadedWorkspace(arguments, request, "plan");
  bar.finish();

  const PathPlanner planner(model, *analysis);
  const Plan plan = planner.plan(plan_request);
  std::cout << "plan from " << vectorText(plan_request.start.position) << " in " << modes[plan_request.start_mode].name
            << " to " << vectorText(plan_request.goal.position) << " (step " << numberText(request.spec.steps[0]) << ")\n";
  if (!plan.success) {
    std::cout << "no plan: " << plan.message << "\n";
    return kNoVerifiedPlan;
  }
  const InputTrajectory trajectory = inputTrajectory(model, *analysis, plan, limits);
  std::printf("%s, %s, length %.4f m, min |measure| %.4g at %s, duration %.3f s, assembly mode %c\n",
              countText(plan.waypoints.size(), "waypoint").c_str(), countText(plan.transitions.size(), "transition").c_str(),
              plan.length, plan.min_measure,
              vectorText(plan.min_measure_at.position).c_str(), trajectory.time.back(), plan.sign > 0 ? '+' : '-');
  std::fflush(stdout);
  for (const PlanTransition& t : plan.transitions) {
    const std::string& from = modes[t.from_mode].name;
    const std::string& to = modes[t.to_mode].name;
    std::cout << "  transition at waypoint " << t.waypoint << " " << vectorText(plan.waypoints[t.waypoint].pose.position)
              << ": " << model.inputs[t.input].name << " " << from[t.input] << "->" << to[t.input] << " (" << from
              << " -> " << to << ")\n";
  }
  const Verification verification = verifyByDkpContinuation(model, trajectory, plan.sign);
  std::cout << "verification: " << (verification.passed ? "passed, " : "FAILED, ") << verification.message << "\n";
  const std::string out = arguments.optional("--out", "");
  if (!out.empty()) {
    writeFileAtomically(out, planCsv(trajectory, modes));
    std::cout << "written to " << out << " (" << trajectory.time.size() << " samples)\n";
  }
  return verification.passed ? 0 : kNoVerifiedPlan;
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
