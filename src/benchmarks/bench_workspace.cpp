// Wall time and peak memory of the whole pipeline (analyseWorkspace) over x y z from the
// robot's reference pose, default options, per grid step. Every run is a forked child,
// because ru_maxrss is a process's peak so far: only a fresh process gives the peak of one
// run. The figures printed are medians over the repetitions; the memory budget is lifted,
// so the estimate (estimate_MiB) can be set beside the peak it predicts.
//
// bench_workspace [--robot FILE] [--step S[,S...]]... [--repetitions N] [--threads N]
//                 [--half-width W] [--csv FILE]
//   --robot        default config/delta_like.yaml (run from the package root)
//   --step         metres; repeatable, or a comma list; default 0.01,0.005
//   --repetitions  runs per step, default 5
//   --threads      analysis threads, default 0 (every hardware thread)
//   --half-width   metres: a cube of this half-width about the reference pose instead of
//                  the robot's safety box, to follow the counts to finer steps
//   --csv          also write the medians there, one row per method and step
// Every row counts the regions, the IKP boundary faces and the transition points.

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {
namespace {

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "bench_workspace: %s\n", message.c_str());
  std::exit(1);
}

// What a child sends back through its pipe, and what the parent adds from wait4.
struct RunFigures {
  double voxels = 0, volume = 0;
  double box_cells = 0, evaluated = 0;  // cells in the box, poses classified
  double maximal_plus = 0, maximal_minus = 0;  // maximal operational workspace per assembly mode (m^3)
  double regions = 0, ikp_faces = 0, transition_points = 0;  // what the regions and transitions stages handle
  double held_mib = 0;      // what the analysis holds once made (memoryBytes)
  double estimate_mib = 0;  // estimateAnalysisBytes, made before the run
  StageSeconds seconds;     // analyseWorkspace's own stage timings
  double process_wall = 0;  // fork to exit: model already loaded, freeing memory included
  double cpu_seconds = 0;   // user + system, all threads of the child
  double peak_mib = 0;      // the child's ru_maxrss
};

struct Options {
  std::string robot = "config/delta_like.yaml";
  std::vector<double> steps;
  std::string csv;
  int repetitions = 5;
  int threads = 0;
  double half_width = 0;  // 0: the robot's safety box
};

double parseNumber(const std::string& flag, const std::string& text) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
  }
  if (used != text.size() || !(value > 0.0)) fail(flag + " needs a positive number, got '" + text + "'");
  return value;
}

Options parseOptions(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (i + 1 == argc) fail("unknown or incomplete option '" + flag + "'");
    const std::string value = argv[++i];
    if (flag == "--robot") {
      options.robot = value;
    } else if (flag == "--half-width") {
      options.half_width = parseNumber(flag, value);
    } else if (flag == "--csv") {
      options.csv = value;
    } else if (flag == "--step") {
      for (std::size_t start = 0, comma = 0; comma != std::string::npos; start = comma + 1) {
        comma = value.find(',', start);
        options.steps.push_back(parseNumber(flag, value.substr(start, comma - start)));
      }
    } else if (flag == "--repetitions" || flag == "--threads") {
      const double count = parseNumber(flag, value);
      if (count != static_cast<int>(count)) fail(flag + " needs a whole number, got '" + value + "'");
      (flag == "--threads" ? options.threads : options.repetitions) = static_cast<int>(count);
    } else {
      fail("unknown option '" + flag + "'");
    }
  }
  if (options.steps.empty()) options.steps = {0.01, 0.005};
  return options;
}

// Runs the pipeline in a child process and returns its figures.
RunFigures runInChild(const RobotModel& model, double step, const Options& options) {
  GridSpec spec;
  spec.variables = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
  spec.steps = {step};
  spec.start = model.reference.pose;
  if (options.half_width > 0) {
    for (int d = 0; d < 3; ++d) {
      const double centre = spec.start.position[d];
      spec.bounds.push_back({centre - options.half_width, centre + options.half_width});
    }
  }
  AnalysisOptions analysis_options;
  analysis_options.threads = options.threads;
  analysis_options.memory_budget = ~std::uint64_t{0};

  int pipe_ends[2];
  if (pipe(pipe_ends) != 0) fail("pipe failed");
  std::fflush(nullptr);  // the child must not inherit unflushed output
  const auto started = std::chrono::steady_clock::now();
  const pid_t child = fork();
  if (child < 0) fail("fork failed");
  if (child == 0) {
    close(pipe_ends[0]);
    try {
      RunFigures figures;
      figures.estimate_mib = static_cast<double>(estimateAnalysisBytes(model, spec, analysis_options)) / (1 << 20);
      const WorkspaceAnalysis analysis = analyseWorkspace(model, spec, analysis_options);
      figures.voxels = static_cast<double>(analysis.voxelCount());
      figures.evaluated = static_cast<double>(analysis.posesEvaluated());
      figures.box_cells = static_cast<double>(analysis.grid().cellCount());
      figures.volume = analysis.workspaceVolume();
      figures.maximal_plus = analysis.assemblyModes()[0].maximal_volume;
      figures.maximal_minus = analysis.assemblyModes()[1].maximal_volume;
      figures.seconds = analysis.seconds();
      figures.regions = static_cast<double>(analysis.regions().size());
      figures.ikp_faces = static_cast<double>(analysis.singularityCounts().ikp_faces);
      figures.transition_points = static_cast<double>(analysis.transitions().points.size());
      figures.held_mib = static_cast<double>(analysis.memoryBytes()) / (1 << 20);
      const bool sent = write(pipe_ends[1], &figures, sizeof figures) == static_cast<ssize_t>(sizeof figures);
      _exit(sent ? 0 : 1);  // _exit: no destructors or atexit handlers of the parent's copy
    } catch (const std::exception& error) {
      std::fprintf(stderr, "bench_workspace: step %g: %s\n", step, error.what());
      _exit(1);
    }
  }
  close(pipe_ends[1]);
  RunFigures figures;
  const bool received = read(pipe_ends[0], &figures, sizeof figures) == static_cast<ssize_t>(sizeof figures);
  close(pipe_ends[0]);
  int status = 0;
  rusage usage{};
  if (wait4(child, &status, 0, &usage) != child) fail("wait4 failed");
  figures.process_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!received || !WIFEXITED(status) || WEXITSTATUS(status) != 0) fail("the analysis at step " + std::to_string(step) + " failed");
  figures.cpu_seconds = usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  figures.peak_mib = usage.ru_maxrss / 1024.0;  // Linux: kilobytes
  return figures;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

