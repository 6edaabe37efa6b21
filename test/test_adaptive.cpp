// The adaptive workspace (issue 7) against the dense wave front: every fine voxel gets the
// same classification, and regions, transitions and the per assembly mode figures agree.
// Also the block machinery on its own: layout round trips and component labelling against
// a plain flood fill on a synthetic field.

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include <gtest/gtest.h>

#include "maximal_workspace/io/octree_export.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/planner/path_planner.h"
#include "maximal_workspace/planner/trajectory.h"
#include "maximal_workspace/planner/verification.h"
#include "maximal_workspace/regions/adaptive_analysis.h"
#include "fig14_goal.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

GridSpec xyzSpec(const RobotModel& model, double step) {
  GridSpec spec;
  spec.variables = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
  spec.steps = {step};
  spec.start = model.reference.pose;
  return spec;
}

// (mode, sign, voxels, debris) of every region, sorted: region ids differ between the two
// computations (wave-front order against block order), the regions must not.
std::vector<std::tuple<int, int, std::uint64_t, bool>> regionSignature(const std::vector<Region>& regions) {
  std::vector<std::tuple<int, int, std::uint64_t, bool>> result;
  for (const Region& region : regions) result.emplace_back(region.mode, region.sign, region.voxels, region.debris);
  std::sort(result.begin(), result.end());
  return result;
}

// Transitions as (mode, sign, voxels) of both ends: ids differ, the region pairs must not.
std::vector<std::tuple<int, int, std::uint64_t, int, std::uint64_t>> transitionSignature(
    const TransitionGraph& graph, const std::vector<Region>& regions) {
  std::vector<std::tuple<int, int, std::uint64_t, int, std::uint64_t>> result;
  for (const Transition& edge : graph.transitions) {
    const Region &from = regions[edge.from_region], &to = regions[edge.to_region];
    result.emplace_back(from.mode, from.sign, from.voxels, to.mode, to.voxels);
  }
  std::sort(result.begin(), result.end());
  return result;
}

