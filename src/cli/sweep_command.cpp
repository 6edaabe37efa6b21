#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <optional>
#include <thread>
#include <utility>

#include <unistd.h>

#include "analysis_request.h"
#include "arguments.h"
#include "commands.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/sweep/sweep_runner.h"
#ifdef MOW_WITH_MPI
#include "sweep_mpi.h"
#endif

namespace maximal_workspace::cli {

namespace {

// More threads than this would only wait on one another.
constexpr std::uint64_t kMaxJobs = 1024;

std::string designText(const Study& study, const ResultRow& row) {
  std::string text = "design " + std::to_string(row.design) + ":";
  for (std::size_t p = 0; p < row.values.size(); ++p) text += " " + study.parameters()[p].column + " = " + row.values[p];
  return text;
}

void printReport(const Study& study, const std::string& out, const SweepReport& report) {
  std::cout << "results: " << out << ": " << countText(report.designs, "design") << ":";
  for (int s = 0; s < kDesignStatusCount; ++s) {
    std::cout << (s ? ", " : " ") << report.statuses[s] << " " << statusName(static_cast<DesignStatus>(s));
  }
  std::cout << "\nthis run: " << countText(report.run, "design") << " in " << numberText(std::round(report.seconds * 10) / 10)
            << " s";
  if (report.run > 0 && report.seconds > 0) {
    std::cout << " (" << numberText(std::round(600.0 * report.run / report.seconds) / 10) << " designs per minute)";
  }
  std::cout << "; " << report.recorded_before << " recorded before\n";
  if (report.best.empty()) return;
  std::cout << "best design per figure (the largest; for seconds the fewest):\n";
  for (const BestDesign& best : report.best) {
    std::printf("  %-28s %14s  %s\n", figureName(best.figure), numberText(best.value).c_str(),
                designText(study, best.row).c_str());
  }
  std::fflush(stdout);
}

// Where an MPI launcher (mpirun, srun) started this process: its rank among how many.
struct Launch {
  long rank = 0;
  long ranks = 1;  // 1: not started by a launcher, or as its only rank
};

Launch launchFromEnvironment() {
  // Open MPI's mpirun, then the PMI of MPICH's mpiexec and Slurm.
  for (const auto& [size_name, rank_name] : {std::pair{"OMPI_COMM_WORLD_SIZE", "OMPI_COMM_WORLD_RANK"},
                                             std::pair{"PMI_SIZE", "PMI_RANK"}}) {
    const char* size = std::getenv(size_name);
    const char* rank = std::getenv(rank_name);
    if (size) return Launch{rank ? std::atol(rank) : 0, std::max(1L, std::atol(size))};
  }
  return Launch{};
}

using Scheduler = std::function<std::optional<SweepReport>(const Study&, const SweepOptions&)>;

// The thread pool, or the MPI ranks when a launcher started more than one.
Scheduler scheduler(const Launch& launch) {
  if (launch.ranks == 1) return runStudy;
#ifdef MOW_WITH_MPI
  return runStudyOnRanks;
#else
  // Each rank would run the whole study on its own, all of them writing one file.
  throw InputError("started by mpirun as one of " + std::to_string(launch.ranks) +
                   " ranks, but this mow was built without MPI; install libopenmpi-dev and build again "
                   "(docs/sweep.md), or run mow sweep without mpirun");
#endif
}

int sweep(const std::vector<std::string>& args, const Launch& launch) {
  const Arguments arguments(args, {"--study", "--out", "--jobs"}, {"--quiet", "--force"});
  const std::string study_path = arguments.required("--study");
  const Scheduler schedule = scheduler(launch);
  const bool under_mpi = launch.ranks > 1;
  SweepOptions options;
  // Default: beside where mow runs, not beside the study (which may be in a source tree).
  options.out = arguments.optional("--out", std::filesystem::path(study_path).stem().string() + ".csv");
  // Under MPI, the threads of each rank's analysis: a launcher usually gives a rank a core.
  options.jobs = static_cast<int>(
      arguments.count("--jobs", under_mpi ? 1 : std::max(1u, std::thread::hardware_concurrency()), 1));
  if (options.jobs > static_cast<int>(kMaxJobs)) {
    throw InputError("option --jobs: at most " + std::to_string(kMaxJobs) +
                     (under_mpi ? " threads for each rank's design" : " designs at once"));
  }
  options.force = arguments.flag("--force");
  const Study study = loadStudy(study_path);
  const bool root = launch.rank == 0;  // under MPI only rank 0 writes, to the file and the terminal
  if (root) {
    std::cout << "study: " << study_path << " (study " << study.fingerprint() << "): "
              << countText(study.designCount(), "design") << " of " << study.robotPath() << ", step "
              << numberText(study.analysis().step) << ", start in " << study.analysis().start_mode << ", "
              << (under_mpi ? countText(static_cast<unsigned long long>(launch.ranks), "MPI rank") + " (" +
                              countText(static_cast<unsigned long long>(launch.ranks - 1), "worker") + ", " +
                              countText(static_cast<unsigned long long>(options.jobs), "thread") + " each)"
                        : countText(static_cast<unsigned long long>(options.jobs), "job"))
              << "\n"
              << std::flush;
  }
  if (root && !arguments.flag("--quiet")) {
    // Redrawn in place on a terminal; a line a design in a log.
    const bool terminal = ::isatty(STDERR_FILENO) != 0;
    const char* format = terminal ? "\rdesign %zu of %zu done (design %zu: %s)     " : "design %zu of %zu done (design %zu: %s)\n";
    options.progress = [terminal, format](const SweepProgress& progress) {
      std::fprintf(stderr, format, progress.finished, progress.to_run, progress.result->design,
                   statusName(progress.result->status));
      if (terminal && progress.finished == progress.to_run) std::fprintf(stderr, "\n");
    };
  }
  options.cancelled = interruptCheck();
  std::optional<SweepReport> report;
  try {
    report = schedule(study, options);
  } catch (const Cancelled&) {
    if (root) std::cerr << "\nmow sweep: interrupted; the rows written stay in " << options.out << " (run again to go on)\n";
    return 130;
  }
  if (report) printReport(study, options.out, *report);
  return 0;
}

}  // namespace

int runSweep(const std::vector<std::string>& args) {
  const Launch launch = launchFromEnvironment();
  try {
    return sweep(args, launch);
  } catch (const InputError&) {
    if (launch.rank > 0) return 2;  // every rank reads the same files: rank 0 says it once
    throw;
  }
}

}  // namespace maximal_workspace::cli
