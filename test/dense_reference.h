#pragma once
// A brute-force analysis for the tests: every cell of the box classified one by one, and
// the workspace, regions, singularity counts, transitions and volumes found by plain
// flood fills over per-cell arrays, with none of the engine's blocks, shells or codes.
// Slow and memory-hungry on purpose: it is the independent answer the block engine must
// reproduce cell for cell at coarse steps. Neighbours come from Grid::neighbour, so a
// periodic variable wraps here as the engine's must.

#include <cmath>
#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <numeric>
#include <tuple>
#include <vector>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/measure_certificate.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "workspace/thin_layers.h"

namespace maximal_workspace::test {

struct DenseReference {
  explicit DenseReference(Grid grid_) : grid(std::move(grid_)) {}

  Grid grid;
  int modes = 0;
  std::vector<std::uint8_t> ikp_assembled;  // per box cell: every chain reaches
  std::vector<std::uint8_t> assembled;      // per box cell: and some working mode keeps every limit
  std::vector<std::uint8_t> inside;         // per box cell: assembled and connected to the start
  std::vector<std::uint8_t> blocked;        // per box cell and mode: the mode breaks a limit
  std::vector<std::int8_t> signs;           // per box cell and mode (banded; 0 where blocked)
  std::vector<std::int32_t> labels;     // per box cell and mode: region, or -1
  std::vector<Region> regions;          // volume and seed_cell left 0
  std::uint64_t voxels = 0, dkp_entries = 0, ikp_faces = 0, ikp_entries = 0, transition_points = 0;
  std::uint64_t thin_layer_faces = 0;
  // (face, working mode) pairs where a mode of a workspace cell breaks a limit across the
  // face: actuator limit, joint cone, interference (the kind at the centre across).
  std::array<std::uint64_t, 3> wall_entries{};
  // (from mode, sign, from voxels, to mode, to voxels) of every transition.
  std::vector<std::tuple<int, int, std::uint64_t, int, std::uint64_t>> transitions;
  std::array<std::uint64_t, 2> maximal_voxels{}, reachable_voxels{};
  std::array<int, 2> components{};

