#pragma once
// estimateAnalysisBytes, and whether its figure is only a lower bound: with the per-block
// and per-thread part alone over the budget the coarse pass is not run, so the refusal
// says "at least" rather than "about".

#include <cstdint>
#include <string>

#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

struct MemoryEstimate {
  std::uint64_t bytes = 0;
  bool lower_bound = false;
};

MemoryEstimate estimateAnalysisMemory(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options);
// The every-block-mixed bound that caps the estimates, without their coarse pass: a budget
// over it admits an analysis whatever its estimate.
std::uint64_t analysisMemoryCeiling(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options);

// "the analysis would need about 2.66 GiB of memory, over the memory budget of 1 GiB"
// ("at least" for a lower bound).
std::string overBudgetText(const MemoryEstimate& estimate, std::uint64_t budget);

}  // namespace maximal_workspace
