#include "analysis_request.h"

#include <atomic>
#include <csignal>

#include <cstdio>
#include <iostream>

#include <unistd.h>

#include "maximal_workspace/io/checksum.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_cache.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace::cli {

namespace {

std::vector<OutputVariable> parseVariables(const std::string& text) {
  std::vector<OutputVariable> variables;
  for (const std::string& name : splitCommas(text)) {
    const auto variable = parseOutputVariable(name);
    if (!variable) throw InputError("option --vars: unknown variable '" + name + "' (expected x y z phi theta psi)");
    variables.push_back(*variable);
  }
  return variables;
}

GridSpec gridSpec(const Arguments& arguments, const RobotModel& model) {
  GridSpec spec;
  spec.variables = arguments.has("--vars") ? parseVariables(arguments.required("--vars")) : translationalVariables(model);
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
  if (arguments.has("--tilt-max") || arguments.has("--torsion") || arguments.has("--angle-step")) {
    OrientationSet set;
    set.tilt_max = arguments.number("--tilt-max", 0.0);
    if (!arguments.has("--torsion")) throw InputError("option --torsion: an orientation set needs its torsion range min,max");
    const std::vector<double> torsion = arguments.numbers("--torsion");
    if (torsion.size() != 2) throw InputError("option --torsion: expected min,max (rad)");
    set.torsion = {torsion[0], torsion[1]};
    set.angle_step = arguments.number("--angle-step", set.tilt_max / 6.0);
    addOrientationSet(model, set, &spec);
  }
  return spec;
}

}  // namespace

std::set<std::string> analysisValueOptions(std::set<std::string> more) {
  more.insert({"--robot", "--step", "--steps", "--vars", "--start", "--start-mode", "--bounds", "--memory-budget", "--margin",
               "--min-region-voxels", "--min-region-fraction", "--threads", "--cache", "--cache-bytes", "--modes",
               "--tilt-max", "--torsion", "--angle-step"});
  return more;
}

namespace {

std::atomic<bool> g_interrupted{false};

// The first Ctrl-C (or TERM) asks the analysis to stop, which then caches nothing; a
// second one ends mow at once.
extern "C" void onInterrupt(int signal) {
  if (g_interrupted.exchange(true)) {
    std::signal(signal, SIG_DFL);
    std::raise(signal);
  }
}

}  // namespace

CancelCheck interruptCheck() {
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
  return [] { return g_interrupted.load(); };
}

std::set<std::string> analysisFlags(std::set<std::string> more) {
  more.insert({"--uncoupled", "--quiet", "--force", "--no-cache"});
  return more;
}

AnalysisRequest analysisRequest(const Arguments& arguments) {
  AnalysisRequest request;
  const std::string robot_path = arguments.required("--robot");
  request.robot_text = readTextFile(robot_path, "robot file");
  request.model = parseRobotFile(request.robot_text, robot_path);
  request.source = RobotSource{robot_path, hex64(fnv1a64(request.robot_text))};
  AnalysisOptions& options = request.options;
  options.margin = arguments.number("--margin", options.margin);
  if (options.margin < 0.0 || options.margin >= 1.0) {
    throw InputError("option --margin: the dexterity margin on |measure| must be in [0, 1)");
  }
  options.debris.min_voxels = arguments.count("--min-region-voxels", options.debris.min_voxels, 1);
  options.debris.min_fraction = arguments.number("--min-region-fraction", options.debris.min_fraction);
  if (options.debris.min_fraction < 0.0 || options.debris.min_fraction >= 1.0) {
    throw InputError("option --min-region-fraction: must be in [0, 1)");
  }
  options.threads = static_cast<int>(arguments.count("--threads", 0, 0, kMaxThreads));
  options.memory_budget = arguments.bytes("--memory-budget", 0);
  options.uncoupled = arguments.flag("--uncoupled");
  options.cancelled = interruptCheck();
  if (arguments.has("--modes")) options.working_modes = splitCommas(arguments.required("--modes"));
  // Only `mow workspace` takes these; --conditioning-threshold implies --conditioning.
  if (arguments.flag("--conditioning") || arguments.has("--conditioning-threshold")) {
    ConditioningRequest conditioning;
    conditioning.threshold = arguments.number("--conditioning-threshold", conditioning.threshold);
    if (conditioning.threshold < 0.0 || conditioning.threshold > 1.0) {
      throw InputError("option --conditioning-threshold: the conditioning index lies in [0, 1], got " +
                       numberText(conditioning.threshold));
    }
    options.conditioning = conditioning;
  }
  static_cast<ResolvedWorkspaceRequest&>(request) = resolveAnalysis(
      request.model, request.robot_text, gridSpec(arguments, request.model), options, arguments.optional("--start-mode", ""));
  return request;
}

std::string gridPointText(const Grid& grid, const Pose& pose) {
  std::string text = "(";
  for (int d = 0; d < grid.dims(); ++d) text += (d ? ", " : "") + numberText(grid.coordinate(pose, d));
  return text + ")";
}

AnalysisRequest atMargin(const AnalysisRequest& request, double margin) {
  AnalysisRequest result = request;
  AnalysisOptions options = request.options;
  options.margin = margin;
  static_cast<ResolvedWorkspaceRequest&>(result) =
      resolveAnalysis(request.model, request.robot_text, request.spec, options, request.options.start_mode);
  return result;
}

ProgressBar::ProgressBar() : last_(std::chrono::steady_clock::now()), terminal_(::isatty(STDERR_FILENO) != 0) {}

void ProgressBar::update(const AnalysisProgress& progress) {
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < std::chrono::milliseconds(200)) return;
  if (!terminal_) {
    if (progress.stage == stage_ && now - last_ < std::chrono::seconds(10)) return;
    last_ = now;
    stage_ = progress.stage;
    std::fprintf(stderr, "%s: %.0f %%, %llu poses classified, %.1f s\n", progress.stage, 100 * progress.fraction,
                 static_cast<unsigned long long>(progress.evaluated), progress.elapsed_seconds);
    return;
  }
  last_ = now;
  const int filled = static_cast<int>(progress.fraction * 30);
  // Padded: a shorter stage name must cover the longer one drawn before it.
  std::fprintf(stderr, "\r%-14s [%s%s] %3.0f %%  %llu poses classified, %.1f s  ", progress.stage,
               std::string(filled, '#').c_str(), std::string(30 - filled, '.').c_str(), 100 * progress.fraction,
               static_cast<unsigned long long>(progress.evaluated), progress.elapsed_seconds);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

WorkspaceStore::Entry storedWorkspace(const Arguments& arguments, const AnalysisRequest& request,
                                      WorkspaceStore::Options options, const std::string& command) {
  WorkspaceStore store(arguments.optional("--cache", defaultCacheDirectory()),
                       arguments.bytes("--cache-bytes", WorkspaceStore::kDefaultCacheBytes));
  if (arguments.flag("--force")) options.policy = WorkspaceStore::Policy::Recompute;
  options.warn = [&command](const std::string& problem) {
    std::cerr << "mow " << command << ": warning: " << problem << "; computing again\n";
  };
  return store.obtain(request, request.model, request.source, options);
}

std::shared_ptr<const WorkspaceAnalysis> loadedWorkspace(const Arguments& arguments, const AnalysisRequest& request,
                                                         const std::string& command) {
  if (arguments.flag("--no-cache")) {
    return std::make_shared<const WorkspaceAnalysis>(analyseWorkspace(request.model, request.spec, request.options));
  }
  WorkspaceStore::Options options;
  options.load = true;
  return storedWorkspace(arguments, request, options, command).analysis;
}

}  // namespace maximal_workspace::cli
