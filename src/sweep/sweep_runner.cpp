#include "maximal_workspace/sweep/sweep_runner.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mutex>
#include <thread>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "regions/analysis_admission.h"
#include "regions/memory_estimate.h"
#include "sweep/design_request.h"
#include "workspace/parallel.h"

namespace maximal_workspace {

namespace {

double figureValue(Figure figure, const WorkspaceAnalysis& analysis) {
  const AssemblyModeSummary& plus = analysis.assemblyModes()[0];
  const AssemblyModeSummary& minus = analysis.assemblyModes()[1];
  switch (figure) {
    case Figure::WorkspaceVolume: return analysis.workspaceVolume();
    case Figure::MaximalVolumePositive: return plus.maximal_volume;
    case Figure::MaximalVolumeNegative: return minus.maximal_volume;
    case Figure::TraditionalVolumePositive: return plus.traditional_volume;
    case Figure::TraditionalVolumeNegative: return minus.traditional_volume;
    case Figure::ReachableVolumePositive: return plus.reachable_volume;
    case Figure::ReachableVolumeNegative: return minus.reachable_volume;
    case Figure::RegionsPositive: return plus.regions;
    case Figure::RegionsNegative: return minus.regions;
    case Figure::TransitionsPositive: return plus.transitions;
    case Figure::TransitionsNegative: return minus.transitions;
    case Figure::Seconds: return analysis.seconds().total;
  }
  return std::nan("");
}

DesignResult ended(std::size_t design, DesignStatus status, const std::string& reason) {
  return DesignResult{design, status, {}, reason};
}

// Messages of InputError are the project's own, with what came from input already cut
// (escapedText): kept whole, they say which field and why. Any other exception's text is
// of unknown length.
DesignResult failed(std::size_t design, const std::exception& error) {
  return ended(design, DesignStatus::Failed, clippedText(error.what()));
}

SweepReport summarise(const Study& study, const std::vector<ResultRow>& rows) {
  SweepReport report;
  report.designs = study.designCount();
  for (const ResultRow& row : rows) ++report.statuses[static_cast<int>(row.status)];
  for (std::size_t f = 0; f < study.figures().size(); ++f) {
    const Figure figure = study.figures()[f];
    const ResultRow* best = nullptr;
    for (const ResultRow& row : rows) {
      const double value = row.figures[f];
      if (row.status != DesignStatus::Ok || !std::isfinite(value)) continue;
      const bool better = !best || (largerIsBetter(figure) ? value > best->figures[f] : value < best->figures[f]) ||
                          (value == best->figures[f] && row.design < best->design);
      if (better) best = &row;
    }
    if (best) report.best.push_back(BestDesign{figure, best->figures[f], *best});
  }
  return report;
}

}  // namespace

std::uint64_t studyMemoryBudget(const Study& study) {
  return study.analysis().memory_budget > 0 ? study.analysis().memory_budget : defaultMemoryBudget();
}

PreparedDesign prepareDesign(const Study& study, std::size_t design, const DesignRunOptions& options) {
  PreparedDesign prepared;
  prepared.design = design;
  const std::string text = study.designRobotText(design);
  try {
    prepared.model = parseRobotFile(text, study.robotPath());
  } catch (const InputError& error) {
    prepared.result = ended(design, DesignStatus::InvalidRobot, error.what());
    return prepared;
  }
  AnalysisOptions analysis = designOptions(study.analysis());
  analysis.threads = options.threads;
  analysis.cancelled = options.cancelled;
  MemoryEstimate estimate;
  try {
    prepared.request = resolveAnalysis(prepared.model, text, designGrid(prepared.model, study.analysis()), analysis,
                                       study.analysis().start_mode);
    estimate = estimateAnalysisMemory(prepared.model, prepared.request.spec, prepared.request.options);
    prepared.estimate_bytes = estimate.bytes;
  } catch (const Cancelled&) {
    throw;
  } catch (const InputError& error) {
    prepared.result = ended(design, DesignStatus::NoWorkspace, error.what());
    return prepared;
  } catch (const std::exception& error) {
    prepared.result = failed(design, error);
    return prepared;
  }
  const std::uint64_t budget = studyMemoryBudget(study);
  if (prepared.estimate_bytes > budget) {
    prepared.result = ended(design, DesignStatus::OverBudget, overBudgetText(estimate, budget));
  }
  return prepared;
}

DesignResult analyseDesign(const Study& study, const PreparedDesign& prepared, const DesignRunOptions& options) {
  if (prepared.result) return *prepared.result;
  AnalysisOptions analysis = prepared.request.options;
  analysis.threads = options.threads;
  analysis.cancelled = options.cancelled;
  analysis.memory_budget = ~std::uint64_t{0};  // admitted on its estimate already
  try {
    const WorkspaceAnalysis result = analyseWorkspace(prepared.model, prepared.request.spec, analysis);
    DesignResult row{prepared.design, DesignStatus::Ok, {}, ""};
    for (const Figure figure : study.figures()) row.figures.push_back(figureValue(figure, result));
    return row;
  } catch (const Cancelled&) {
    throw;
  } catch (const InputError& error) {
    return ended(prepared.design, DesignStatus::NoWorkspace, error.what());
  } catch (const std::exception& error) {
    return failed(prepared.design, error);
  }
}

DesignResult runDesign(const Study& study, std::size_t design, const DesignRunOptions& options) {
  return analyseDesign(study, prepareDesign(study, design, options), options);
}

std::vector<std::size_t> designsToRun(const Study& study, const ResultsFile& results) {
  std::vector<std::size_t> to_run;
  for (std::size_t design = 0; design < study.designCount(); ++design) {
    if (!results.recorded(design)) to_run.push_back(design);
  }
  return to_run;
}

// A study none of whose designs fits is refused before anything runs; the designs
// prepared on the way are kept for the run.
std::vector<PreparedDesign> prepareUntilOneFits(const Study& study, const std::vector<std::size_t>& to_run,
                                                const DesignRunOptions& options, const ResultsFile& results) {
  std::vector<PreparedDesign> ahead;
  std::uint64_t smallest = ~std::uint64_t{0};
  bool fits = to_run.empty();
  while (!fits && ahead.size() < to_run.size()) {
    throwIfCancelled(options.cancelled);
    ahead.push_back(prepareDesign(study, to_run[ahead.size()], options));
    const PreparedDesign& prepared = ahead.back();
    if (prepared.result && prepared.result->status == DesignStatus::OverBudget) {
      smallest = std::min(smallest, prepared.estimate_bytes);
    }
    fits = !prepared.result;
  }
  if (!fits && smallest != ~std::uint64_t{0}) {
    if (results.created() && results.rows().empty()) std::remove(results.path().c_str());
    throw InputError(study.path() + ": every design to run is over the memory budget of " +
                     byteText(static_cast<double>(studyMemoryBudget(study))) + " (the smallest estimate is " +
                     byteText(static_cast<double>(smallest)) + "); give a larger analysis.memory_budget or step");
  }
  return ahead;
}

SweepReport sweepReport(const Study& study, const ResultsFile& results, std::size_t recorded_before,
                        std::chrono::steady_clock::time_point started) {
  SweepReport report = summarise(study, results.rows());
  report.recorded_before = recorded_before;
  report.run = results.rows().size() - recorded_before;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report;
}

SweepReport runStudy(const Study& study, const SweepOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  ResultsFile results(options.out, study, options.force);
  const std::vector<std::size_t> to_run = designsToRun(study, results);
  const std::size_t recorded_before = study.designCount() - to_run.size();
  const int jobs = resolveThreadCount(options.jobs);
  DesignRunOptions run;
  run.threads = jobs > 1 ? 1 : 0;
  run.cancelled = options.cancelled;
  std::vector<PreparedDesign> ahead = prepareUntilOneFits(study, to_run, run, results);

  // prepareDesign has set aside the designs that cannot fit alone.
  AnalysisAdmission admission(studyMemoryBudget(study));
  std::atomic<std::size_t> next{0}, finished{0};
  std::atomic<bool> stop{false};
  std::mutex progress_mutex;
  std::exception_ptr first_error;
  const auto stopping = [&] { return stop.load() || (options.cancelled && options.cancelled()); };
  const auto work = [&] {
    try {
      for (std::size_t k = next++; k < to_run.size() && !stop.load(); k = next++) {
        throwIfCancelled(options.cancelled);
        const PreparedDesign prepared = k < ahead.size() ? std::move(ahead[k]) : prepareDesign(study, to_run[k], run);
        DesignResult result;
        if (prepared.result) {
          result = *prepared.result;
        } else {
          const AnalysisAdmission::Ticket admitted = admission.enter(prepared.estimate_bytes, stopping);
          if (!admitted) break;
          result = analyseDesign(study, prepared, run);
        }
        results.append(result);
        if (options.progress) {
          std::lock_guard<std::mutex> lock(progress_mutex);
          options.progress(SweepProgress{++finished, to_run.size(), &result});
        }
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      if (!first_error) first_error = std::current_exception();
      stop = true;
    }
  };
  std::vector<std::thread> workers;
  const std::size_t count = std::min<std::size_t>(static_cast<std::size_t>(jobs), to_run.size());
  for (std::size_t w = 1; w < count; ++w) workers.emplace_back(work);
  if (count > 0) work();  // this thread is one of the workers
  for (std::thread& worker : workers) worker.join();
  if (first_error) std::rethrow_exception(first_error);
  // Workers stop early, having thrown nothing, when Ctrl-C comes while they wait for memory.
  if (results.rows().size() - recorded_before < to_run.size()) throwIfCancelled(options.cancelled);

  return sweepReport(study, results, recorded_before, started);
}

}  // namespace maximal_workspace
