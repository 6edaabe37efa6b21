#include "maximal_workspace/io/display_sampling.h"

#include <algorithm>
#include <bitset>
#include <functional>
#include <cmath>
#include <limits>
#include <unordered_set>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

// Taubin iterations on display surfaces: the display cells' corners otherwise show as facets.
constexpr int kDisplaySmoothing = 5;

// Display cells of `factor` grid steps a side over the grid's box (the last ones cut by
// the box). Grid coordinates map to display coordinates by division.
class DisplayLattice {
 public:
  DisplayLattice(const Grid& grid, int factor) : grid_(grid), factor_(factor) {
    count_ = 1;
    for (int d = grid.dims() - 1; d >= 0; --d) {
      size_[d] = (grid.size(d) + factor - 1) / factor;
      stride_[d] = count_;
      count_ *= static_cast<std::uint64_t>(size_[d]);
    }
  }
  std::uint64_t count() const { return count_; }
  std::int64_t size(int d) const { return size_[d]; }
  std::uint64_t index(const GridCell& at) const {
    std::uint64_t result = 0;
    for (int d = 0; d < grid_.dims(); ++d) result += static_cast<std::uint64_t>(at[d]) * stride_[d];
    return result;
  }
  bool single() const { return count_ <= 1; }
  std::uint64_t ofGridCell(std::uint64_t grid_index) const {
    const GridCell fine = grid_.cell(grid_index);
    std::uint64_t index = 0;
    for (int d = 0; d < grid_.dims(); ++d) index += static_cast<std::uint64_t>(fine[d] / factor_) * stride_[d];
    return index;
  }
  GridCell coords(std::uint64_t index) const {
    GridCell at{};
    for (int d = 0; d < grid_.dims(); ++d) at[d] = static_cast<std::int64_t>(index / stride_[d] % size_[d]);
    return at;
  }
  // The grid cell at the display cell's middle (within the box).
  std::uint64_t sampleCell(std::uint64_t index) const {
    GridCell fine = coords(index);
    for (int d = 0; d < grid_.dims(); ++d) fine[d] = std::min<std::int64_t>(fine[d] * factor_ + factor_ / 2, grid_.size(d) - 1);
    return grid_.index(fine);
  }
  // The display cell's geometric centre.
  Eigen::Vector3d centre(std::uint64_t index) const {
    const GridCell at = coords(index);
    double values[kMaxGridDims];
    for (int d = 0; d < grid_.dims(); ++d) values[d] = grid_.centre(d, at[d] * factor_) + 0.5 * (factor_ - 1) * grid_.step(d);
    return grid_.poseAt(values).position;
  }
  bool neighbour(std::uint64_t index, int d, int direction, std::uint64_t* result) const {
    const std::int64_t at = static_cast<std::int64_t>(index / stride_[d] % size_[d]) + direction;
    if (at < 0 || at >= size_[d]) return false;
    *result = direction > 0 ? index + stride_[d] : index - stride_[d];
    return true;
  }

 private:
  const Grid& grid_;
  int factor_;
  std::array<std::int64_t, kMaxGridDims> size_{};
  std::array<std::uint64_t, kMaxGridDims> stride_{};
  std::uint64_t count_ = 0;
};

int firstFactor(const Grid& grid, double display_step) {
  // Past the grid's largest side a factor is one display cell like any larger one: held
  // there before the conversion, which beyond INT_MAX is undefined (and doubling on from it
  // would overflow).
  double largest = 1.0;
  for (int d = 0; d < grid.dims(); ++d) largest = std::max(largest, static_cast<double>(grid.size(d)));
  const double factor = std::ceil(display_step / grid.step(0) - 1e-9);
  return factor >= 1.0 ? static_cast<int>(std::min({factor, largest, 0x1p30})) : 1;
}

// Per display cell, the working modes whose non-debris regions of each sign hold its
// middle cell: masks[0] for +, masks[1] for -.
void membership(const WorkspaceAnalysis& analysis, const DisplayLattice& lattice, std::vector<std::uint64_t> masks[2]) {
  const std::vector<Region>& regions = analysis.regions();
  const BlockLayout& blocks = analysis.blocks();
  const int modes = static_cast<int>(analysis.modes().size());
  for (int s = 0; s < 2; ++s) masks[s].assign(lattice.count(), 0);
  for (std::uint64_t i = 0; i < lattice.count(); ++i) {
    std::uint64_t block = 0;
    int cell = 0;
    if (!blocks.locate(lattice.sampleCell(i), &block, &cell) || !analysis.inside(block, cell)) continue;
    for (int m = 0; m < modes; ++m) {
      const std::int32_t label = analysis.label(block, cell, m);
      if (label < 0 || regions[label].debris) continue;
      masks[regions[label].sign > 0 ? 0 : 1][i] |= std::uint64_t{1} << m;
    }
  }
}