  std::int8_t sign(std::uint64_t cell, int mode) const { return signs[cell * modes + mode]; }
  bool isBlocked(std::uint64_t cell, int mode) const { return blocked[cell * modes + mode] != 0; }
  std::int32_t label(std::uint64_t cell, int mode) const { return labels[cell * modes + mode]; }
};

namespace dense_detail {

// Face-connected components of the cells where key(cell) is the same non-zero value,
// joined across the faces where joined(lower cell, d) holds (the face towards +d).
template <class Key, class Joined>
std::vector<std::uint64_t> floodFill(const Grid& grid, const Key& key, const Joined& joined,
                                     std::vector<std::int32_t>* component) {
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
          if (!joined(direction > 0 ? queue[head] : next, d)) continue;
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

// The stages of the brute-force analysis, each over the whole box.
class DenseAnalysis {
 public:
  DenseAnalysis(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options)
      : model_(model), options_(options), ref_(Grid(model, spec)), modes_(analysedWorkingModes(model, options)),
        start_mode_(resolveStartMode(model, modes_, spec.start, options.start_mode)),
        // The engine's own choice of path: the factorised one is checked against LU
        // elsewhere (test_workspace: CoupleFactorisationAgreesWithLu); LU per cell would
        // take minutes.
        classifier_(model, modes_, spec.start, orientationFixed(spec)) {
    ref_.grid.cellOf(spec.start, &start_);
    ref_.modes = static_cast<int>(modes_.size());
  }

  DenseReference run() {
    classify();
    findThinLayers();
    connect();
    labelRegions();
    for (std::uint64_t cell = 0; cell < ref_.grid.cellCount(); ++cell) {
      if (ref_.inside[cell]) scanCell(cell);
    }
    tally();
    return std::move(ref_);
  }

 private:
  static bool orientationFixed(const GridSpec& spec) {
    return std::none_of(spec.variables.begin(), spec.variables.end(), isRotational);
  }

  void classify() {
    const std::uint64_t cells = ref_.grid.cellCount();
    ref_.ikp_assembled.assign(cells, 0);
    ref_.assembled.assign(cells, 0);
    ref_.blocked.assign(cells * ref_.modes, 0);
    ref_.signs.assign(cells * ref_.modes, 0);
    std::vector<double> measures(modes_.size());
    for (std::uint64_t cell = 0; cell < cells; ++cell) {
      ref_.ikp_assembled[cell] = classifier_.classify(ref_.grid.pose(cell), measures.data());
      if (!ref_.ikp_assembled[cell]) continue;
      for (int m = 0; m < ref_.modes; ++m) {
        ref_.blocked[cell * ref_.modes + m] = !modeAdmissible(measures[m]);
        ref_.signs[cell * ref_.modes + m] = bandedSign(measures[m], options_.margin);
      }
      // A cell where every working mode breaks a limit of the robot is outside the
      // workspace: no configuration of the robot holds the pose.
      ref_.assembled[cell] = std::any_of(measures.begin(), measures.end(), modeAdmissible);
    }
  }

  // Layers thinner than the step (workspace/thin_layers.h), face by face: every face
  // between two assembled cells one of which is not proven assembled over its own box, or
  // has a chain near its reach over it (MeasureCertificate::chainsNearReach), is checked,
  // for a gap on the segment between the centres, then for a working mode whose sign at
  // both centres differs at the face's centre. (The engine skips the near cells whose
  // working modes' signs are all proven over their boxes: no sign layer can cross those,
  // so that changes no cut.)
  void findThinLayers() {
    const Grid& grid = ref_.grid;
    const MeasureCertificate certificate(model_, modes_, grid.spec().start);
    std::vector<std::uint32_t> open(grid.cellCount(), 0);
    std::vector<std::uint8_t> near(grid.cellCount(), 0);
    for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
      if (!ref_.assembled[cell]) continue;
      certificate.assemblyOf(grid.cellBox(cell), ~0u, &open[cell]);
      near[cell] = certificate.chainsNearReach(grid.cellBox(cell)) != 0;
    }
    std::vector<double> measures(modes_.size());
    for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
      for (int d = 0; d < grid.dims() && ref_.assembled[cell]; ++d) {
        std::uint64_t next = 0;
        if (!grid.neighbour(cell, d, 1, &next) || !ref_.assembled[next]) continue;
        if ((open[cell] | open[next]) == 0 && !near[cell] && !near[next]) continue;
        const Pose centre = grid.pose(cell);
        bool gap = segmentLeavesWorkspace(grid, certificate, centre, d, grid.step(d), open[cell] | open[next]);
        std::uint64_t modes = 0;
        Pose face = centre;
        face.setValue(grid.variable(d), centre.value(grid.variable(d)) + 0.5 * grid.step(d));
        gap = gap || !classifier_.classify(face, measures.data());
        for (int m = 0; m < ref_.modes && !gap; ++m) {
          const int sign = ref_.sign(cell, m);
          if (sign != 0 && sign == ref_.sign(next, m) && bandedSign(measures[m], 0.0) != sign) modes |= std::uint64_t{1} << m;
        }
        if (gap || modes != 0) cuts_[cell * kMaxGridDims + d] = {gap, modes};
      }
    }
    ref_.thin_layer_faces = cuts_.size();
  }

  // Whether the components of `mode` (-1: the workspace's) join across the face.
  bool joined(std::uint64_t lower, int d, int mode) const {
    const auto cut = cuts_.find(lower * kMaxGridDims + d);
    return cut == cuts_.end() || !(cut->second.first || (mode >= 0 && (cut->second.second >> mode & 1u)));
  }

  // The workspace: the assembled cells connected to the start.
  void connect() {
    std::vector<std::int32_t> connected;
    floodFill(
        ref_.grid, [&](std::uint64_t c) { return int(ref_.assembled[c]); },
        [&](std::uint64_t lower, int d) { return joined(lower, d, -1); }, &connected);
    ref_.inside.assign(ref_.grid.cellCount(), 0);
    for (std::uint64_t cell = 0; cell < ref_.grid.cellCount(); ++cell) {
      ref_.inside[cell] = connected[cell] >= 0 && connected[cell] == connected[start_];
      ref_.voxels += ref_.inside[cell];
    }
  }

  // Regions, mode by mode, in mode order then first cell.
  void labelRegions() {
    const std::uint64_t cells = ref_.grid.cellCount();
    ref_.labels.assign(cells * ref_.modes, -1);
    const double min_voxels = std::max(static_cast<double>(options_.debris.min_voxels),
                                       options_.debris.min_fraction * static_cast<double>(ref_.voxels));
    for (int m = 0; m < ref_.modes; ++m) {
      std::vector<std::int32_t> component;
      const std::vector<std::uint64_t> sizes = floodFill(
          ref_.grid,
          [&](std::uint64_t c) { return ref_.inside[c] ? (ref_.sign(c, m) > 0 ? 1 : ref_.sign(c, m) < 0 ? 2 : 0) : 0; },
          [&](std::uint64_t lower, int d) { return joined(lower, d, m); }, &component);
      const std::int32_t offset = static_cast<std::int32_t>(ref_.regions.size());
      for (std::uint64_t size : sizes) {
        Region region;
        region.id = static_cast<std::uint32_t>(ref_.regions.size());
        region.mode = m;
        region.voxels = size;
        region.debris = static_cast<double>(size) < min_voxels;
        ref_.regions.push_back(region);
      }
      for (std::uint64_t cell = 0; cell < cells; ++cell) {
        if (component[cell] < 0) continue;
        ref_.labels[cell * ref_.modes + m] = offset + component[cell];
        ref_.regions[offset + component[cell]].sign = ref_.sign(cell, m);
      }
    }
  }

