#include "regions/conditioning_summary.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "maximal_workspace/kinematics/conditioning.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "workspace/parallel.h"

namespace maximal_workspace {

namespace {

// Lattice points per work item: sums are kept per item and added in item order, so the
// figures are the same whatever the thread count.
constexpr std::uint64_t kPointsPerChunk = 4096;

struct ConditioningTally {
  std::array<std::uint64_t, 2> samples{}, well_conditioned{};
  std::array<double, 2> index_sum{};
};

// The sub-lattice: every stride-th cell along each grid variable, from the middle of the
// first stride.
class SampleLattice {
 public:
  SampleLattice(const Grid& grid, int stride) : grid_(grid), stride_(stride), offset_(stride / 2) {
    for (int d = 0; d < grid.dims(); ++d) {
      counts_[d] = grid.size(d) > offset_ ? (grid.size(d) - offset_ + stride - 1) / stride : 0;
      points_ *= static_cast<std::uint64_t>(counts_[d]);
    }
  }
  std::uint64_t points() const { return points_; }
  // The grid cell of lattice point `point`, the last variable fastest.
  GridCell cell(std::uint64_t point) const {
    GridCell cell{};
    for (int d = grid_.dims() - 1; d >= 0; --d) {
      cell[d] = offset_ + stride_ * static_cast<std::int64_t>(point % counts_[d]);
      point /= counts_[d];
    }
    return cell;
  }

 private:
  const Grid& grid_;
  std::int64_t stride_, offset_;
  std::array<std::int64_t, kMaxGridDims> counts_{};
  std::uint64_t points_ = 1;
};

// Per cell and assembly mode, the best index of the working modes whose non-debris region
// of that sign holds the cell: the robot may be in any of them there.
class CellConditioning {
 public:
  CellConditioning(const RobotModel& model, const AnalysisData& data, double threshold)
      : model_(model), data_(data), threshold_(threshold) {}

  void add(const GridCell& cell, ConditioningTally* tally) const {
    std::uint64_t block = 0;
    int in_block = 0;
    if (!data_.cells.layout.locate(cell, &block, &in_block) || !codeInside(data_.cells.codes.code(block, in_block))) return;
    const std::array<double, 2> best =
        bestConditioning(model_, data_.grid.pose(data_.grid.index(cell)), data_.modes, [&](int m) {
          const std::int32_t label = data_.regions.label(block, in_block, m);
          return label < 0 || data_.regions.regions[label].debris ? 0 : int{data_.regions.regions[label].sign};
        });
    for (int a = 0; a < 2; ++a) {
      if (best[a] < 0.0) continue;
      ++tally->samples[a];
      tally->well_conditioned[a] += best[a] >= threshold_ ? 1 : 0;
      tally->index_sum[a] += best[a];
    }
  }

 private:
  const RobotModel& model_;
  const AnalysisData& data_;
  double threshold_;
};

ConditioningFigures figures(std::uint64_t samples, std::uint64_t well_conditioned, double index_sum,
                            double maximal_volume) {
  ConditioningFigures result;
  result.samples = samples;
  result.well_conditioned = well_conditioned;
  if (samples == 0) return result;
  // A share of the maximal volume (the share first: a threshold of 0 then gives the
  // volume exactly, whatever the stride).
  const double share = static_cast<double>(well_conditioned) / static_cast<double>(samples);
  result.well_conditioned_volume = maximal_volume * share;
  result.global_index = index_sum / static_cast<double>(samples);
  return result;
}

}  // namespace

std::array<double, 2> bestConditioning(const RobotModel& model, const Pose& pose, const std::vector<WorkingMode>& modes,
                                       const std::function<int(int)>& region_sign) {
  std::optional<IkpResult> ikp;  // solved for the first working mode that needs it
  std::array<double, 2> best{-1.0, -1.0};
  for (std::size_t m = 0; m < modes.size(); ++m) {
    const int sign = region_sign(static_cast<int>(m));
    if (sign == 0) continue;
    if (!ikp) ikp = solveIkp(model, pose);
    double& slot = best[sign > 0 ? 0 : 1];
    slot = std::max(slot, conditioningIndex(model, configurationOf(pose, *ikp, modes[m])));
  }
  return best;
}

int conditioningStride(std::uint64_t cells, int dims, int modes, std::uint64_t evaluations) {
  const double wanted = static_cast<double>(cells) * modes;
  // At least one cell is sampled, whatever the budget.
  const double budget = std::max(static_cast<double>(evaluations), static_cast<double>(modes));
  int stride = 1;
  while (wanted / std::pow(stride, dims) > budget) ++stride;
  return stride;
}

ConditioningSummary summariseConditioning(const RobotModel& model, const AnalysisData& data,
                                          const ConditioningRequest& request, int threads,
                                          const std::function<void(double)>& progress) {
  const auto started = std::chrono::steady_clock::now();
  ConditioningSummary summary;
  summary.request = request;
  summary.stride = conditioningStride(data.cells.inside_cells, data.grid.dims(), static_cast<int>(data.modes.size()),
                                      request.evaluations);
  const SampleLattice lattice(data.grid, summary.stride);
  const std::size_t chunks = static_cast<std::size_t>((lattice.points() + kPointsPerChunk - 1) / kPointsPerChunk);
  std::vector<ConditioningTally> tallies(chunks);
  ItemProgress chunks_done(progress, chunks);
  parallelFor(chunks, threads, [&](std::size_t begin, std::size_t end) {
    const CellConditioning conditioning(model, data, request.threshold);
    for (std::size_t chunk = begin; chunk < end; ++chunk) {
      const std::uint64_t last = std::min(lattice.points(), (chunk + 1) * kPointsPerChunk);
      for (std::uint64_t point = chunk * kPointsPerChunk; point < last; ++point) {
        conditioning.add(lattice.cell(point), &tallies[chunk]);
      }
      chunks_done.finished();
    }
  }, 1);
  ConditioningTally total;
  for (const ConditioningTally& tally : tallies) {
    for (int a = 0; a < 2; ++a) {
      total.samples[a] += tally.samples[a];
      total.well_conditioned[a] += tally.well_conditioned[a];
      total.index_sum[a] += tally.index_sum[a];
    }
  }
  for (int a = 0; a < 2; ++a) {
    summary.assembly_modes[a] = figures(total.samples[a], total.well_conditioned[a], total.index_sum[a],
                                        data.assembly_modes[a].maximal_volume);
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return summary;
}

}  // namespace maximal_workspace
