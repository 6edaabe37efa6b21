#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "arguments.h"
#include "commands.h"
#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_cache.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace::cli {

namespace {

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> items;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    items.push_back(text.substr(start, comma - start));
    if (comma == std::string::npos) return items;
    start = comma + 1;
  }
}

std::vector<OutputVariable> parseVariables(const std::string& text) {
  std::vector<OutputVariable> variables;
  for (const std::string& name : splitList(text)) {
    const auto variable = parseOutputVariable(name);
    if (!variable) throw InputError("option --vars: unknown variable '" + name + "' (expected x y z phi theta psi)");
    variables.push_back(*variable);
  }
  return variables;
}

// The robot's translational DOF: x y z for a spatial robot, x y for a planar one.
std::vector<OutputVariable> defaultVariables(const RobotModel& model) {
  std::vector<OutputVariable> variables;
  for (OutputVariable variable : model.output_variables) {
    if (!isRotational(variable)) variables.push_back(variable);
  }
  return variables;
}

GridSpec gridSpec(const Arguments& arguments, const RobotModel& model) {
  GridSpec spec;
  spec.variables = arguments.has("--vars") ? parseVariables(arguments.required("--vars")) : defaultVariables(model);
  spec.steps = arguments.has("--steps") ? arguments.numbers("--steps") : std::vector<double>{arguments.number("--step", 0.01)};
  spec.start = model.reference.pose;
  if (arguments.has("--start")) {
    const std::vector<double> start = arguments.numbers("--start");
    if (start.size() != 3 && start.size() != 6) throw InputError("option --start: expected x,y,z or x,y,z,phi,theta,psi");
    for (std::size_t k = 0; k < start.size(); ++k) spec.start.setValue(static_cast<OutputVariable>(k), start[k]);
  }
  if (arguments.has("--bounds")) {
    const std::vector<double> bounds = arguments.numbers("--bounds");
    if (bounds.size() != 2 * spec.variables.size()) {
      throw InputError("option --bounds: expected lower,upper for each of the " + std::to_string(spec.variables.size()) +
                       " grid variables, in --vars order");
    }
    for (std::size_t d = 0; d < spec.variables.size(); ++d) spec.bounds.push_back({bounds[2 * d], bounds[2 * d + 1]});
  }
  spec.voxel_budget = arguments.count("--budget", spec.voxel_budget, 1);
  return spec;
}

// A one-line bar on stderr, redrawn at most five times a second.
class ProgressBar {
 public:
  ProgressBar() : last_(std::chrono::steady_clock::now()) {}
  void update(const WaveFrontProgress& progress) {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(200)) return;
    last_ = now;
    const double fraction = progress.estimated_inside > 0
                                ? std::min(0.99, static_cast<double>(progress.inside) / progress.estimated_inside)
                                : 0.0;
    const int filled = static_cast<int>(fraction * 30);
    std::fprintf(stderr, "\rwave front [%s%s] %3.0f %%  %llu voxels, %llu poses tested, %.1f s", std::string(filled, '#').c_str(),
                 std::string(30 - filled, '.').c_str(), 100 * fraction, static_cast<unsigned long long>(progress.inside),
                 static_cast<unsigned long long>(progress.evaluated), progress.elapsed_seconds);
    drawn_ = true;
  }
  void finish() {
    if (drawn_) std::fprintf(stderr, "\n");
  }

 private:
  std::chrono::steady_clock::time_point last_;
  bool drawn_ = false;
};

std::string percent(double fraction) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f %%", 100.0 * fraction);
  return buffer;
}

