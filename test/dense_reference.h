#pragma once
// A brute-force analysis for the tests: every cell of the box classified one by one, and
// the workspace, regions, singularity counts, transitions and volumes found by plain
// flood fills over per-cell arrays, with none of the engine's blocks, shells or codes.
// Slow and memory-hungry on purpose: it is the independent answer the block engine must
// reproduce cell for cell at coarse steps. Neighbours come from Grid::neighbour, so a
// periodic variable wraps here as the engine's must.

#include <algorithm>
#include <cstdint>
#include <map>
#include <numeric>
#include <tuple>
#include <vector>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace::test {

struct DenseReference {
  explicit DenseReference(Grid grid_) : grid(std::move(grid_)) {}

  Grid grid;
  int modes = 0;
  std::vector<std::uint8_t> assembled;  // per box cell
  std::vector<std::uint8_t> inside;     // per box cell: assembled and connected to the start
  std::vector<std::int8_t> signs;       // per box cell and mode (banded)
  std::vector<std::int32_t> labels;     // per box cell and mode: region, or -1
  std::vector<Region> regions;          // volume and seed_cell left 0
  std::uint64_t voxels = 0, dkp_entries = 0, ikp_faces = 0, ikp_entries = 0, transition_points = 0;
  // (from mode, sign, from voxels, to mode, to voxels) of every transition.
  std::vector<std::tuple<int, int, std::uint64_t, int, std::uint64_t>> transitions;
  std::array<std::uint64_t, 2> maximal_voxels{}, reachable_voxels{};
  std::array<int, 2> components{};

  std::int8_t sign(std::uint64_t cell, int mode) const { return signs[cell * modes + mode]; }
  std::int32_t label(std::uint64_t cell, int mode) const { return labels[cell * modes + mode]; }
};

namespace dense_detail {

// Face-connected components of the cells where key(cell) is the same non-zero value.
template <class Key>
std::vector<std::uint64_t> floodFill(const Grid& grid, const Key& key, std::vector<std::int32_t>* component) {
  component->assign(grid.cellCount(), -1);
  std::vector<std::uint64_t> sizes, queue;
  for (std::uint64_t seed = 0; seed < grid.cellCount(); ++seed) {
    const int seed_key = key(seed);
    if (seed_key == 0 || (*component)[seed] >= 0) continue;
    const std::int32_t id = static_cast<std::int32_t>(sizes.size());
    (*component)[seed] = id;
    queue.assign(1, seed);
    for (std::size_t head = 0; head < queue.size(); ++head) {
      for (int d = 0; d < grid.dims(); ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t next = 0;
          if (!grid.neighbour(queue[head], d, direction, &next) || (*component)[next] >= 0 || key(next) != seed_key) continue;
          (*component)[next] = id;
          queue.push_back(next);
        }
      }
    }
    sizes.push_back(queue.size());
  }
  return sizes;
}

inline int root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace dense_detail

