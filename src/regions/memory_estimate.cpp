// How much memory an analysis will take, before it takes it (docs/benchmarks.md has the
// estimates beside the measured peaks).

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include "maximal_workspace/model/input_error.h"
#include "regions/analysis_data.h"

namespace maximal_workspace {

namespace {

// Surfaces gain a little more than the square of the refinement per halving of the step:
// finer grids show small pieces of the singularity sets that coarser ones step over
// (docs/benchmarks.md: about 1/step^2.3 in three variables).
constexpr double kSurfaceExcess = 0.3;
constexpr int kCoarseFactor = 4;

struct Footprint {
  double code_pages = 0, label_pages = 0, points = 0;
};

Footprint footprintOf(const AnalysisData& data) {
  Footprint footprint;
  footprint.code_pages = data.cells.codes.pageCount();
  for (const LabelLayer& layer : data.regions.layers) footprint.label_pages += layer.pageCount();
  footprint.points = static_cast<double>(data.transitions.points.size());
  return footprint;
}

}  // namespace

std::uint64_t defaultMemoryBudget() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page_size = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page_size > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page_size) / 2
                                    : std::uint64_t{4} << 30;
}

std::uint64_t estimateAnalysisBytes(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  const Grid grid(model, spec);
  const BlockLayout layout(grid);
  const double modes = static_cast<double>(analysedWorkingModes(model, options).size());
  const double blocks = static_cast<double>(layout.blockCount()), page = layout.cellsPerBlock();
  // Per block, whatever the surfaces: a code entry, a label entry per working mode, and
  // the labelling's block keys.
  double bytes = blocks * (4 + 4 * modes + 2 * 2);
  GridSpec coarse = spec;
  for (double& step : coarse.steps) step *= kCoarseFactor;
  AnalysisOptions coarse_options = options;
  coarse_options.progress = nullptr;
  coarse_options.memory_budget = ~std::uint64_t{0};
  Footprint footprint;
  try {
    footprint = footprintOf(AnalysisAccess::data(analyseWorkspace(model, coarse, coarse_options)));
  } catch (const InputError&) {
    // Too coarse to hold the start: every block may be mixed.
    return static_cast<std::uint64_t>(bytes + blocks * page * (2 + 4 * modes));
  }
  const double scale = std::pow(kCoarseFactor, grid.dims() - 1 + kSurfaceExcess);
  bytes += footprint.code_pages * scale * page * sizeof(CellCode);
  bytes += footprint.label_pages * scale * page * 4;
  // Each point is found, then copied into the graph: twice, at the peak.
  bytes += footprint.points * std::pow(kCoarseFactor, grid.dims() - 1) * 2 * (sizeof(TransitionPoint) + 16);
  return static_cast<std::uint64_t>(bytes);
}

}  // namespace maximal_workspace