// Printed from summary.json, so a cached and a fresh result read the same.
void printSummary(const nlohmann::json& summary) {
  const nlohmann::json& grid = summary["grid"];
  const std::string unit = " " + grid["volume_unit"].get<std::string>();
  std::cout << "robot: " << summary["robot"]["name"].get<std::string>() << " (" << summary["robot"]["file"].get<std::string>()
            << ")\ngrid:";
  for (const auto& variable : grid["variables"]) std::cout << " " << variable.get<std::string>();
  std::cout << ", step";
  for (const auto& step : grid["steps"]) std::cout << " " << numberText(step.get<double>());
  std::cout << ", box";
  for (std::size_t d = 0; d < grid["box_cells"].size(); ++d) std::cout << (d ? " x " : " ") << grid["box_cells"][d].get<long long>();
  std::cout << " = " << grid["cells"].get<unsigned long long>() << " cells\n";
  std::cout << "working modes: " << summary["working_modes"].size() << ", start in "
            << summary["start_mode"].get<std::string>() << " (det J_DKP by " << summary["det_method"].get<std::string>() << ")\n";
  const nlohmann::json& workspace = summary["workspace"];
  std::cout << "workspace: " << workspace["voxels"].get<unsigned long long>() << " voxels, volume "
            << numberText(workspace["volume"].get<double>()) << unit << " (" << workspace["poses_tested"].get<unsigned long long>()
            << " poses tested)\n";
  std::cout << "singularity map: " << summary["singularity_map"]["dkp_voxel_entries"].get<unsigned long long>()
            << " DKP-singular voxel entries, " << summary["singularity_map"]["ikp_boundary_faces"].get<unsigned long long>()
            << " IKP boundary faces\n";
  std::cout << "regions per working mode and sign: count [debris count] and volume (" << grid["volume_unit"].get<std::string>()
            << ") of the non-debris ones:\n";
  std::printf("  %-8s %22s %22s\n", "mode", "sign +", "sign -");
  for (const nlohmann::json& mode : summary["volumes_per_mode"]) {
    const nlohmann::json &plus = mode["positive"], &minus = mode["negative"];
    std::printf("  %-8s %4d [%3d] %12.6f %4d [%3d] %12.6f\n", mode["mode"].get<std::string>().c_str(), plus["regions"].get<int>(),
                plus["debris"].get<int>(), plus["volume"].get<double>(), minus["regions"].get<int>(),
                minus["debris"].get<int>(), minus["volume"].get<double>());
  }
  std::fflush(stdout);
  for (const nlohmann::json& am : summary["assembly_modes"]) {
    std::cout << "assembly mode " << (am["sign"].get<int>() > 0 ? "+" : "-") << ": maximal "
              << numberText(am["maximal_volume"].get<double>()) << unit << " (" << percent(am["maximal_fraction"].get<double>())
              << " of the workspace), traditional " << numberText(am["traditional_volume"].get<double>()) << unit << " ("
              << percent(am["traditional_fraction"].get<double>()) << "), reachable from the start "
              << numberText(am["reachable_volume"].get<double>()) << unit << " ("
              << percent(am["reachable_fraction"].get<double>()) << "); " << am["regions"].get<int>() << " regions, "
              << am["debris_regions"].get<int>() << " debris, " << am["transitions"].get<int>() << " transitions, "
              << am["components"].get<int>() << " connected groups\n";
  }
  std::cout << "transition points: " << summary["transition_points"].get<unsigned long long>() << "\n";
  std::cout << "octrees: " << summary["octrees"].get<std::string>() << "\n";
  const nlohmann::json& s = summary["seconds"];
  std::printf("seconds: wave front %.3f, singularities %.3f, regions %.3f, transitions %.3f, summary %.3f, total %.3f\n",
              s["wave_front"].get<double>(), s["singularities"].get<double>(), s["regions"].get<double>(),
              s["transitions"].get<double>(), s["summary"].get<double>(), s["total"].get<double>());
  std::fflush(stdout);
}

// ROS_HOME/maximal_workspace, else ~/.ros/maximal_workspace: shared with the nodes.
std::string defaultCacheDirectory() {
  if (const char* ros_home = std::getenv("ROS_HOME")) return std::string(ros_home) + "/maximal_workspace";
  const char* home = std::getenv("HOME");
  return std::string(home ? home : ".") + "/.ros/maximal_workspace";
}