void expectAdaptiveEqualsDense(double step) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis dense = analyseWorkspace(model, xyzSpec(model, step), {});
  const AdaptiveAnalysis adaptive = analyseWorkspaceAdaptive(model, xyzSpec(model, step), {});
  const Grid& grid = dense.grid;
  const BlockLayout& layout = adaptive.workspace.layout;
  ASSERT_EQ(adaptive.grid.cellCount(), grid.cellCount());
  const int modes = dense.map.mode_count;

  // Voxel by voxel, over the whole box.
  std::uint64_t inside = 0, wrong_inside = 0, wrong_sign = 0, singular = 0, band_voxels = 0;
  for (std::uint64_t index = 0; index < grid.cellCount(); ++index) {
    const GridCell cell = grid.cell(index);
    std::uint64_t block = 0;
    int block_cell = 0;
    ASSERT_TRUE(layout.locate({cell[0], cell[1], cell[2]}, &block, &block_cell));
    ASSERT_EQ(layout.gridIndex({cell[0], cell[1], cell[2]}), index);
    const CellCode code = adaptive.workspace.codes.code(block, block_cell);
    const std::uint32_t voxel = dense.map.cell_voxel[index];
    const bool dense_inside = voxel < kCellOutside;
    if (dense_inside != codeInside(code)) {
      ++wrong_inside;
      continue;
    }
    if (!dense_inside) continue;
    ++inside;
    bool in_band = false;
    for (int m = 0; m < modes; ++m) {
      wrong_sign += codeSign(code, m) != dense.map.sign(voxel, m);
      singular += dense.map.sign(voxel, m) == 0;
      in_band = in_band || dense.map.sign(voxel, m) == 0;
    }
    band_voxels += in_band;
  }
  EXPECT_EQ(wrong_inside, 0u);
  EXPECT_EQ(wrong_sign, 0u);
  EXPECT_EQ(inside, dense.map.voxelCount());
  EXPECT_EQ(adaptive.workspace.inside_cells, dense.map.voxelCount());
  EXPECT_GT(singular, 0u) << "the singular band should be met, or the test checks less than it claims";
  EXPECT_LT(adaptive.workspace.evaluated, grid.cellCount()) << "nothing was left unevaluated";
  const std::uint64_t blocks = layout.blockCount(), mixed = adaptive.workspace.codes.pageCount();
  EXPECT_LT(mixed, blocks) << "every block is mixed: nothing is stored coarse";
  std::printf("step %g m: %llu of %llu box cells classified, %llu of %llu blocks mixed; %.2f %% of the voxels in "
              "some working mode's singular band\n",
              step, static_cast<unsigned long long>(adaptive.workspace.evaluated),
              static_cast<unsigned long long>(grid.cellCount()), static_cast<unsigned long long>(mixed),
              static_cast<unsigned long long>(blocks), 100.0 * static_cast<double>(band_voxels) / static_cast<double>(inside));

  EXPECT_EQ(regionSignature(adaptive.regions.regions), regionSignature(dense.regions.regions));
  EXPECT_EQ(transitionSignature(adaptive.transitions.graph, adaptive.regions.regions),
            transitionSignature(dense.transitions, dense.regions.regions));
  EXPECT_EQ(adaptive.transitions.graph.points.size(), dense.transitions.points.size());
  EXPECT_EQ(adaptive.transitions.ikp_faces, [&] {
    std::uint64_t faces = 0;  // dense faces per (voxel, dim, direction), not per chain
    for (std::size_t f = 0; f < dense.singularities.ikp.size(); ++f) {
      const IkpBoundaryFace &face = dense.singularities.ikp[f];
      faces += f == 0 || dense.singularities.ikp[f - 1].voxel != face.voxel || dense.singularities.ikp[f - 1].dim != face.dim ||
               dense.singularities.ikp[f - 1].direction != face.direction;
    }
    return faces;
  }());
  // Octrees from the blocks: the maximal workspaces byte for byte as the dense export; the
  // region labels with the same nodes, their ids mapped one to one.
  for (std::int8_t sign : {1, -1}) {
    std::ostringstream want_bytes, got_bytes;
    maximalWorkspaceOctree(dense, sign)->writeBinary(want_bytes);
    const std::unique_ptr<octomap::OcTree> tree = maximalWorkspaceOctree(adaptive, sign);
    tree->writeBinary(got_bytes);
    EXPECT_EQ(got_bytes.str(), want_bytes.str()) << "maximal workspace octree of sign " << int(sign);
    EXPECT_GT(tree->getNumLeafNodes(), 0u);
  }
  for (int m : {0, modes - 1}) {
    const std::unique_ptr<RegionLabelOcTree> want = regionLabelOctree(dense, m), got = regionLabelOctree(adaptive, m);
    ASSERT_EQ(got->getNumLeafNodes(), want->getNumLeafNodes());
    std::map<std::int32_t, std::int32_t> dense_to_adaptive;
    auto leaf = want->begin_leafs();
    for (auto it = got->begin_leafs(); it != got->end_leafs(); ++it, ++leaf) {
      ASSERT_EQ(it.getKey(), leaf.getKey());
      ASSERT_EQ(it.getDepth(), leaf.getDepth());
      const auto [entry, inserted] = dense_to_adaptive.emplace(leaf->label(), it->label());
      ASSERT_EQ(entry->second, it->label()) << "one dense region split in two";
    }
    std::set<std::int32_t> images;
    for (const auto& [from, to] : dense_to_adaptive) images.insert(to);
    EXPECT_EQ(images.size(), dense_to_adaptive.size()) << "two dense regions merged";
  }
  for (int a = 0; a < 2; ++a) {
    const AssemblyModeSummary &want = dense.assembly_modes[a], &got = adaptive.assembly_modes[a];
    SCOPED_TRACE(a == 0 ? "assembly mode +" : "assembly mode -");
    EXPECT_EQ(got.regions, want.regions);
    EXPECT_EQ(got.debris_regions, want.debris_regions);
    EXPECT_EQ(got.transitions, want.transitions);
    EXPECT_EQ(got.components, want.components);
    EXPECT_EQ(got.maximal_voxels, want.maximal_voxels);
    EXPECT_EQ(got.reachable_voxels, want.reachable_voxels);
    EXPECT_DOUBLE_EQ(got.traditional_volume, want.traditional_volume);
  }
}

TEST(AdaptiveWorkspace, EqualsTheDenseWaveFrontAt10mm) { expectAdaptiveEqualsDense(0.01); }

TEST(AdaptiveWorkspace, EqualsTheDenseWaveFrontAt5mm) { expectAdaptiveEqualsDense(0.005); }