// The same request as analyseWorkspace(model, spec, options) answers.
inline DenseReference denseReference(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  using dense_detail::floodFill;
  DenseReference ref{Grid(model, spec)};
  const Grid& grid = ref.grid;
  const std::vector<WorkingMode> modes = analysedWorkingModes(model, options);
  const int start_mode = resolveStartMode(model, modes, spec.start, options.start_mode);
  ref.modes = static_cast<int>(modes.size());
  // The engine's own choice of path: the factorised one is checked against LU elsewhere
  // (test_workspace: CoupleFactorisationAgreesWithLu), and LU per cell would take minutes.
  bool orientation_fixed = true;
  for (OutputVariable variable : grid.spec().variables) orientation_fixed = orientation_fixed && !isRotational(variable);
  const PoseClassifier classifier(model, modes, spec.start, orientation_fixed);
  const std::uint64_t cells = grid.cellCount();
  ref.assembled.assign(cells, 0);
  ref.signs.assign(cells * ref.modes, 0);
  std::vector<double> measures(modes.size());
  for (std::uint64_t cell = 0; cell < cells; ++cell) {
    ref.assembled[cell] = classifier.classify(grid.pose(cell), measures.data());
    if (!ref.assembled[cell]) continue;
    for (int m = 0; m < ref.modes; ++m) ref.signs[cell * ref.modes + m] = bandedSign(measures[m], options.singular_threshold);
  }
  // The workspace: the assembled cells connected to the start.
  std::uint64_t start = 0;
  grid.cellOf(spec.start, &start);
  std::vector<std::int32_t> connected;
  floodFill(grid, [&](std::uint64_t c) { return int(ref.assembled[c]); }, &connected);
  ref.inside.assign(cells, 0);
  for (std::uint64_t cell = 0; cell < cells; ++cell) {
    ref.inside[cell] = connected[cell] >= 0 && connected[cell] == connected[start];
    ref.voxels += ref.inside[cell];
  }
  // Regions, mode by mode, in mode order then first cell.
  ref.labels.assign(cells * ref.modes, -1);
  const double min_voxels =
      std::max(static_cast<double>(options.debris.min_voxels), options.debris.min_fraction * static_cast<double>(ref.voxels));
  for (int m = 0; m < ref.modes; ++m) {
    std::vector<std::int32_t> component;
    const std::vector<std::uint64_t> sizes = floodFill(
        grid, [&](std::uint64_t c) { return ref.inside[c] ? (ref.sign(c, m) > 0 ? 1 : ref.sign(c, m) < 0 ? 2 : 0) : 0; },
        &component);
    const std::int32_t offset = static_cast<std::int32_t>(ref.regions.size());
    for (std::uint64_t cell = 0; cell < cells; ++cell) {
      if (component[cell] < 0) continue;
      ref.labels[cell * ref.modes + m] = offset + component[cell];
    }
    for (std::uint64_t size : sizes) {
      Region region;
      region.id = static_cast<std::uint32_t>(ref.regions.size());
      region.mode = m;
      region.voxels = size;
      region.debris = static_cast<double>(size) < min_voxels;
      ref.regions.push_back(region);
    }
    for (std::uint64_t cell = 0; cell < cells; ++cell) {
      if (component[cell] >= 0) ref.regions[offset + component[cell]].sign = ref.sign(cell, m);
    }
  }
  // Singular entries, IKP faces and transitions, cell by cell.
  const int groups = options.uncoupled ? model.chainCount() : model.inputCount();
  std::map<std::pair<int, int>, int> edges;  // region pair -> sign
  for (std::uint64_t cell = 0; cell < cells; ++cell) {
    if (!ref.inside[cell]) continue;
    for (int m = 0; m < ref.modes; ++m) {
      bool singular = ref.sign(cell, m) == 0;
      for (int d = 0; d < grid.dims(); ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t next = 0;
          if (grid.neighbour(cell, d, direction, &next) && ref.inside[next]) {
            singular = singular || ref.sign(cell, m) * ref.sign(next, m) < 0;
          }
        }
      }
      ref.dkp_entries += singular;
    }
    for (int d = 0; d < grid.dims(); ++d) {
      for (int direction : {-1, 1}) {
        std::uint64_t next = 0;
        if (!grid.neighbour(cell, d, direction, &next) || ref.assembled[next]) continue;
        ++ref.ikp_faces;
        const Pose from = grid.pose(cell);
        Pose to = from;
        to.setValue(grid.variable(d), from.value(grid.variable(d)) + direction * grid.step(d));
        const IkpResult ikp = solveIkp(model, to);
        std::vector<bool> group_done(groups, false);
        for (int c = 0; c < model.chainCount(); ++c) {
          if (ikp.chains[c].assembled) continue;
          ++ref.ikp_entries;
          const int group = options.uncoupled ? c : model.chain_input[c];
          if (group_done[group]) continue;
          group_done[group] = true;
          // The reach boundary of chain c along the step, by plain bisection.
          double low = 0.0, high = 1.0;
          const auto along = [&](double t) {
            Pose pose;
            pose.position = from.position + t * (to.position - from.position);
            pose.euler_zyz = from.euler_zyz + t * (to.euler_zyz - from.euler_zyz);
            return pose;
          };
          while (grid.step(d) * (high - low) > options.transition_tolerance) {
            const double middle = 0.5 * (low + high);
            (solveIkp(model, along(middle)).chains[c].assembled ? low : high) = middle;
          }
          if (!classifier.classify(along(low), measures.data())) continue;
          bool any = false;
          for (int m = 0; m < ref.modes; ++m) {
            for (int other = m + 1; other < ref.modes; ++other) {
              const std::uint32_t flipped = options.uncoupled ? 1u << c : [&] {
                std::uint32_t mask = 0;
                for (int k : model.inputs[model.chain_input[c]].chains) mask |= 1u << k;
                return mask;
              }();
              if ((modes[m].negative_chains ^ modes[other].negative_chains) != flipped) continue;
              const std::int32_t a = ref.label(cell, m), b = ref.label(cell, other);
              if (a < 0 || b < 0 || ref.regions[a].sign != ref.regions[b].sign) continue;
              const int s = ref.regions[a].sign;
              if (bandedSign(measures[m], options.singular_threshold) != s ||
                  bandedSign(measures[other], options.singular_threshold) != s) {
                continue;
              }
              edges[{a, b}] = s;
              any = true;
            }
          }
          ref.transition_points += any;
        }
      }
    }
  }
  std::vector<int> parent(ref.regions.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& [pair, s] : edges) {
    const Region &a = ref.regions[pair.first], &b = ref.regions[pair.second];
    ref.transitions.emplace_back(a.mode, s, a.voxels, b.mode, b.voxels);
    if (!a.debris && !b.debris) parent[dense_detail::root(parent, pair.first)] = dense_detail::root(parent, pair.second);
  }
  std::sort(ref.transitions.begin(), ref.transitions.end());
  // Per assembly mode: groups, maximal and reachable cells.
  for (int a = 0; a < 2; ++a) {
    const int sign = a == 0 ? 1 : -1;
    std::vector<bool> seen(ref.regions.size(), false);
    for (const Region& region : ref.regions) {
      const int r = dense_detail::root(parent, static_cast<int>(region.id));
      if (region.sign == sign && !region.debris && !seen[r]) seen[r] = true, ++ref.components[a];
    }
    std::int32_t traditional = ref.label(start, start_mode);
    if (traditional < 0 || ref.regions[traditional].sign != sign) {
      traditional = -1;
      for (int m = 0; m < ref.modes; ++m) {
        const std::int32_t r = ref.label(start, m);
        if (r >= 0 && ref.regions[r].sign == sign && (traditional < 0 || ref.regions[r].voxels > ref.regions[traditional].voxels)) {
          traditional = r;
        }
      }
    }
    for (std::uint64_t cell = 0; cell < cells; ++cell) {
      bool maximal = false, reachable = false;
      for (int m = 0; m < ref.modes && ref.inside[cell]; ++m) {
        const std::int32_t r = ref.label(cell, m);
        if (r < 0 || ref.regions[r].debris) continue;
        maximal = maximal || ref.regions[r].sign == sign;
        reachable = reachable || (traditional >= 0 && dense_detail::root(parent, r) == dense_detail::root(parent, traditional));
      }
      ref.maximal_voxels[a] += maximal;
      ref.reachable_voxels[a] += reachable;
    }
  }
  return ref;
}

}  // namespace maximal_workspace::test
