// Per assembly mode figures: region and transition counts, the traditional region, and
// the maximal and reachable volumes tallied over the blocks.

#include <algorithm>
#include <atomic>
#include <mutex>

#include "regions/analysis_data.h"
#include "workspace/parallel.h"

namespace maximal_workspace {

namespace {

// The counts and the traditional region at construction, volumes from add() over every
// workspace cell.
class AssemblyModeTally {
 public:
  // start_labels[m]: the region of working mode m at the start (or -1).
  AssemblyModeTally(const std::vector<Region>& regions, const TransitionGraph& graph, const std::int32_t* start_labels,
                    int start_mode, int mode_count)
      : regions_(regions), graph_(graph), mode_count_(mode_count) {
    for (int a = 0; a < 2; ++a) {
      summaries_[a].sign = a == 0 ? 1 : -1;
      countRegions(summaries_[a]);
      summaries_[a].traditional_region = traditionalRegion(summaries_[a].sign, start_labels, start_mode);
      if (summaries_[a].traditional_region >= 0) {
        summaries_[a].traditional_volume = regions[summaries_[a].traditional_region].volume;
      }
      reachable_component_[a] =
          summaries_[a].traditional_region >= 0 ? graph.component[summaries_[a].traditional_region] : -1;
    }
  }

  // `voxels` cells that all have labels[m] in working mode m.
  void add(const std::int32_t* labels, std::uint64_t voxels) {
    for (int a = 0; a < 2; ++a) {
      bool in_maximal = false, in_reachable = false;
      for (int m = 0; m < mode_count_; ++m) {
        const std::int32_t label = labels[m];
        if (label < 0 || regions_[label].debris) continue;
        in_maximal = in_maximal || regions_[label].sign == summaries_[a].sign;
        in_reachable = in_reachable || graph_.component[label] == reachable_component_[a];
      }
      summaries_[a].maximal_voxels += in_maximal ? voxels : 0;
      summaries_[a].reachable_voxels += in_reachable ? voxels : 0;
    }
  }
  // Adds the cells another tally (a copy of this one, before any add) counted.
  void merge(const AssemblyModeTally& other) {
    for (int a = 0; a < 2; ++a) {
      summaries_[a].maximal_voxels += other.summaries_[a].maximal_voxels;
      summaries_[a].reachable_voxels += other.summaries_[a].reachable_voxels;
    }
  }
  std::array<AssemblyModeSummary, 2> finish(double cell_volume) const {
    std::array<AssemblyModeSummary, 2> result = summaries_;
    for (AssemblyModeSummary& summary : result) {
      summary.maximal_volume = static_cast<double>(summary.maximal_voxels) * cell_volume;
      summary.reachable_volume = static_cast<double>(summary.reachable_voxels) * cell_volume;
    }
    return result;
  }

 private:
  void countRegions(AssemblyModeSummary& summary) const {
    std::vector<bool> component_seen;
    for (const Region& region : regions_) {
      if (region.sign != summary.sign) continue;
      (region.debris ? summary.debris_regions : summary.regions)++;
      const std::int32_t component = graph_.component[region.id];
      if (component >= static_cast<std::int32_t>(component_seen.size())) component_seen.resize(component + 1, false);
      if (!region.debris && !component_seen[component]) {
        component_seen[component] = true;
        summary.components++;
      }
    }
    for (const Transition& transition : graph_.transitions) {
      summary.transitions += transition.sign == summary.sign && !regions_[transition.from_region].debris &&
                             !regions_[transition.to_region].debris;
    }
  }
  std::int32_t traditionalRegion(std::int8_t sign, const std::int32_t* start_labels, int start_mode) const {
    const std::int32_t own = start_labels[start_mode];
    if (own >= 0 && regions_[own].sign == sign) return own;
    std::int32_t best = -1;
    for (int m = 0; m < mode_count_; ++m) {
      const std::int32_t label = start_labels[m];
      if (label >= 0 && regions_[label].sign == sign && (best < 0 || regions_[label].voxels > regions_[best].voxels)) {
        best = label;
      }
    }
    return best;
  }

