// The memory estimate against the peak it predicts, at three steps: each analysis runs in
// a forked child, whose ru_maxrss is the peak of that analysis alone. Not run under the
// sanitizers (test/sanitized), whose shadow memory is no part of the estimate.

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>

#include <gtest/gtest.h>

#include "maximal_workspace/regions/workspace_analysis.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

// Peak resident bytes of a child that runs the analysis; 0 when it failed.
double peakOfAnalysis(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  std::fflush(nullptr);
  const pid_t child = fork();
  if (child == 0) {
    try {
      analyseWorkspace(model, spec, options);
    } catch (...) {
      _exit(1);
    }
    _exit(0);
  }
  int status = 0;
  rusage usage{};
  if (child < 0 || wait4(child, &status, 0, &usage) != child || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return 0;
  return usage.ru_maxrss * 1024.0;  // Linux: kilobytes
}

TEST(MemoryEstimate, IsWithinTwiceTheMeasuredPeak) {
  const RobotModel& model = test::deltaLike();
  for (double step : {0.01, 0.005, 0.003}) {
    const GridSpec spec = test::referenceGrid(model, step);
    AnalysisOptions options;
    options.memory_budget = ~std::uint64_t{0};
    const double estimate = static_cast<double>(estimateAnalysisBytes(model, spec, options));
    const double peak = peakOfAnalysis(model, spec, options);
    ASSERT_GT(peak, 0.0) << "the analysis at step " << step << " failed";
    std::printf("step %g m: estimate %.1f MiB, measured peak %.1f MiB\n", step, estimate / (1 << 20), peak / (1 << 20));
    EXPECT_LT(estimate, 2.0 * peak) << "step " << step;
    EXPECT_GT(estimate, 0.5 * peak) << "step " << step;
  }
}

}  // namespace
}  // namespace maximal_workspace