TEST(AdaptivePlanner, PlansThroughTransitionsLikeTheDensePlanner) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis dense = analyseWorkspace(model, xyzSpec(model, 0.01), {});
  const AdaptiveAnalysis adaptive = analyseWorkspaceAdaptive(model, xyzSpec(model, 0.01), {});
  const PathPlanner on_dense(model, dense, 1e-3), on_adaptive(model, adaptive, 1e-3);

  const std::uint32_t goal_voxel = test::fig14Goal(dense);
  ASSERT_GT(goal_voxel, 0u);
  const Pose goal = dense.grid.pose(dense.map.voxel_cell[goal_voxel]);
  PlanRequest request;
  request.start = model.reference.pose;
  request.start_mode = dense.start_mode;
  request.goal = goal;
  ASSERT_EQ(adaptive.start_mode, dense.start_mode);

  const Plan want = on_dense.plan(request), got = on_adaptive.plan(request);
  ASSERT_TRUE(want.success) << want.message;
  ASSERT_TRUE(got.success) << got.message;
  std::printf("dense plan %.3f m with %zu transitions, adaptive plan %.3f m with %zu transitions\n", want.length,
              want.transitions.size(), got.length, got.transitions.size());
  EXPECT_GE(got.transitions.size(), 1u);
  EXPECT_EQ(got.sign, want.sign);
  // Portals come from the same transition points in another order, so the routes may
  // differ a little; not by much, on the same regions.
  EXPECT_NEAR(got.length, want.length, 0.15 * want.length);
  const InputTrajectory trajectory =
      inputTrajectory(model, adaptive.modes, adaptive.grid.step(0), got, InputLimits{{1.0, 0.5, 0.5}, {2.0, 1.0, 1.0}});
  const Verification verification = verifyByDkpContinuation(model, trajectory, got.sign);
  EXPECT_TRUE(verification.passed) << verification.message;

  // Refusals agree too: one working mode alone, and a goal outside the workspace.
  request.allowed_modes = {request.start_mode};
  EXPECT_FALSE(on_adaptive.plan(request).success);
  EXPECT_EQ(on_adaptive.plan(request).message, on_dense.plan(request).message);
  request.allowed_modes.clear();
  request.goal.position = Eigen::Vector3d(0.0, 0.0, 5.0);
  EXPECT_EQ(on_adaptive.plan(request).message, on_dense.plan(request).message);
  EXPECT_FALSE(on_adaptive.plan(request).success);
}

TEST(BlockLayout, CellsAndNeighboursRoundTrip) {
  const RobotModel& model = test::deltaLike();
  GridSpec spec = xyzSpec(model, 0.03);
  const Grid grid(model, spec);
  const BlockLayout layout(grid);
  for (std::uint64_t index = 0; index < grid.cellCount(); index += 7) {
    const GridCell cell = grid.cell(index);
    const BlockCoords coords = {cell[0], cell[1], cell[2]};
    std::uint64_t block = 0;
    int block_cell = 0;
    ASSERT_TRUE(layout.locate(coords, &block, &block_cell));
    EXPECT_EQ(layout.cellCoords(block, block_cell), coords);
    // Blocks are octree nodes: the first cell of a block has a lattice index divisible by
    // the block side.
    const BlockCoords first = layout.cellCoords(block, 0);
    for (int d = 0; d < 3; ++d) EXPECT_EQ((first[d] + grid.firstLatticeIndex(d)) % kBlockSide, 0);
    for (int d = 0; d < 3; ++d) {
      for (int direction : {-1, 1}) {
        std::uint64_t next_block = 0;
        int next_cell = 0;
        BlockCoords want = coords;
        want[d] += direction;
        if (!layout.neighbour(block, block_cell, d, direction, &next_block, &next_cell)) continue;
        EXPECT_EQ(layout.cellCoords(next_block, next_cell), want);
      }
    }
  }
}