  const std::vector<Region>& regions_;
  const TransitionGraph& graph_;
  int mode_count_;
  std::array<AssemblyModeSummary, 2> summaries_;
  std::array<std::int32_t, 2> reachable_component_{};
};

// Adds the workspace cells of blocks [first, end) to a tally, in runs of equal labels:
// neighbouring cells mostly share them.
void tallyBlocks(const AnalysisData& data, std::uint64_t first, std::uint64_t end, AssemblyModeTally& tally) {
  const WorkspaceCells& cells = data.cells;
  const int modes = static_cast<int>(data.modes.size()), per_block = cells.layout.cellsPerBlock();
  std::vector<std::int32_t> run(modes, kNoLabel), labels(modes);
  std::vector<LabelLayer::LocalPage> pages(modes);  // local components where a layer is not uniform
  std::vector<const std::int32_t*> local_labels(modes);
  std::uint64_t run_cells = 0;
  auto extend = [&](std::uint64_t count) {
    if (!std::equal(run.begin(), run.end(), labels.begin())) {
      if (run_cells > 0) tally.add(run.data(), run_cells);
      run = labels;
      run_cells = 0;
    }
    run_cells += count;
  };
  for (std::uint64_t b = first; b < end; ++b) {
    bool uniform = cells.codes.uniform(b);
    for (int m = 0; m < modes; ++m) {
      const LabelLayer& layer = data.regions.layers[m];
      local_labels[m] = layer.uniform(b) ? nullptr : layer.localLabels(b);
      if (local_labels[m] != nullptr) pages[m] = layer.localPage(b);
      labels[m] = layer.label(b, 0);
      uniform = uniform && local_labels[m] == nullptr;
    }
    if (uniform) {
      if (codeInside(cells.codes.uniformCode(b))) extend(static_cast<std::uint64_t>(per_block));
      continue;
    }
    for (int c = 0; c < per_block; ++c) {
      if (!codeInside(cells.codes.code(b, c))) continue;
      for (int m = 0; m < modes; ++m) {
        if (local_labels[m] == nullptr) continue;
        const std::uint16_t local = pages[m][c];
        labels[m] = local == LabelLayer::kNoLocal ? kNoLabel : local_labels[m][local];
      }
      extend(1);
    }
  }
  if (run_cells > 0) tally.add(run.data(), run_cells);
}

}  // namespace

std::array<AssemblyModeSummary, 2> summariseAssemblyModes(const AnalysisData& data, int threads,
                                                          const std::function<void(double)>& progress) {
  const WorkspaceCells& cells = data.cells;
  const int modes = static_cast<int>(data.modes.size());
  std::vector<std::int32_t> start_labels(modes);
  for (int m = 0; m < modes; ++m) start_labels[m] = data.regions.label(cells.start_block, cells.start_cell, m);
  const AssemblyModeTally total(data.regions.regions, data.transitions, start_labels.data(), data.start_mode, modes);
  // Fixed chunks of blocks, each with its own copy of the tally, merged in order.
  const std::uint64_t blocks = cells.layout.blockCount();
  const std::size_t chunks = static_cast<std::size_t>(std::min<std::uint64_t>(blocks, 64));
  std::vector<AssemblyModeTally> tallies(chunks, total);
  std::atomic<std::size_t> done{0};
  std::mutex progress_mutex;
  parallelFor(chunks, threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t chunk = begin; chunk < end; ++chunk) {
      tallyBlocks(data, blocks * chunk / chunks, blocks * (chunk + 1) / chunks, tallies[chunk]);
      const std::size_t finished = ++done;
      if (progress) {
        const std::lock_guard<std::mutex> lock(progress_mutex);
        progress(static_cast<double>(finished) / chunks);
      }
    }
  }, 1);
  AssemblyModeTally merged = total;
  for (const AssemblyModeTally& tally : tallies) merged.merge(tally);
  return merged.finish(data.grid.cellVolume());
}

}  // namespace maximal_workspace
