// Plan latency on cached data (issue 5): the delta-like robot from its reference
// configuration to a fixed set of goals, at each step given. The analysis and the planner's
// set-up are done first and not timed; each goal is then planned, and separately planned,
// timed as an actuator trajectory and verified by DKP continuation (what /plan_path does).
// Goals: voxels drawn with a fixed seed among those the start can reach through
// transitions, at least 0.2 m from it. Prints medians, minima and maxima.
//
//   bench_planner [--step 0.01,0.005] [--goals 20] [--robot FILE]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/planner/path_planner.h"
#include "maximal_workspace/planner/trajectory.h"
#include "maximal_workspace/planner/verification.h"

namespace maximal_workspace {
namespace {

using Clock = std::chrono::steady_clock;

double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Spread {
  double median, min, max;
};

Spread spread(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  const double median = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  return {median, values.front(), values.back()};
}

std::vector<double> numbers(const std::string& text) {
  std::vector<double> values;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    values.push_back(std::stod(text.substr(start, comma - start)));
    if (comma == std::string::npos) return values;
    start = comma + 1;
  }
}

int run(int argc, char** argv) {
  std::vector<double> steps = {0.01, 0.005};
  int goals = 20;
  std::string robot = "config/delta_like.yaml";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string option = argv[i];
    if (option == "--step") steps = numbers(argv[i + 1]);
    else if (option == "--goals") goals = std::stoi(argv[i + 1]);
    else if (option == "--robot") robot = argv[i + 1];
  }
  const RobotModel model = loadRobotFile(robot);
  const InputLimits limits{{1.0, 0.5, 0.5}, {2.0, 1.0, 1.0}};
  std::printf("robot %s, start: reference pose in its reference working mode, %d goals per step\n", model.name.c_str(), goals);
  std::printf("%8s %10s %14s %30s %30s %10s %12s\n", "step_mm", "setup_ms", "planned", "plan_ms median [min, max]",
              "+trajectory+verify_ms", "verified", "transitions");
  for (double step : steps) {
    GridSpec spec;
    spec.variables = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
    spec.steps = {step};
    spec.start = model.reference.pose;
    const AnalysisOptions options;
    const WorkspaceAnalysis analysis = analyseWorkspace(model, spec, options);
    Clock::time_point started = Clock::now();
    const PathPlanner planner(model, analysis);
    const double setup = millisecondsSince(started);
    // The goals: reachable through transitions from the start region, sampled over the box.
    const Grid& grid = analysis.grid();
    std::uint64_t start_cell = 0;
    grid.cellOf(model.reference.pose, &start_cell);
    const std::int32_t start_region = analysis.label(start_cell, analysis.startMode());
    const std::vector<Region>& regions = analysis.regions();
    const std::vector<std::int32_t>& component = analysis.transitions().component;
    const std::int8_t sign = regions[start_region].sign;
    std::vector<std::uint64_t> reachable;
    const std::uint64_t stride = std::max<std::uint64_t>(1, grid.cellCount() / 200000) | 1;
    for (std::uint64_t cell = 0; cell < grid.cellCount(); cell += stride) {
      for (int m = 0; m < static_cast<int>(analysis.modes().size()); ++m) {
        const std::int32_t label = analysis.label(cell, m);
        if (label >= 0 && regions[label].sign == sign && !regions[label].debris &&
            component[label] == component[start_region] &&
            (grid.pose(cell).position - model.reference.pose.position).norm() > 0.2) {
          reachable.push_back(cell);
          break;
        }
      }
    }
    std::mt19937 random(5);
    std::vector<double> plan_ms, full_ms;
    int planned = 0, verified = 0, transitions = 0;
    for (int g = 0; g < goals; ++g) {
      PlanRequest request;
      request.start = model.reference.pose;
      request.start_mode = analysis.startMode();
      request.goal = grid.pose(reachable[random() % reachable.size()]);
      request.heuristic_weight = 1.5;
      started = Clock::now();
      const Plan plan = planner.plan(request);
      plan_ms.push_back(millisecondsSince(started));
      started = Clock::now();
      const Plan again = planner.plan(request);
      if (!again.success) continue;
      const InputTrajectory trajectory = inputTrajectory(model, analysis, again, limits);
      const Verification verification = verifyByDkpContinuation(model, trajectory, again.sign);
      full_ms.push_back(millisecondsSince(started));
      planned += plan.success;
      verified += verification.passed;
      transitions += static_cast<int>(plan.transitions.size());
    }
    const Spread p = spread(plan_ms), f = spread(full_ms.empty() ? std::vector<double>{0.0} : full_ms);
    char plan_text[64], full_text[64];
    std::snprintf(plan_text, sizeof plan_text, "%.1f [%.1f, %.1f]", p.median, p.min, p.max);
    std::snprintf(full_text, sizeof full_text, "%.1f [%.1f, %.1f]", f.median, f.min, f.max);
    std::printf("%8g %10.1f %11d/%-2d %30s %30s %7d/%-2d %12d\n", step * 1000, setup, planned, goals, plan_text, full_text,
                verified, planned, transitions);
  }
  return 0;
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  try {
    return maximal_workspace::run(argc, argv);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_planner: %s\n", error.what());
    return 1;
  }
}
