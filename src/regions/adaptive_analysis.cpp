#include "maximal_workspace/regions/adaptive_analysis.h"

#include <algorithm>
#include <chrono>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/workspace/parallel.h"

namespace maximal_workspace {

namespace {

void summarise(AdaptiveAnalysis& analysis, int threads) {
  const AdaptiveWorkspace& workspace = analysis.workspace;
  const int modes = workspace.mode_count;
  auto labelsAt = [&](std::uint64_t block, int cell, std::int32_t* labels) {
    for (int m = 0; m < modes; ++m) labels[m] = analysis.regions.label(block, cell, m);
    return labels;
  };
  std::vector<std::int32_t> start_labels(modes);
  const AssemblyModeTally total(analysis.regions.regions, analysis.transitions.graph,
                                labelsAt(workspace.start_block, workspace.start_cell, start_labels.data()),
                                analysis.start_mode, modes);
  // Fixed chunks of blocks, each with its own copy of the tally, merged in order.
  const std::uint64_t blocks = workspace.layout.blockCount();
  const std::size_t chunks = static_cast<std::size_t>(std::min<std::uint64_t>(blocks, 64));
  std::vector<AssemblyModeTally> tallies(chunks, total);
  parallelFor(chunks, threads, [&](std::size_t begin, std::size_t end) {
    std::vector<std::int32_t> run(modes, kNoLabel), labels(modes);
    for (std::size_t chunk = begin; chunk < end; ++chunk) {
      AssemblyModeTally& tally = tallies[chunk];
      // Neighbouring cells mostly share their labels: runs of equal labels are added at once.
      std::uint64_t run_cells = 0;
      auto extend = [&](const std::int32_t* cell_labels, std::uint64_t cells) {
        if (!std::equal(run.begin(), run.end(), cell_labels)) {
          if (run_cells > 0) tally.add(run.data(), run_cells);
          run.assign(cell_labels, cell_labels + modes);
          run_cells = 0;
        }
        run_cells += cells;
      };
      for (std::uint64_t b = blocks * chunk / chunks; b < blocks * (chunk + 1) / chunks; ++b) {
        bool uniform = workspace.codes.uniform(b);
        for (int m = 0; m < modes && uniform; ++m) uniform = analysis.regions.layers[m].uniform(b);
        if (uniform) {
          if (codeInside(workspace.codes.uniformCode(b))) extend(labelsAt(b, 0, labels.data()), kBlockCells);
          continue;
        }
        for (int c = 0; c < kBlockCells; ++c) {
          if (codeInside(workspace.codes.code(b, c))) extend(labelsAt(b, c, labels.data()), 1);
        }
      }
      if (run_cells > 0) tally.add(run.data(), run_cells);
    }
  }, 1);
  AssemblyModeTally merged = total;
  for (const AssemblyModeTally& tally : tallies) merged.merge(tally);
  analysis.assembly_modes = merged.finish(analysis.grid.cellVolume());
}

}  // namespace

AdaptiveAnalysis analyseWorkspaceAdaptive(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  AdaptiveAnalysis analysis{Grid(model, spec)};
  const Grid& grid = analysis.grid;
  if (!grid.isSpatial() || grid.dims() != 3) throw InputError("adaptive refinement needs a grid over x y z");
  analysis.modes = analysedWorkingModes(model, options);
  analysis.start_mode = resolveStartMode(model, analysis.modes, grid.spec().start, options.start_mode);
  const PoseClassifier classifier(model, analysis.modes, grid.spec().start, true);

  StageSeconds& seconds = analysis.seconds;
  seconds.wave_front = stageSeconds([&] {
    analysis.workspace = classifyAdaptive(grid, classifier, AdaptiveOptions{options.singular_threshold, options.threads});
  });
  seconds.regions =
      stageSeconds([&] { analysis.regions = labelRegionsAdaptive(grid, analysis.workspace, options.debris, options.threads); });
  seconds.transitions = stageSeconds([&] {
    analysis.transitions =
        findTransitionsAdaptive(model, grid, classifier, analysis.workspace, analysis.regions, transitionOptions(options));
  });
  seconds.summary = stageSeconds([&] { summarise(analysis, options.threads); });
  seconds.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return analysis;
}

}  // namespace maximal_workspace
