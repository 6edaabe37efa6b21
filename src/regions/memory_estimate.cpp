// How much memory an analysis will take, before it takes it (docs/benchmarks.md has the
// estimates beside the measured peaks).

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include "regions/memory_estimate.h"

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "regions/analysis_data.h"
#include "workspace/classification.h"
#include "workspace/parallel.h"

namespace maximal_workspace {

namespace {

// Surfaces gain a little more than the square of the refinement per halving of the step:
// finer grids show small pieces of the singularity sets that coarser ones step over
// (docs/benchmarks.md: about 1/step^2.3 in three variables).
constexpr double kSurfaceExcess = 0.3;
constexpr int kCoarseFactor = 4;
constexpr double kProcessBytes = 8.0 * (1 << 20);  // libraries and stacks, before any analysis

struct Footprint {
  double code_pages = 0, label_pages = 0, points = 0, patterns = 0;
};

Footprint footprintOf(const AnalysisData& data) {
  Footprint footprint;
  footprint.code_pages = data.cells.codes.pageCount();
  footprint.patterns = static_cast<double>(data.cells.patterns.patterns.size());
  for (const LabelLayer& layer : data.regions.layers) footprint.label_pages += layer.pageCount();
  footprint.points = static_cast<double>(data.transitions.points.size());
  return footprint;
}

struct Estimate {
  double bytes = 0;
  bool lower_bound = false;
};

// What an analysis takes whatever its surfaces (`fixed`), and with every block mixed
// (`worst`, the ceiling).
struct Bounds {
  double fixed = 0, worst = 0;
};

Bounds boundsOf(const Grid& grid, const BlockLayout& layout, double modes, const AnalysisOptions& options) {
  const double blocks = static_cast<double>(layout.blockCount()), page = layout.cellsPerBlock();
  // Per block, whatever the surfaces: a code entry, a label entry per working mode, and
  // the labelling's block keys and nodes. Per thread, the classification's scratch cube
  // and the batch of a cube's shell (a pose, its position and a measure per working mode
  // a cell). And the process's own.
  const double side = topNodeSide(grid, layout), threads = resolveThreadCount(options.threads);
  const double shell = 2.0 * grid.dims() * std::pow(side, grid.dims() - 1);
  Bounds bounds;
  bounds.fixed = blocks * (4 + 4 * modes + 2 * (2 + 4)) +
                 threads * (std::pow(side, grid.dims()) * sizeof(CellCode) +
                            shell * (sizeof(Pose) + 4 * sizeof(double) + 8 * modes)) +
                 kProcessBytes;
  // Every block mixed: a code and a local component per cell and working mode, and a
  // transition point per cell of the box's surface at most.
  bounds.worst = bounds.fixed + blocks * page * (2 + modes + 4) +
                 2 * grid.dims() * std::pow(static_cast<double>(grid.cellCount()), 1.0 - 1.0 / grid.dims()) *
                     (sizeof(TransitionPoint) + 16);
  return bounds;
}

Estimate estimateBytes(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options, double budget) {
  const Grid grid(model, spec);
  const BlockLayout layout(grid);
  const double modes = static_cast<double>(analysedWorkingModes(model, options).size());
  const double blocks = static_cast<double>(layout.blockCount()), page = layout.cellsPerBlock();
  const auto [fixed, worst] = boundsOf(grid, layout, modes, options);
  if (fixed > budget) return {fixed, true};
  // An orientation set's angles are cut in a few cells already (a handful of tilt layers):
  // cut four times coarser they would not resolve the set, so only positions are.
  GridSpec coarse = spec;
  if (coarse.steps.size() == 1) coarse.steps.assign(grid.dims(), coarse.steps[0]);
  int coarsened = 0;
  for (int d = 0; d < grid.dims(); ++d) {
    if (grid.tiltTorsion() && isRotational(grid.variable(d))) continue;
    coarse.steps[d] *= kCoarseFactor;
    ++coarsened;
  }
  const double scale = std::pow(kCoarseFactor, coarsened - 1 + kSurfaceExcess);
  // Transition points lie on the workspace's boundary: a surface over x y z, but over an
  // orientation set the boundary at each of the set's angles, whose points grow nearly as
  // the positions' cells do (the long-crank hexapod's 64 working modes at 10 deg: x45 for
  // 64 times the cells, where a surface's growth is 16).
  const double point_scale = std::pow(kCoarseFactor, grid.tiltTorsion() ? coarsened : coarsened - 1);
  Estimate coarse_estimate;
  try {
    coarse_estimate = estimateBytes(model, coarse, options, budget);
  } catch (const InputError&) {
    return {worst};  // a step too coarse for its own grid: no pass to measure
  }
  // Refused anyway: the coarse pass alone would not fit.
  if (coarse_estimate.bytes > budget) {
    return {std::clamp(coarse_estimate.bytes * scale, fixed, worst), coarse_estimate.lower_bound};
  }
  AnalysisOptions coarse_options = options;
  coarse_options.progress = nullptr;
  Footprint footprint;
  try {
    footprint = footprintOf(*analyseFootprint(model, coarse, coarse_options));
  } catch (const InputError&) {
    return {worst};  // too coarse to hold the start
  }
  // Pages of mixed blocks, at most every block: a grid of a few angular cells has its
  // blocks mixed at the coarse step already (every block of the hexaglide's 10 deg set).
  // Code pages widen to four bytes a cell past 65,530 sign patterns, which grow as the
  // surfaces' crossings do.
  const double code_bytes = footprint.patterns * scale >= CodeMap::kNarrowCodes ? sizeof(CellCode) : sizeof(std::uint16_t);
  double bytes = fixed;
  bytes += std::min(footprint.code_pages * scale, blocks) * page * code_bytes;
  bytes += std::min(footprint.label_pages * scale, blocks * modes) * page;  // a byte a cell (LabelLayer)
  // Each point is found, then moved into the graph: twice, at the peak.
  bytes += footprint.points * point_scale * 2 * (sizeof(TransitionPoint) + 16);
  return {std::min(bytes, worst)};
}

}  // namespace

std::uint64_t physicalMemoryBytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page_size = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page_size > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page_size)
                                    : std::uint64_t{8} << 30;
}

std::uint64_t defaultMemoryBudget() { return physicalMemoryBytes() / 2; }

MemoryEstimate estimateAnalysisMemory(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  const double budget = static_cast<double>(options.memory_budget > 0 ? options.memory_budget : defaultMemoryBudget());
  const Estimate estimate = estimateBytes(model, spec, options, budget);
  return {static_cast<std::uint64_t>(std::min(estimate.bytes, 1.8e19)), estimate.lower_bound};
}

std::uint64_t analysisMemoryCeiling(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  const Grid grid(model, spec);
  const BlockLayout layout(grid);
  const double modes = static_cast<double>(analysedWorkingModes(model, options).size());
  return static_cast<std::uint64_t>(std::min(boundsOf(grid, layout, modes, options).worst, 1.8e19));
}

std::uint64_t estimateAnalysisBytes(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  return estimateAnalysisMemory(model, spec, options).bytes;
}

std::string overBudgetText(const MemoryEstimate& estimate, std::uint64_t budget) {
  return std::string("the analysis would need ") + (estimate.lower_bound ? "at least " : "about ") +
         byteText(static_cast<double>(estimate.bytes)) + " of memory, over the memory budget of " +
         byteText(static_cast<double>(budget));
}

}  // namespace maximal_workspace
