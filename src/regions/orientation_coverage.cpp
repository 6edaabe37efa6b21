#include "maximal_workspace/regions/orientation_coverage.h"

#include <algorithm>
#include <cmath>

#include "maximal_workspace/model/input_error.h"
#include "workspace/parallel.h"

namespace maximal_workspace {

namespace {

constexpr int kSets = 2;  // reachable, traditional

// Per region, the sets of each assembly mode it belongs to: bit 2 a + s for assembly mode
// index a (0: +, 1: -) and set s.
std::vector<std::uint8_t> regionSets(const WorkspaceAnalysis& analysis) {
  const std::vector<Region>& regions = analysis.regions();
  const TransitionGraph& graph = analysis.transitions();
  std::vector<std::uint8_t> sets(regions.size(), 0);
  for (int a = 0; a < 2; ++a) {
    const std::int32_t traditional = analysis.assemblyModes()[a].traditional_region;
    if (traditional < 0) continue;
    for (std::size_t r = 0; r < regions.size(); ++r) {
      if (regions[r].debris || regions[r].sign != regions[traditional].sign) continue;
      if (graph.component[r] == graph.component[traditional]) sets[r] |= 1u << (kSets * a);
    }
    sets[traditional] |= 1u << (kSets * a + 1);
  }
  return sets;
}

void requireOrientationSet(const Grid& grid) {
  if (!hasOrientationSet(grid)) {
    throw InputError("orientation coverage: the analysis is not over x y z and a tilt-and-torsion orientation set");
  }
}

// Weight of each tilt layer: the integral of sin t over its cell.
std::vector<double> tiltWeights(const Grid& grid) {
  const int tilt = grid.tiltDim();
  std::vector<double> weights(grid.size(tilt));
  for (std::int64_t k = 0; k < grid.size(tilt); ++k) {
    const double low = std::max(0.0, grid.centre(tilt, k) - 0.5 * grid.step(tilt));
    weights[k] = std::cos(low) - std::cos(grid.centre(tilt, k) + 0.5 * grid.step(tilt));
  }
  return weights;
}

// The weight of every orientation cell of a position together.
double totalWeight(const Grid& grid, const std::vector<double>& tilt_weights) {
  double column = 0.0;
  for (double weight : tilt_weights) column += weight;
  return column * static_cast<double>(grid.size(3)) * static_cast<double>(grid.size(5));
}

}  // namespace

std::array<std::uint8_t, 3> coverageColour(double share) {
  const double t = std::clamp(share, 0.0, 1.0);
  return {static_cast<std::uint8_t>(255.0 * t), static_cast<std::uint8_t>(255.0 * (1.0 - std::abs(2.0 * t - 1.0))),
          static_cast<std::uint8_t>(255.0 * (1.0 - t))};
}

bool hasOrientationSet(const Grid& grid) {
  const std::vector<OutputVariable> all = {OutputVariable::X,   OutputVariable::Y,     OutputVariable::Z,
                                           OutputVariable::Phi, OutputVariable::Theta, OutputVariable::Psi};
  return grid.tiltTorsion() && grid.spec().variables == all;
}

OrientationCoverage orientationCoverage(const WorkspaceAnalysis& analysis, int threads) {
  const Grid& grid = analysis.grid();
  requireOrientationSet(grid);
  const BlockLayout& layout = analysis.blocks();
  const int tilt = grid.tiltDim(), modes = static_cast<int>(analysis.modes().size());
  OrientationCoverage coverage;
  for (int d = 0; d < 3; ++d) coverage.size_[d] = grid.size(d);
  const std::uint64_t positions = coverage.positionCount();
  const std::vector<double> tilt_weight = tiltWeights(grid);
  const double total_weight = totalWeight(grid, tilt_weight);
  const std::uint64_t orientation_cells = static_cast<std::uint64_t>(grid.size(3) * grid.size(4) * grid.size(5));
  const std::vector<std::uint8_t> region_sets = regionSets(analysis);
  std::array<std::vector<double>, 2 * kSets> weight;
  std::array<std::vector<std::uint32_t>, 2 * kSets> count;
  for (int s = 0; s < 2 * kSets; ++s) weight[s].assign(positions, 0.0), count[s].assign(positions, 0);

  // Blocks are ordered with x y z slowest: the blocks of one position block are a run, and
  // runs of different position blocks touch different positions, so threads share none.
  std::uint64_t angle_blocks = 1;
  for (int d = 3; d < 6; ++d) angle_blocks *= static_cast<std::uint64_t>(layout.blocks(d));
  const std::uint64_t position_blocks = layout.blockCount() / angle_blocks;
  parallelForEach(position_blocks, threads, [&](std::size_t begin, std::size_t end) {
    std::vector<std::int32_t> labels(static_cast<std::size_t>(layout.cellsPerBlock()) * modes);
    for (std::uint64_t b = begin * angle_blocks; b < end * angle_blocks; ++b) {
      for (int m = 0; m < modes; ++m) analysis.blockLabels(b, m, labels.data() + static_cast<std::size_t>(m) * layout.cellsPerBlock());
      const GridCell corner = layout.cellCoords(b, 0);  // a cell's coordinates: these plus its own in the block
      for (int c = 0; c < layout.cellsPerBlock(); ++c) {
        GridCell at = corner;
        for (int d = 0; d < 6; ++d) at[d] += layout.cellCoord(c, d);
        if (!layout.inBox(at)) continue;
        std::uint8_t in = 0;
        for (int m = 0; m < modes; ++m) {
          const std::int32_t region = labels[static_cast<std::size_t>(m) * layout.cellsPerBlock() + c];
          if (region >= 0) in |= region_sets[region];
        }
        if (in == 0) continue;
        const std::uint64_t p = coverage.position(at[0], at[1], at[2]);
        for (int s = 0; s < 2 * kSets; ++s) {
          if (!(in >> s & 1u)) continue;
          weight[s][p] += tilt_weight[at[tilt]];
          ++count[s][p];
        }
      }
    }
  });

  const double position_volume = grid.step(0) * grid.step(1) * grid.step(2);
  for (int a = 0; a < 2; ++a) {
    AssemblyModeCoverage& summary = coverage.summaries_[a];
    summary.sign = a == 0 ? 1 : -1;
    coverage.reachable_[a].resize(positions);
    coverage.traditional_[a].resize(positions);
    for (int set = 0; set < kSets; ++set) {
      const int s = kSets * a + set;
      CoverageVolumes& volumes = set == 0 ? summary.reachable : summary.traditional;
      std::vector<float>& share = set == 0 ? coverage.reachable_[a] : coverage.traditional_[a];
      for (std::uint64_t p = 0; p < positions; ++p) {
        share[p] = static_cast<float>(weight[s][p] / total_weight);
        volumes.total_orientation_positions += count[s][p] == orientation_cells;
        volumes.inclusion_positions += count[s][p] > 0;
      }
      volumes.total_orientation_volume = static_cast<double>(volumes.total_orientation_positions) * position_volume;
      volumes.inclusion_volume = static_cast<double>(volumes.inclusion_positions) * position_volume;
    }
  }
  return coverage;
}

std::array<std::array<double, 2>, 2> coverageAt(const WorkspaceAnalysis& analysis, std::int64_t i, std::int64_t j,
                                                std::int64_t k) {
  const Grid& grid = analysis.grid();
  requireOrientationSet(grid);
  const std::vector<double> tilt_weight = tiltWeights(grid);
  const std::vector<std::uint8_t> region_sets = regionSets(analysis);
  const int modes = static_cast<int>(analysis.modes().size());
  std::array<std::array<double, 2>, 2> shares{};
  for (std::int64_t a = 0; a < grid.size(3); ++a) {
    for (std::int64_t t = 0; t < grid.size(4); ++t) {
      for (std::int64_t s = 0; s < grid.size(5); ++s) {
        const std::uint64_t cell = grid.index(GridCell{i, j, k, a, t, s});
        std::uint8_t in = 0;
        for (int m = 0; m < modes; ++m) {
          const std::int32_t region = analysis.label(cell, m);
          if (region >= 0) in |= region_sets[region];
        }
        for (int bit = 0; bit < 2 * kSets; ++bit) {
          if (in >> bit & 1u) shares[bit / kSets][bit % kSets] += tilt_weight[t];
        }
      }
    }
  }
  const double total = totalWeight(grid, tilt_weight);
  for (auto& assembly : shares) {
    for (double& share : assembly) share /= total;
  }
  return shares;
}

}  // namespace maximal_workspace