  // A workspace cell's singular entries, and its faces to cells where some chain cannot
  // be assembled, with their transitions.
  void scanCell(std::uint64_t cell) {
    const Grid& grid = ref_.grid;
    for (int m = 0; m < ref_.modes; ++m) {
      bool singular = ref_.sign(cell, m) == 0 && !ref_.isBlocked(cell, m);
      for (int d = 0; d < grid.dims(); ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t next = 0;
          if (grid.neighbour(cell, d, direction, &next) && ref_.inside[next]) {
            singular = singular || ref_.sign(cell, m) * ref_.sign(next, m) < 0;
          }
        }
      }
      ref_.dkp_entries += singular;
    }
    for (int d = 0; d < grid.dims(); ++d) {
      for (int direction : {-1, 1}) {
        std::uint64_t next = 0;
        if (!grid.neighbour(cell, d, direction, &next)) continue;
        if (ref_.ikp_assembled[next]) {
          scanWall(cell, next, d, direction);
          continue;
        }
        ++ref_.ikp_faces;
        Pose to = grid.pose(cell);
        to.setValue(grid.variable(d), to.value(grid.variable(d)) + direction * grid.step(d));
        scanFace(cell, grid.pose(cell), to, grid.step(d));
      }
    }
  }

  // A face of a workspace cell to a cell every chain reaches: the modes that keep every limit
  // at the cell and break one across the face (all of them when every mode breaks one
  // there), each counted by the limit broken at the centre across.
  void scanWall(std::uint64_t cell, std::uint64_t next, int d, int direction) {
    if (!constraints_.active()) return;
    Pose across = ref_.grid.pose(cell);
    ref_.grid.move(&across, d, direction * ref_.grid.step(d));
    const IkpResult ikp = solveIkp(model_, across);
    for (int m = 0; m < ref_.modes; ++m) {
      if (ref_.isBlocked(cell, m) || (ref_.assembled[next] && !ref_.isBlocked(next, m))) continue;
      const ConstraintKind kind = wallLimit(constraints_.margins(across, ikp, modes_[m])).kind;
      ++ref_.wall_entries[kind == ConstraintKind::JointCone ? 1 : kind == ConstraintKind::Interference ? 2 : 0];
    }
  }

  // The face from a workspace cell's centre `from` to `to`, one step away, where some chain
  // cannot be assembled: one point per couple (or chain) leaving its reach, bisected.
  void scanFace(std::uint64_t cell, const Pose& from, const Pose& to, double step) {
    const int groups = options_.uncoupled ? model_.chainCount() : model_.inputCount();
    const IkpResult ikp = solveIkp(model_, to);
    std::vector<bool> group_done(groups, false);
    for (int c = 0; c < model_.chainCount(); ++c) {
      if (ikp.chains[c].assembled) continue;
      ++ref_.ikp_entries;
      const int group = options_.uncoupled ? c : model_.chain_input[c];
      if (group_done[group]) continue;
      group_done[group] = true;
      double low = 0.0, high = 1.0;
      const auto along = [&](double t) {
        Pose pose;
        pose.position = from.position + t * (to.position - from.position);
        pose.euler_zyz = from.euler_zyz + t * (to.euler_zyz - from.euler_zyz);
        return pose;
      };
      while (step * (high - low) > options_.transition_tolerance) {
        const double middle = 0.5 * (low + high);
        (solveIkp(model_, along(middle)).chains[c].assembled ? low : high) = middle;
      }
      ref_.transition_points += joinAt(cell, from, along(low), c);
    }
  }

