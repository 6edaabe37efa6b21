#pragma once
// Running a study (mow sweep, docs/sweep.md). One design gives one row (runDesign, in two
// steps so that a scheduler can weigh a design's memory before it runs it); runStudy runs
// the designs a results file does not hold yet, concurrently within a memory budget, and
// appends their rows as they finish.

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/sweep/results_file.h"
#include "maximal_workspace/sweep/study.h"
#include "maximal_workspace/workspace/cancellation.h"

namespace maximal_workspace {

struct DesignRunOptions {
  int threads = 0;  // of the design's analysis; 0: every core
  CancelCheck cancelled;
};

// The bytes a design may take: the study's memory_budget, or half the machine's memory.
std::uint64_t studyMemoryBudget(const Study& study);

// A design up to its analysis: its robot loaded, its request resolved and the bytes its
// analysis will need estimated (estimateAnalysisBytes); or, when it ends there, its result
// (invalid_robot, no_workspace, over_budget).
struct PreparedDesign {
  std::size_t design = 0;
  std::optional<DesignResult> result;
  RobotModel model;
  ResolvedWorkspaceRequest request;
  std::uint64_t estimate_bytes = 0;
};

// Both throw Cancelled when `options.cancelled` says so; any other failure is the result.
PreparedDesign prepareDesign(const Study& study, std::size_t design, const DesignRunOptions& options);
// The analysis of a prepared design (analyseWorkspace, no cache), already admitted: its
// budget is not checked again. The figures are the analysis's own.
DesignResult analyseDesign(const Study& study, const PreparedDesign& prepared, const DesignRunOptions& options);
// One design, one row: prepareDesign, then analyseDesign unless that ended it.
DesignResult runDesign(const Study& study, std::size_t design, const DesignRunOptions& options);

struct SweepProgress {
  std::size_t finished = 0;  // designs of this run finished, this one included
  std::size_t to_run = 0;
  const DesignResult* result = nullptr;
};

struct SweepOptions {
  std::string out;  // the results file
  int jobs = 0;     // designs at once; 0: every core. Above 1 each analysis takes one thread.
  bool force = false;
  CancelCheck cancelled;
  std::function<void(const SweepProgress&)> progress;  // after each row, one call at a time
};

// The best ok row of a figure: the largest, or the fewest seconds; the first design of a tie.
struct BestDesign {
  Figure figure = Figure::WorkspaceVolume;
  double value = 0.0;
  ResultRow row;
};

struct SweepReport {
  std::size_t designs = 0;          // in the study
  std::size_t recorded_before = 0;  // rows the results file held already
  std::size_t run = 0;              // designs this run added
  double seconds = 0.0;             // of this run
  std::array<std::size_t, kDesignStatusCount> statuses{};  // rows per status, the whole file
  std::vector<BestDesign> best;     // per figure of the study with an ok row, in its order
};

// What every scheduler of a study shares (runStudy's threads; mow sweep's MPI ranks).
// The designs `results` does not hold yet, in index order.
std::vector<std::size_t> designsToRun(const Study& study, const ResultsFile& results);
// Prepares the designs of `to_run` in order until one fits the budget, and returns those
// prepared. Throws InputError when none fits and some are over the budget (the smallest
// estimate in the message), having removed the results file if this run created it empty.
std::vector<PreparedDesign> prepareUntilOneFits(const Study& study, const std::vector<std::size_t>& to_run,
                                                const DesignRunOptions& options, const ResultsFile& results);
// The report on the whole results file, of which `recorded_before` rows were there when
// this run began at `started`.
SweepReport sweepReport(const Study& study, const ResultsFile& results, std::size_t recorded_before,
                        std::chrono::steady_clock::time_point started);

// The rows the file does not hold yet, `jobs` designs at once, none started while the
// estimates of those running and its own would together exceed the budget. Throws
// InputError for a results file of another study, and before running anything when every
// design to run is over the budget (the smallest estimate in the message); Cancelled on
// request, the rows written staying.
SweepReport runStudy(const Study& study, const SweepOptions& options);

}  // namespace maximal_workspace
