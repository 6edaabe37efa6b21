// The block engine against the brute-force dense reference (dense_reference.h), cell by
// cell, for every kind of grid and robot it serves: x y z with the couple factorisation,
// robots with limits (actuator ranges, cones, rod interference),
// a planar x y grid, the 64 working modes of the uncoupled auxiliary (the generic LU
// path), a grid with a rotational variable, and a planar robot over x y phi whose regions
// cross phi = +/-pi (a periodic grid).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "dense_reference.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

using OV = OutputVariable;

GridSpec gridSpec(const RobotModel& model, std::vector<OutputVariable> variables, std::vector<double> steps) {
  GridSpec spec;
  spec.variables = std::move(variables);
  spec.steps = std::move(steps);
  spec.start = model.reference.pose;
  return spec;
}

const RobotModel& planar3rrr() {
  static const RobotModel model = loadRobotFile(test::sourcePath("test/robots/planar_3rrr.yaml"));
  return model;
}

// (mode, sign, voxels, debris) of every region, sorted: ids differ (block order against
// scan order), the regions must not.
std::vector<std::tuple<int, int, std::uint64_t, bool>> regionSignature(const std::vector<Region>& regions) {
  std::vector<std::tuple<int, int, std::uint64_t, bool>> result;
  for (const Region& region : regions) result.emplace_back(region.mode, region.sign, region.voxels, region.debris);
  std::sort(result.begin(), result.end());
  return result;
}

std::vector<std::tuple<int, int, std::uint64_t, int, std::uint64_t>> transitionSignature(const WorkspaceAnalysis& a) {
  std::vector<std::tuple<int, int, std::uint64_t, int, std::uint64_t>> result;
  for (const Transition& edge : a.transitions().transitions) {
    const Region &from = a.regions()[edge.from_region], &to = a.regions()[edge.to_region];
    result.emplace_back(from.mode, edge.sign, from.voxels, to.mode, to.voxels);
  }
  std::sort(result.begin(), result.end());
  return result;
}

// Every cell of the box: inside alike, and each working mode's regions the same partition
// (labels map one to one); then every count and figure. With a margin, the cells under
// it must be met, or the comparison covers less than it claims.
void expectEqualsReference(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  const WorkspaceAnalysis analysis = analyseWorkspace(model, spec, options);
  const test::DenseReference ref = test::denseReference(model, spec, options);
  const Grid& grid = analysis.grid();
  ASSERT_EQ(grid.cellCount(), ref.grid.cellCount());
  const int modes = static_cast<int>(analysis.modes().size());
  ASSERT_EQ(modes, ref.modes);
  std::vector<std::map<std::int32_t, std::int32_t>> to_engine(modes);
  std::uint64_t wrong_inside = 0, wrong_label = 0, band_cells = 0;
  for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
    if (analysis.inside(cell) != (ref.inside[cell] != 0)) {
      ++wrong_inside;
      continue;
    }
    for (int m = 0; m < modes; ++m) {
      const std::int32_t want = ref.label(cell, m), got = analysis.label(cell, m);
      band_cells += ref.inside[cell] && ref.sign(cell, m) == 0;
      if ((want < 0) != (got < 0)) {
        ++wrong_label;
        continue;
      }
      if (want < 0) continue;
      const auto [entry, inserted] = to_engine[m].emplace(want, got);
      wrong_label += entry->second != got;
    }
  }
  EXPECT_EQ(wrong_inside, 0u);
  EXPECT_EQ(wrong_label, 0u);
  if (options.margin > 0.0) {
    EXPECT_GT(band_cells, 0u) << "no cell under the margin";
  }
  EXPECT_EQ(analysis.voxelCount(), ref.voxels);
  EXPECT_LT(analysis.posesEvaluated(), grid.cellCount()) << "the adaptive classification left nothing unevaluated";
  EXPECT_EQ(regionSignature(analysis.regions()), regionSignature(ref.regions));
  EXPECT_EQ(transitionSignature(analysis), ref.transitions);
  const SingularityCounts& counts = analysis.singularityCounts();
  EXPECT_EQ(counts.dkp_entries, ref.dkp_entries);
  EXPECT_EQ(counts.ikp_faces, ref.ikp_faces);
  EXPECT_EQ(counts.ikp_entries, ref.ikp_entries);
  EXPECT_EQ(counts.thin_layer_faces, ref.thin_layer_faces);
  EXPECT_EQ(counts.limit_entries, ref.wall_entries[0]);
  EXPECT_EQ(counts.cone_entries, ref.wall_entries[1]);
  EXPECT_EQ(counts.interference_entries, ref.wall_entries[2]);
  EXPECT_EQ(analysis.transitions().points.size(), ref.transition_points);
  for (int a = 0; a < 2; ++a) {
    SCOPED_TRACE(a == 0 ? "assembly mode +" : "assembly mode -");
    const AssemblyModeSummary& got = analysis.assemblyModes()[a];
    EXPECT_EQ(got.maximal_voxels, ref.maximal_voxels[a]);
    EXPECT_EQ(got.reachable_voxels, ref.reachable_voxels[a]);
    EXPECT_EQ(got.components, ref.components[a]);
  }
  std::printf("%s over %d variables: %llu of %llu box cells classified, %zu regions, %zu transitions, %llu faces "
              "across a thin layer, walls %llu actuator %llu cone %llu interference\n",
              model.name.c_str(), grid.dims(), static_cast<unsigned long long>(analysis.posesEvaluated()),
              static_cast<unsigned long long>(grid.cellCount()), analysis.regions().size(),
              analysis.transitions().transitions.size(), static_cast<unsigned long long>(counts.thin_layer_faces),
              static_cast<unsigned long long>(counts.limit_entries), static_cast<unsigned long long>(counts.cone_entries),
              static_cast<unsigned long long>(counts.interference_entries));
}