// The working modes whose set the display cell is on the surface of: in it, with a face
// neighbour (or the box's edge) out of it.
std::uint64_t surfaceModes(const DisplayLattice& lattice, int dims, const std::vector<std::uint64_t>& mask,
                           std::uint64_t i) {
  std::uint64_t all_neighbours = ~std::uint64_t{0};
  for (int d = 0; d < dims; ++d) {
    for (int direction : {-1, 1}) {
      std::uint64_t next = 0;
      all_neighbours &= lattice.neighbour(i, d, direction, &next) ? mask[next] : 0;
    }
  }
  return mask[i] & ~all_neighbours;
}

// A key per display cell, kind and working mode or face: what one point stands for.
std::uint64_t sampleKey(std::uint64_t display_cell, const SingularityEntry& entry, int mode) {
  const int detail = entry.kind == SingularityEntry::Kind::Dkp   ? mode
                     : entry.kind == SingularityEntry::Kind::Ikp ? 64 + 2 * entry.dim + (entry.direction > 0)
                                                                 : 128 + mode;
  return display_cell << 8 | static_cast<std::uint64_t>(detail);
}

// The entries kept at one display factor, one per key; false when over `cap`.
bool keepEntries(const WorkspaceAnalysis& analysis, const DisplayLattice& lattice, std::uint64_t cap,
                 std::vector<std::pair<SingularityEntry, int>>* kept) {
  std::unordered_set<std::uint64_t> keys;
  kept->clear();
  bool within = true;
  analysis.forEachSingularity([&](const SingularityEntry& entry) {
    if (!within) return;
    const std::uint64_t display_cell = lattice.ofGridCell(entry.cell);
    for (int m = 0; m < 64; ++m) {
      // DKP singularities and walls are per working mode, the IKP boundary is every mode's.
      const bool per_mode = entry.kind != SingularityEntry::Kind::Ikp;
      if (per_mode && !(entry.modes >> m & 1)) continue;
      if (keys.insert(sampleKey(display_cell, entry, m)).second) kept->emplace_back(entry, m);
      if (!per_mode) break;
    }
    within = kept->size() <= cap;
  });
  return within;
}

}  // namespace

std::string DisplayDecimation::text() const {
  const std::string points = std::to_string(shown) + " points for " + std::to_string(full) + " entries, one per ";
  if (factor == 1) return points + "grid cell, kind and working mode";
  return points + "display cell of " + std::to_string(factor) +
         " grid steps (display_step, doubled while over max_points), kind and working mode";
}

namespace {

// The points of the entries kept: DKP ones at the cell centre with their measure, IKP
// ones at the face centre once per chain that cannot be assembled across it, walls at the
// face centre with the limit broken across it.
std::vector<SingularityPoint> singularityPoints(const RobotModel& model, const WorkspaceAnalysis& analysis,
                                               const std::vector<std::pair<SingularityEntry, int>>& kept) {
  const Grid& grid = analysis.grid();
  const PoseClassifier classifier(model, analysis.modes(), grid.spec().start, grid.orientationFixed());
  const RobotConstraints constraints(model);
  std::vector<double> measures(analysis.modes().size());
  std::vector<SingularityPoint> points;
  for (const auto& [entry, mode] : kept) {
    Pose pose = grid.pose(entry.cell);
    if (entry.kind == SingularityEntry::Kind::Dkp) {
      classifier.classify(pose, measures.data());
      points.push_back(SingularityPoint{pose.position, static_cast<std::uint8_t>(mode), 0, -1,
                                        static_cast<float>(measures[mode])});
      continue;
    }
    const OutputVariable variable = grid.variable(entry.dim);
    Pose outside = pose;
    grid.move(&outside, entry.dim, entry.direction * grid.step(entry.dim));
    if (!isRotational(variable)) grid.move(&pose, entry.dim, 0.5 * entry.direction * grid.step(entry.dim));
    const IkpResult ikp = solveIkp(model, outside);
    if (entry.kind == SingularityEntry::Kind::Limit) {
      // The limit the mode breaks across the face, and its chain.
      const WallLimit wall = ikp.assembled ? wallLimit(constraints.margins(outside, ikp, analysis.modes()[mode]))
                                           : WallLimit{ConstraintKind::InputRange, -1};
      points.push_back(SingularityPoint{pose.position, static_cast<std::uint8_t>(mode), static_cast<std::uint8_t>(wall.kind),
                                        static_cast<std::int8_t>(wall.chain), 0.0f});
      continue;
    }
    for (int c = 0; c < model.chainCount(); ++c) {
      if (!ikp.chains[c].assembled) {
        points.push_back(SingularityPoint{pose.position, kAllWorkingModes, 1, static_cast<std::int8_t>(c), 0.0f});
      }
    }
  }
  return points;
}

}  // namespace