TEST(BlockLabels, ComponentsMatchAFloodFillOnASyntheticField) {
  // Codes 0 and 1 in two slabs, 2 in a ball, 3 elsewhere in the first slab, and a wall of
  // outside cells: code 3 has key 0, so components follow the slabs and the ball, split by
  // the wall.
  const RobotModel& model = test::deltaLike();
  GridSpec spec = xyzSpec(model, 0.05);
  const Grid grid(model, spec);
  AdaptiveWorkspace workspace(grid);
  const BlockLayout& layout = workspace.layout;
  auto codeAt = [&](const BlockCoords& c) -> CellCode {
    if (!layout.inBox(c)) return kCodeVoid;
    if (c[1] == grid.size(1) / 2) return kCodeOutside;
    const double dx = c[0] - grid.size(0) / 2.0, dy = c[1] - grid.size(1) / 4.0, dz = c[2] - grid.size(2) / 2.0;
    if (dx * dx + dy * dy + dz * dz < 9.0) return 2;
    if (c[2] < 3) return 3;
    return c[0] < grid.size(0) / 3 ? 0 : 1;
  };
  for (std::uint64_t b = 0; b < layout.blockCount(); ++b) {
    std::unique_ptr<CellCode[]> page(new CellCode[kBlockCells]);
    bool uniform = true;
    for (int c = 0; c < kBlockCells; ++c) {
      page[c] = codeAt(layout.cellCoords(b, c));
      uniform = uniform && page[c] == page[0];
    }
    if (uniform) {
      workspace.codes.setUniform(b, page[0]);
    } else {
      workspace.codes.setPage(b, std::move(page));
    }
  }
  std::vector<std::uint8_t> keys(65536, 0);
  keys[0] = 1;
  keys[1] = 2;
  keys[2] = 3;
  LabelLayer layer;
  const std::vector<Component> components = labelComponents(workspace, keys, &layer);

  // Reference: a flood fill over the dense field.
  std::vector<int> reference(grid.cellCount(), -1);
  std::vector<std::uint64_t> sizes;
  for (std::uint64_t seed = 0; seed < grid.cellCount(); ++seed) {
    const GridCell s = grid.cell(seed);
    const int key = keys[codeAt({s[0], s[1], s[2]})];
    if (key == 0 || reference[seed] >= 0) continue;
    std::vector<std::uint64_t> queue = {seed};
    reference[seed] = static_cast<int>(sizes.size());
    for (std::size_t head = 0; head < queue.size(); ++head) {
      for (int d = 0; d < 3; ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t next = 0;
          if (!grid.neighbour(queue[head], d, direction, &next) || reference[next] >= 0) continue;
          const GridCell n = grid.cell(next);
          if (keys[codeAt({n[0], n[1], n[2]})] != key) continue;
          reference[next] = reference[seed];
          queue.push_back(next);
        }
      }
    }
    sizes.push_back(queue.size());
  }
  ASSERT_EQ(components.size(), sizes.size());
  EXPECT_EQ(sizes.size(), 5u) << "two slabs on each side of the wall, and the ball";
  // Same partition: labels map one to one, with the same sizes.
  std::map<int, std::int32_t> to_adaptive;
  for (std::uint64_t index = 0; index < grid.cellCount(); ++index) {
    const GridCell cell = grid.cell(index);
    std::uint64_t block = 0;
    int block_cell = 0;
    layout.locate({cell[0], cell[1], cell[2]}, &block, &block_cell);
    const std::int32_t label = layer.label(block, block_cell);
    if (reference[index] < 0) {
      ASSERT_EQ(label, kNoLabel);
      continue;
    }
    const auto [entry, inserted] = to_adaptive.emplace(reference[index], label);
    ASSERT_EQ(entry->second, label);
    if (inserted) {
      EXPECT_EQ(components[label].cells, sizes[reference[index]]);
    }
  }
  EXPECT_EQ(to_adaptive.size(), sizes.size());
}

TEST(AdaptiveWorkspace, RefusesGridsItCannotHandle) {
  const RobotModel& model = test::deltaLike();
  GridSpec two = xyzSpec(model, 0.02);
  two.variables = {OutputVariable::X, OutputVariable::Y};
  EXPECT_THROW(analyseWorkspaceAdaptive(model, two, {}), InputError);
  AnalysisOptions uncoupled;
  uncoupled.uncoupled = true;  // 64 working modes of the auxiliary
  uncoupled.start_mode = "nnppnn";
  EXPECT_THROW(analyseWorkspaceAdaptive(model, xyzSpec(model, 0.02), uncoupled), InputError);

  // A start in the box but not assembled: refused before any work, as the dense analysis
  // refuses it.
  GridSpec far = xyzSpec(model, 0.02);
  far.start.position.z() += 10.0;
  far.bounds = {{-2.0, 2.0}, {-2.0, 2.0}, {-12.0, 12.0}};
  AnalysisOptions options;
  options.start_mode = coupledWorkingModes(model).front().name;
  std::string dense_message, adaptive_message;
  try {
    analyseWorkspace(model, far, options);
  } catch (const InputError& error) {
    dense_message = error.what();
  }
  try {
    analyseWorkspaceAdaptive(model, far, options);
  } catch (const InputError& error) {
    adaptive_message = error.what();
  }
  EXPECT_NE(dense_message.find("outside the workspace"), std::string::npos) << dense_message;
  EXPECT_EQ(adaptive_message, dense_message);
}

}  // namespace
}  // namespace maximal_workspace