TEST(EngineAgainstReference, DeltaLikeOverXyzAt10mm) {
  const RobotModel& model = test::deltaLike();
  expectEqualsReference(model, gridSpec(model, {OV::X, OV::Y, OV::Z}, {0.01}), {});
}

TEST(EngineAgainstReference, DeltaLikeOverXyzAt5mmWithAMargin) {
  const RobotModel& model = test::deltaLike();
  AnalysisOptions options;
  options.margin = 1e-3;
  expectEqualsReference(model, gridSpec(model, {OV::X, OV::Y, OV::Z}, {0.005}), options);
}

// Robots with limits (actuator ranges, joint cones, rod interference): the reference's
// classifier drops a working mode where it breaks one, and a cell where every working mode
// does is outside the workspace, as in the engine.
TEST(EngineAgainstReference, RobotsWithLimitsAt10mm) {
  for (const char* file : {"config/delta_like_limited.yaml", "config/linear_delta.yaml", "config/rotary_delta.yaml",
                           "test/robots/linear_delta_thick_rods.yaml"}) {
    SCOPED_TRACE(file);
    const RobotModel model = loadRobotFile(test::sourcePath(file));
    expectEqualsReference(model, gridSpec(model, {OV::X, OV::Y, OV::Z}, {0.01}), {});
  }
}

TEST(EngineAgainstReference, FiveBarOverAPlane) {
  const RobotModel& model = test::fiveBar();
  expectEqualsReference(model, gridSpec(model, {OV::X, OV::Y}, {0.004}), {});
}

TEST(EngineAgainstReference, UncoupledAuxiliaryWith64WorkingModes) {
  const RobotModel& model = test::deltaLike();
  AnalysisOptions options;
  options.uncoupled = true;
  expectEqualsReference(model, gridSpec(model, {OV::X, OV::Y, OV::Z}, {0.04}), options);
}

// Holes of the workspace smaller than a block, away from its shell and its middle cell
// (test/robots/five_bar_holes.yaml): no sample of a scheme that samples cubes' shells and
// the middle of each block falls in them, so only the proofs (or a block sampled whole)
// keep them out. Each leg reaches no point closer than 3 mm to its base joint.
TEST(EngineAgainstReference, FiveBarWithHolesSmallerThanABlock) {
  static const RobotModel model = loadRobotFile(test::sourcePath("test/robots/five_bar_holes.yaml"));
  const double step = 0.002, hole_radius = 0.003;
  const GridSpec spec = gridSpec(model, {OV::X, OV::Y}, {step});
  expectEqualsReference(model, spec, {});
  const WorkspaceAnalysis analysis = analyseWorkspace(model, spec, {});
  const Grid& grid = analysis.grid();
  for (int leg = 0; leg < 2; ++leg) {
    const Eigen::Vector3d joint = leg == 0 ? Eigen::Vector3d(-0.107, 0.005, 0.0) : Eigen::Vector3d(0.101, 0.005, 0.0);
    int hole_cells = 0;
    for (int i = -3; i <= 3; ++i) {
      for (int j = -3; j <= 3; ++j) {
        Pose pose = model.reference.pose;
        pose.position = joint + Eigen::Vector3d(i * step, j * step, 0.0);
        if ((pose.position - joint).norm() >= hole_radius) continue;
        std::uint64_t cell = 0;
        ASSERT_TRUE(grid.cellOf(pose, &cell));
        EXPECT_FALSE(analysis.inside(cell)) << "leg " << leg << " cell " << i << " " << j;
        ++hole_cells;
        // Blocks are 8 cells a side, on the lattice k step (block_layout.h): the cell is
        // neither on its block's shell nor the block's middle cell (4, 4).
        int local[2];
        for (int d = 0; d < 2; ++d) {
          const long k = std::lround(std::floor(pose.position[d] / step));
          local[d] = static_cast<int>(((k % 8) + 8) % 8);
          EXPECT_TRUE(local[d] >= 1 && local[d] <= 6) << "leg " << leg << " cell " << i << " " << j;
        }
        EXPECT_FALSE(local[0] == 4 && local[1] == 4);
      }
    }
    EXPECT_EQ(hole_cells, 9) << "leg " << leg;
  }
}