  // The pairs of regions joined at an exact point where chain c's branches meet; whether
  // there is any. Both working modes must keep their sign on the way from the cell's
  // centre `from`: at 1/4 of it, then at 1 - 2^-k for k = 1 .. 12.
  bool joinAt(std::uint64_t cell, const Pose& from, const Pose& point, int chain) {
    std::vector<double> measures(modes_.size());
    if (!classifier_.classify(point, measures.data())) return false;
    std::uint32_t flipped = 1u << chain;
    if (!options_.uncoupled) {
      flipped = 0;
      for (int k : model_.inputs[model_.chain_input[chain]].chains) flipped |= 1u << k;
    }
    std::vector<std::tuple<int, int, int>> candidates;  // (mode, other mode, sign)
    for (int m = 0; m < ref_.modes; ++m) {
      for (int other = m + 1; other < ref_.modes; ++other) {
        if ((modes_[m].negative_chains ^ modes_[other].negative_chains) != flipped) continue;
        const std::int32_t a = ref_.label(cell, m), b = ref_.label(cell, other);
        if (a < 0 || b < 0 || ref_.regions[a].sign != ref_.regions[b].sign) continue;
        const int s = ref_.regions[a].sign;
        if (bandedSign(measures[m], options_.margin) == s && bandedSign(measures[other], options_.margin) == s) {
          candidates.emplace_back(m, other, s);
        }
      }
    }
    if (candidates.empty()) return false;
    std::vector<double> fractions = {0.25};
    for (int k = 1; k <= 12; ++k) fractions.push_back(1.0 - std::ldexp(1.0, -k));
    for (const double t : fractions) {
      Pose between;
      between.position = from.position + t * (point.position - from.position);
      between.euler_zyz = from.euler_zyz + t * (point.euler_zyz - from.euler_zyz);
      if (!classifier_.classify(between, measures.data())) return false;
      std::vector<std::tuple<int, int, int>> kept;
      for (const auto& [m, other, s] : candidates) {
        if (bandedSign(measures[m], 0.0) == s && bandedSign(measures[other], 0.0) == s) kept.emplace_back(m, other, s);
      }
      candidates = std::move(kept);
    }
    for (const auto& [m, other, s] : candidates) edges_[{ref_.label(cell, m), ref_.label(cell, other)}] = s;
    return !candidates.empty();
  }

  // Transitions, their groups, and per assembly mode the maximal and reachable cells.
  void tally() {
    std::vector<int> parent(ref_.regions.size());
    std::iota(parent.begin(), parent.end(), 0);
    for (const auto& [pair, s] : edges_) {
      const Region &a = ref_.regions[pair.first], &b = ref_.regions[pair.second];
      ref_.transitions.emplace_back(a.mode, s, a.voxels, b.mode, b.voxels);
      if (!a.debris && !b.debris) parent[root(parent, pair.first)] = root(parent, pair.second);
    }
    std::sort(ref_.transitions.begin(), ref_.transitions.end());
    for (int a = 0; a < 2; ++a) {
      const int sign = a == 0 ? 1 : -1;
      std::vector<bool> seen(ref_.regions.size(), false);
      for (const Region& region : ref_.regions) {
        const int r = root(parent, static_cast<int>(region.id));
        if (region.sign == sign && !region.debris && !seen[r]) seen[r] = true, ++ref_.components[a];
      }
      const std::int32_t traditional = traditionalRegion(sign);
      for (std::uint64_t cell = 0; cell < ref_.grid.cellCount(); ++cell) {
        bool maximal = false, reachable = false;
        for (int m = 0; m < ref_.modes && ref_.inside[cell]; ++m) {
          const std::int32_t r = ref_.label(cell, m);
          if (r < 0 || ref_.regions[r].debris) continue;
          maximal = maximal || ref_.regions[r].sign == sign;
          reachable = reachable || (traditional >= 0 && root(parent, r) == root(parent, traditional));
        }
        ref_.maximal_voxels[a] += maximal;
        ref_.reachable_voxels[a] += reachable;
      }
    }
  }

  // The start's region in the start mode, else the largest of this sign at the start.
  std::int32_t traditionalRegion(int sign) const {
    const std::int32_t own = ref_.label(start_, start_mode_);
    if (own >= 0 && ref_.regions[own].sign == sign) return own;
    std::int32_t best = -1;
    for (int m = 0; m < ref_.modes; ++m) {
      const std::int32_t r = ref_.label(start_, m);
      if (r >= 0 && ref_.regions[r].sign == sign && (best < 0 || ref_.regions[r].voxels > ref_.regions[best].voxels)) best = r;
    }
    return best;
  }

  const RobotModel& model_;
  const AnalysisOptions& options_;
  DenseReference ref_;
  std::vector<WorkingMode> modes_;
  int start_mode_;
  PoseClassifier classifier_;
  RobotConstraints constraints_{model_};
  std::uint64_t start_ = 0;
  std::map<std::pair<int, int>, int> edges_;  // region pair -> sign
  std::map<std::uint64_t, std::pair<bool, std::uint64_t>> cuts_;  // face -> (gap, modes whose sign changes)
};

}  // namespace dense_detail

// The same request as analyseWorkspace(model, spec, options) answers.
inline DenseReference denseReference(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  return dense_detail::DenseAnalysis(model, spec, options).run();
}

}  // namespace maximal_workspace::test