// Copies the entry's files (not its manifest) into `out`, each through a rename.
std::vector<std::string> copyFiles(const std::string& from, const std::string& out) {
  std::error_code error;
  std::filesystem::create_directories(out, error);
  if (error || !std::filesystem::is_directory(out)) {
    throw InputError(out + ": cannot create output directory" + (error ? ": " + error.message() : ""));
  }
  std::vector<std::string> names;
  for (const auto& file : std::filesystem::directory_iterator(from)) {
    const std::string name = file.path().filename().string();
    if (name == "manifest.json") continue;
    writeFileAtomically(out + "/" + name, readTextFile(file.path().string(), "cache file"));
    names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

int runWorkspace(const std::vector<std::string>& args) {
  const Arguments arguments(args,
                            {"--robot", "--step", "--steps", "--vars", "--start", "--start-mode", "--bounds", "--budget",
                             "--threshold", "--min-region-voxels", "--min-region-fraction", "--threads", "--out",
                             "--cache", "--modes"},
                            {"--uncoupled", "--quiet", "--force", "--no-cache"});
  const std::string robot_path = arguments.required("--robot");
  const std::string robot_text = readTextFile(robot_path, "robot file");
  const RobotModel model = parseRobotFile(robot_text, robot_path);
  const RobotSource source{robot_path, hex64(fnv1a64(robot_text))};
  AnalysisOptions options;
  options.singular_threshold = arguments.number("--threshold", options.singular_threshold);
  if (options.singular_threshold < 0.0 || options.singular_threshold >= 1.0) {
    throw InputError("option --threshold: the singular band's |measure| threshold must be in [0, 1)");
  }
  options.debris.min_voxels = arguments.count("--min-region-voxels", options.debris.min_voxels, 1);
  options.debris.min_fraction = arguments.number("--min-region-fraction", options.debris.min_fraction);
  if (options.debris.min_fraction < 0.0 || options.debris.min_fraction >= 1.0) {
    throw InputError("option --min-region-fraction: must be in [0, 1)");
  }
  options.threads = static_cast<int>(arguments.count("--threads", 0, 0));
  options.uncoupled = arguments.flag("--uncoupled");
  if (arguments.has("--modes")) options.working_modes = splitList(arguments.required("--modes"));
  // Checked now (cheaply, before any allocation): a bad grid or start mode fails at once,
  // and the resolved start mode is part of the cache key.
  const Grid grid(model, gridSpec(arguments, model));
  const std::vector<WorkingMode> modes = analysedWorkingModes(model, options);
  options.start_mode = modes[resolveStartMode(model, modes, grid.spec().start, arguments.optional("--start-mode", ""))].name;
  ProgressBar bar;
  if (!arguments.flag("--quiet")) options.progress = [&bar](const WaveFrontProgress& p) { bar.update(p); };
  const std::string out = arguments.optional("--out", "");

  if (arguments.flag("--no-cache")) {
    const WorkspaceAnalysis analysis = analyseWorkspace(model, grid.spec(), options);
    bar.finish();
    if (!out.empty()) {
      std::filesystem::create_directories(out);
      writeWorkspaceFiles(model, source, options, analysis, out);
    }
    printSummary(workspaceSummary(model, source, options, analysis));
    return 0;
  }
  const WorkspaceCache cache(arguments.optional("--cache", defaultCacheDirectory()));
  const std::string key = workspaceCacheKey(robot_text, workspaceRequestText(grid, options));
  std::string problem;
  // Without --out only the summary is read: check just that file.
  const std::vector<std::string> needed = out.empty() ? std::vector<std::string>{"summary.json"} : std::vector<std::string>{};
  std::optional<std::string> entry = arguments.flag("--force") ? std::nullopt : cache.find(key, &problem, needed);
  if (!problem.empty()) std::cerr << "mow workspace: warning: " << problem << "; computing again\n";
  const bool from_cache = entry.has_value();
  if (!from_cache) {
    const WorkspaceAnalysis analysis = analyseWorkspace(model, grid.spec(), options);
    bar.finish();
    const std::string staging = cache.stagingDirectory(key);
    writeWorkspaceFiles(model, source, options, analysis, staging);
    entry = cache.commit(key, staging);
  }
  printSummary(nlohmann::json::parse(readTextFile(*entry + "/summary.json", "cached summary")));
  std::cout << (from_cache ? "from cache: " : "cached in: ") << *entry << "\n";
  if (!out.empty()) {
    const std::vector<std::string> names = copyFiles(*entry, out);
    std::cout << "written to " << out << ":";
    for (const std::string& name : names) std::cout << " " << name;
    std::cout << "\n";
  }
  return 0;
}

}  // namespace maximal_workspace::cli