// Six chains, no couples: every working mode's determinant by the generic path, and a
// workspace small enough to lie inside one top cube.
TEST(EngineAgainstReference, HexapodWith64WorkingModes) {
  static const RobotModel model = loadRobotFile(test::sourcePath("config/hexapod_6rss.yaml"));
  expectEqualsReference(model, gridSpec(model, {OV::X, OV::Y, OV::Z}, {0.006}), {});
}

TEST(EngineAgainstReference, DeltaLikeWithATurningPlatform) {
  const RobotModel& model = test::deltaLike();
  GridSpec spec = gridSpec(model, {OV::X, OV::Y, OV::Z, OV::Theta}, {0.06, 0.06, 0.06, 0.05});
  const Grid box(model, gridSpec(model, {OV::X, OV::Y, OV::Z}, {0.06}));
  spec.bounds = {box.spec().bounds[0], box.spec().bounds[1], box.spec().bounds[2], {-0.3, 0.3}};
  expectEqualsReference(model, spec, {});
}

TEST(EngineAgainstReference, PlanarRobotOverAFullTurnOfPhi) {
  const RobotModel& model = planar3rrr();
  const GridSpec spec = gridSpec(model, {OV::X, OV::Y, OV::Phi}, {0.02, 0.02, 0.1});
  ASSERT_TRUE(Grid(model, spec).periodic(2));
  expectEqualsReference(model, spec, {});
}

// Regions that cross phi = +/-pi are one region on a periodic grid: moving the seam (the
// start's phi, which anchors the cells) by a whole number of steps gives the same cells,
// so the same regions, however the seam cuts them.
TEST(PeriodicGrid, RegionsDoNotDependOnWhereTheTurnIsCut) {
  const RobotModel& model = planar3rrr();
  GridSpec spec = gridSpec(model, {OV::X, OV::Y, OV::Phi}, {0.02, 0.02, 2 * M_PI / 60});
  AnalysisOptions options;
  options.start_mode = "ppp";
  const WorkspaceAnalysis at_zero = analyseWorkspace(model, spec, options);
  spec.start.euler_zyz[0] = 17 * 2 * M_PI / 60;  // the seam moves by 17 cells
  const WorkspaceAnalysis moved = analyseWorkspace(model, spec, options);
  EXPECT_EQ(moved.voxelCount(), at_zero.voxelCount());
  EXPECT_EQ(regionSignature(moved.regions()), regionSignature(at_zero.regions()));
  EXPECT_EQ(transitionSignature(moved), transitionSignature(at_zero));
  // Some region of the + assembly mode does cross the seam: cells at the first and at the
  // last phi share a label, the pair being neighbours only through the wrap.
  const Grid& grid = at_zero.grid();
  bool crossing = false;
  for (std::int64_t i = 0; i < grid.size(0) && !crossing; ++i) {
    for (std::int64_t j = 0; j < grid.size(1) && !crossing; ++j) {
      const std::uint64_t first = grid.index({i, j, 0}), last = grid.index({i, j, grid.size(2) - 1});
      for (int m = 0; m < 8; ++m) crossing = crossing || (at_zero.label(first, m) >= 0 && at_zero.label(first, m) == at_zero.label(last, m));
    }
  }
  EXPECT_TRUE(crossing);
}

}  // namespace
}  // namespace maximal_workspace