int run(int argc, char** argv) {
  const Options options = parseOptions(argc, argv);
  const RobotModel model = loadRobotFile(options.robot);
  rusage parent{};
  getrusage(RUSAGE_SELF, &parent);
  // A child starts as a copy of this process, so its peak may include this much.
  std::printf("robot %s, grid x y z from the reference pose, default analysis options, %d threads; medians of %d runs, "
              "each in a fresh process (forked from a parent of peak RSS %.1f MiB)\n",
              model.name.c_str(), options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency()),
              options.repetitions, parent.ru_maxrss / 1024.0);
  if (options.half_width > 0) std::printf("box: a cube of half-width %g m about the reference pose\n", options.half_width);

  // One column per figure: its heading, decimals, and where it is in RunFigures.
  struct Column {
    const char* heading;
    int decimals;
    double RunFigures::*field = nullptr;
    double StageSeconds::*stage = nullptr;
  };
  const std::vector<Column> columns = {
      {"box_cells", 0, &RunFigures::box_cells},
      {"evaluated", 0, &RunFigures::evaluated},
      {"voxels", 0, &RunFigures::voxels},
      {"volume_m3", 5, &RunFigures::volume},
      {"maximal_p_m3", 5, &RunFigures::maximal_plus},
      {"maximal_n_m3", 5, &RunFigures::maximal_minus},
      {"classify_s", 3, nullptr, &StageSeconds::classification},
      {"regions_s", 3, nullptr, &StageSeconds::regions},
      {"singular_s", 3, nullptr, &StageSeconds::singularities},
      {"transitions_s", 3, nullptr, &StageSeconds::transitions},
      {"summary_s", 3, nullptr, &StageSeconds::summary},
      {"total_s", 3, nullptr, &StageSeconds::total},
      {"process_s", 3, &RunFigures::process_wall},
      {"cpu_s", 3, &RunFigures::cpu_seconds},
      {"peak_MiB", 1, &RunFigures::peak_mib},
      {"held_MiB", 1, &RunFigures::held_mib},
      {"estimate_MiB", 1, &RunFigures::estimate_mib},
      {"regions", 0, &RunFigures::regions},
      {"ikp_faces", 0, &RunFigures::ikp_faces},
      {"transition_points", 0, &RunFigures::transition_points},
  };
  constexpr int kWidth = 16;
  std::FILE* csv = nullptr;
  if (!options.csv.empty()) {
    csv = std::fopen(options.csv.c_str(), "w");
    if (csv == nullptr) fail("cannot write " + options.csv);
    std::fprintf(csv, "step_mm");
    for (const Column& column : columns) std::fprintf(csv, ",%s", column.heading);
    std::fprintf(csv, "\n");
  }
  std::printf("%8s", "step_mm");
  for (const Column& column : columns) std::printf(" %*s", kWidth, column.heading);
  std::printf("\n");

  for (double step : options.steps) {
    std::vector<RunFigures> runs;
    for (int r = 0; r < options.repetitions; ++r) {
      runs.push_back(runInChild(model, step, options));
      std::fprintf(stderr, "step %g run %d/%d: total %.3f s, peak %.1f MiB\n", step, r + 1, options.repetitions,
                   runs.back().seconds.total, runs.back().peak_mib);
    }
    std::printf("%8g", step * 1000);
    if (csv) std::fprintf(csv, "%g", step * 1000);
    for (const Column& column : columns) {
      std::vector<double> values;
      for (const RunFigures& figures : runs) values.push_back(column.field ? figures.*column.field : figures.seconds.*column.stage);
      std::printf(" %*.*f", kWidth, column.decimals, median(values));
      if (csv) std::fprintf(csv, ",%.*f", column.decimals, median(values));
    }
    std::printf("\n");
    if (csv) std::fprintf(csv, "\n");
    std::fflush(stdout);
  }
  if (csv && std::fclose(csv) != 0) fail("cannot write " + options.csv);
  return 0;
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  try {
    return maximal_workspace::run(argc, argv);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_workspace: %s\n", error.what());
    return 1;
  }
}