SingularitySample sampleSingularities(const RobotModel& model, const WorkspaceAnalysis& analysis,
                                      const DisplayLimits& limits) {
  const Grid& grid = analysis.grid();
  SingularitySample sample;
  const SingularityCounts& counts = analysis.singularityCounts();
  sample.decimation.full =
      counts.dkp_entries + counts.ikp_entries + counts.limit_entries + counts.cone_entries + counts.interference_entries;
  std::vector<std::pair<SingularityEntry, int>> kept;
  for (int factor = firstFactor(grid, limits.display_step);; factor *= 2) {
    const DisplayLattice lattice(grid, factor);
    const bool last = lattice.single();
    if (!keepEntries(analysis, lattice, limits.max_points, &kept) && !last) continue;
    sample.points = singularityPoints(model, analysis, kept);
    // An IKP entry may stand for two chains: the points themselves must fit too.
    if (sample.points.size() > limits.max_points && !last) continue;
    sample.decimation.factor = factor;
    sample.decimation.shown = sample.points.size();
    return sample;
  }
}

SurfaceSample sampleSurfaces(const WorkspaceAnalysis& analysis, const DisplayLimits& limits, std::int8_t assembly_mode) {
  const Grid& grid = analysis.grid();
  SurfaceSample sample;
  if (!grid.isSpatial()) return sample;
  const int modes = static_cast<int>(analysis.modes().size());
  const bool keep[2] = {assembly_mode >= 0, assembly_mode <= 0};
  std::vector<std::uint64_t> masks[2];
  for (int factor = firstFactor(grid, limits.display_step);; factor *= 2) {
    const DisplayLattice lattice(grid, factor);
    membership(analysis, lattice, masks);
    std::uint64_t cubes = 0;
    for (std::uint64_t i = 0; i < lattice.count(); ++i) {
      for (int s = 0; s < 2; ++s) {
        if (keep[s] && masks[s][i] != 0) cubes += std::bitset<64>(surfaceModes(lattice, grid.dims(), masks[s], i)).count();
      }
    }
    if (cubes > limits.max_cubes && !lattice.single()) continue;
    sample.cube_size = factor * grid.step(0);
    sample.decimation = DisplayDecimation{factor, 0, cubes};
    for (int s = 0; s < 2; ++s) {
      sample.cubes[s].assign(keep[s] ? modes : 0, {});
      if (!keep[s]) continue;
      for (std::uint64_t i = 0; i < lattice.count(); ++i) {
        const std::uint64_t on_surface = masks[s][i] != 0 ? surfaceModes(lattice, grid.dims(), masks[s], i) : 0;
        for (int m = 0; m < modes; ++m) {
          if (on_surface >> m & 1) sample.cubes[s][m].push_back(lattice.centre(i));
        }
      }
    }
    return sample;
  }
}

namespace {

// The display cells `in` accepts, as cells of a lattice for meshing: display cell a spans
// [a, a + 1] display steps from the box's lower corner.
CellSet displayCells(const Grid& grid, const DisplayLattice& lattice, int factor,
                     const std::function<bool(std::uint64_t)>& in) {
  CellSet set;
  std::array<std::int64_t, 3> blocks{};
  for (int d = 0; d < 3; ++d) {
    set.steps[d] = factor * grid.step(d);
    set.origin[d] = grid.centre(d, 0) - 0.5 * grid.step(d);
    blocks[d] = (lattice.size(d) + kCellBlockSide - 1) / kCellBlockSide;
  }
  set.blocks = static_cast<std::uint64_t>(blocks[0] * blocks[1] * blocks[2]);
  set.read = [&lattice, in, blocks](std::uint64_t b, CellBlock* block) {
    const std::array<std::int64_t, 3> at = {static_cast<std::int64_t>(b) / (blocks[1] * blocks[2]),
                                            static_cast<std::int64_t>(b) / blocks[2] % blocks[1],
                                            static_cast<std::int64_t>(b) % blocks[2]};
    for (int d = 0; d < 3; ++d) block->origin[d] = at[d] * kCellBlockSide;
    block->full = false;
    block->cells.reset();
    for (int c = 0; c < kCellBlockSide * kCellBlockSide * kCellBlockSide; ++c) {
      const GridCell cell = {block->origin[0] + c / (kCellBlockSide * kCellBlockSide),
                             block->origin[1] + c / kCellBlockSide % kCellBlockSide, block->origin[2] + c % kCellBlockSide};
      if (cell[0] < lattice.size(0) && cell[1] < lattice.size(1) && cell[2] < lattice.size(2) && in(lattice.index(cell))) {
        block->cells.set(c);
      }
    }
    return block->cells.any();
  };
  return set;
}

// Per vertex of a mesh of `mask`'s display cells, the working mode shown there: of the
// display cells at its corners in the set, the first one's start mode if it has it, else
// its lowest working mode.
std::vector<int> vertexModes(const SurfaceMesh& mesh, const CellSet& cells, const DisplayLattice& lattice,
                             const std::vector<std::uint64_t>& mask, int start_mode) {
  std::vector<int> modes(mesh.vertices.size(), start_mode);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    for (int corner = 0; corner < 8; ++corner) {
      GridCell at{};
      bool within = true;
      for (int d = 0; d < 3; ++d) {
        const double offset = ((corner >> d & 1) ? 0.5 : -0.5) * cells.steps[d];
        at[d] = static_cast<std::int64_t>(std::floor((mesh.vertices[v][d] + offset - cells.origin[d]) / cells.steps[d]));
        within = within && at[d] >= 0 && at[d] < lattice.size(d);
      }
      const std::uint64_t here = within ? mask[lattice.index(at)] : 0;
      if (here == 0) continue;
      modes[v] = (here >> start_mode & 1) ? start_mode : __builtin_ctzll(here);
      break;
    }
  }
  return modes;
}

}  // namespace

DisplaySurfaces displaySurfaces(const WorkspaceAnalysis& analysis, const DisplayLimits& limits, std::int8_t assembly_mode,
                                bool per_mode) {
  const Grid& grid = analysis.grid();
  DisplaySurfaces surfaces;
  if (grid.dims() != 3 || !grid.isSpatial()) return surfaces;
  const int factor = firstFactor(grid, limits.display_step);
  const DisplayLattice lattice(grid, factor);
  std::vector<std::uint64_t> masks[2];
  membership(analysis, lattice, masks);
  surfaces.cell_size = factor * grid.step(0);
  const MeshOptions options{kDisplaySmoothing, limits.max_triangles};
  const BlockLayout& blocks = analysis.blocks();
  const int modes = static_cast<int>(analysis.modes().size());
  for (int s = 0; s < 2; ++s) {
    const AssemblyModeSummary& am = analysis.assemblyModes()[s];
    if ((assembly_mode > 0 && s == 1) || (assembly_mode < 0 && s == 0)) continue;
    const std::vector<std::uint64_t>& mask = masks[s];
    const CellSet maximal = displayCells(grid, lattice, factor, [&](std::uint64_t i) { return mask[i] != 0; });
    surfaces.maximal[s] = surfaceMesh(maximal, options);
    surfaces.maximal_vertex_modes[s] = vertexModes(surfaces.maximal[s], maximal, lattice, mask, analysis.startMode());
    if (am.traditional_region >= 0) {
      const Region& traditional = analysis.regions()[am.traditional_region];
      surfaces.traditional[s] = surfaceMesh(displayCells(grid, lattice, factor, [&](std::uint64_t i) {
        std::uint64_t block = 0;
        int cell = 0;
        return (mask[i] >> traditional.mode & 1) && blocks.locate(lattice.sampleCell(i), &block, &cell) &&
               analysis.label(block, cell, traditional.mode) == am.traditional_region;
      }), options);
    }
    if (!per_mode) continue;
    surfaces.modes[s].resize(modes);
    for (int m = 0; m < modes; ++m) {
      surfaces.modes[s][m] =
          surfaceMesh(displayCells(grid, lattice, factor, [&](std::uint64_t i) { return (mask[i] >> m & 1) != 0; }), options);
    }
  }
  return surfaces;
}

std::vector<TransitionMark> transitionMarks(const WorkspaceAnalysis& analysis, std::int8_t assembly_mode) {
  const std::vector<Region>& regions = analysis.regions();
  const TransitionGraph& graph = analysis.transitions();
  std::vector<TransitionMark> marks;
  for (const Transition& t : graph.transitions) {
    if ((assembly_mode != 0 && t.sign != assembly_mode) || t.points.empty()) continue;
    if (regions[t.from_region].debris || regions[t.to_region].debris) continue;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (std::uint32_t p : t.points) centroid += graph.points[p].position;
    centroid /= static_cast<double>(t.points.size());
    // A point of the transition itself: the centroid of a curved one can lie outside it.
    TransitionMark mark;
    double nearest = std::numeric_limits<double>::infinity();
    for (std::uint32_t p : t.points) {
      const double distance = (graph.points[p].position - centroid).squaredNorm();
      if (distance < nearest) nearest = distance, mark.position = graph.points[p].position;
    }
    mark.sign = t.sign;
    mark.input = t.input;
    mark.from_mode = regions[t.from_region].mode;
    mark.to_mode = regions[t.to_region].mode;
    mark.points = t.points.size();
    marks.push_back(mark);
  }
  return marks;
}

}  // namespace maximal_workspace
