// What the topics show of an analysis (io/display_sampling.h): at full resolution every
// singularity entry and every surface cell, checked cell by cell against the analysis's
// own queries; at a coarse display step within the caps, saying how it was thinned.

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "maximal_workspace/io/display_sampling.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "mesh_topology.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

WorkspaceAnalysis deltaLike(double step) {
  return analyseWorkspace(test::deltaLike(), test::referenceGrid(test::deltaLike(), step), {});
}

// In working mode m's non-debris regions of the sign.
bool inSet(const WorkspaceAnalysis& analysis, std::uint64_t cell, int mode, std::int8_t sign) {
  const std::int32_t label = analysis.label(cell, mode);
  return label >= 0 && analysis.regions()[label].sign == sign && !analysis.regions()[label].debris;
}

TEST(DisplaySampling, FullResolutionShowsEverySingularityEntry) {
  const WorkspaceAnalysis analysis = deltaLike(0.03);
  const SingularitySample sample = sampleSingularities(test::deltaLike(), analysis, DisplayLimits{0.0, 10'000'000, 1});
  EXPECT_EQ(sample.decimation.factor, 1);
  const SingularityCounts& counts = analysis.singularityCounts();
  EXPECT_EQ(sample.points.size(), counts.dkp_entries + counts.ikp_entries);
  EXPECT_EQ(sample.decimation.text(), std::to_string(sample.points.size()) + " points for " +
                                          std::to_string(sample.points.size()) +
                                          " entries, one per grid cell, kind and working mode");
  // Every DKP point is a workspace cell centre where its mode's region sign changes or
  // stops; every IKP point is half a step from a workspace cell, towards a cell where its
  // chain cannot be assembled.
  const Grid& grid = analysis.grid();
  for (const SingularityPoint& point : sample.points) {
    Pose pose = grid.spec().start;
    pose.position = point.position;
    if (point.kind == 0) {
      std::uint64_t cell = 0;
      ASSERT_TRUE(grid.cellOf(pose, &cell));
      EXPECT_TRUE(analysis.inside(cell));
      EXPECT_EQ(grid.pose(cell).position, point.position);
      EXPECT_LT(std::abs(point.measure), 0.5f);
      continue;
    }
    ASSERT_EQ(point.kind, 1);
    ASSERT_GE(point.chain, 0);
    int faces = 0;
    for (int d = 0; d < 3; ++d) {
      for (double direction : {-0.5, 0.5}) {
        Pose beside = pose;
        beside.position[d] += direction * grid.step(d);
        std::uint64_t cell = 0;
        if (!grid.cellOf(beside, &cell) || (grid.pose(cell).position - beside.position).norm() > 1e-9) continue;
        Pose across = pose;
        across.position[d] -= direction * grid.step(d);
        faces += analysis.inside(cell) && !solveIkp(test::deltaLike(), across).chains[point.chain].assembled;
      }
    }
    EXPECT_EQ(faces, 1) << "an IKP point is on one face of the workspace";
  }
}

TEST(DisplaySampling, FullResolutionSurfacesAreTheSetsBoundaryCells) {
  const WorkspaceAnalysis analysis = deltaLike(0.03);
  const SurfaceSample sample = sampleSurfaces(analysis, DisplayLimits{0.0, 1, 10'000'000}, 0);
  const Grid& grid = analysis.grid();
  EXPECT_DOUBLE_EQ(sample.cube_size, 0.03);
  for (int s = 0; s < 2; ++s) {
    const std::int8_t sign = s == 0 ? 1 : -1;
    ASSERT_EQ(sample.cubes[s].size(), analysis.modes().size());
    for (int m = 0; m < static_cast<int>(analysis.modes().size()); ++m) {
      // Expected: the cells of the set with a face neighbour out of it, or on the box's side.
      std::set<std::uint64_t> expected, shown;
      for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
        if (!inSet(analysis, cell, m, sign)) continue;
        for (int d = 0; d < 3; ++d) {
          for (int direction : {-1, 1}) {
            std::uint64_t next = 0;
            if (!grid.neighbour(cell, d, direction, &next) || !inSet(analysis, next, m, sign)) expected.insert(cell);
          }
        }
      }
      for (const Eigen::Vector3d& centre : sample.cubes[s][m]) {
        Pose pose = grid.spec().start;
        pose.position = centre;
        std::uint64_t cell = 0;
        ASSERT_TRUE(grid.cellOf(pose, &cell));
        shown.insert(cell);
      }
      EXPECT_EQ(shown, expected) << "mode " << m << " sign " << int(sign);
    }
  }
}

TEST(DisplaySampling, CoarseDisplayKeepsWithinTheCapsAndSaysHow) {
  const WorkspaceAnalysis analysis = deltaLike(0.01);
  const DisplayLimits limits{0.02, 20'000, 5'000};
  const SingularitySample singular = sampleSingularities(test::deltaLike(), analysis, limits);
  EXPECT_LE(singular.points.size(), limits.max_points);
  EXPECT_GE(singular.decimation.factor, 2);
  EXPECT_GT(singular.points.size(), 1000u) << "thinned, not emptied";
  EXPECT_NE(singular.decimation.text().find(", one per display cell of " + std::to_string(singular.decimation.factor) +
                                            " grid steps (display_step, doubled while over max_points)"),
            std::string::npos)
      << singular.decimation.text();
  const SurfaceSample surfaces = sampleSurfaces(analysis, limits, 1);
  std::size_t cubes = 0;
  for (const auto& per_mode : surfaces.cubes[0]) cubes += per_mode.size();
  EXPECT_TRUE(surfaces.cubes[1].empty()) << "assembly mode + only";
  EXPECT_LE(cubes, limits.max_cubes);
  EXPECT_GT(cubes, 500u);
  EXPECT_DOUBLE_EQ(surfaces.cube_size, surfaces.decimation.factor * 0.01);
  EXPECT_EQ(surfaces.decimation.shown, cubes);
}

// A display step beyond INT_MAX grid steps (issue 28: an undefined conversion, which gave
// full resolution here) is one display cell over the whole box.
TEST(DisplaySampling, ADisplayStepPastAnyIntegerIsOneDisplayCell) {
  const WorkspaceAnalysis analysis = deltaLike(0.01);
  const DisplayLimits limits{1e30, 20'000, 5'000};
  const Grid& grid = analysis.grid();
  std::int64_t largest = 1;
  for (int d = 0; d < grid.dims(); ++d) largest = std::max(largest, grid.size(d));
  EXPECT_GE(sampleSingularities(test::deltaLike(), analysis, limits).decimation.factor, largest);
  EXPECT_GE(sampleSurfaces(analysis, limits, 0).decimation.factor, largest);
}

// The surfaces a display draws (displaySurfaces): closed and outward on the display
// lattice, the maximal one enclosing about the maximal workspace's volume (the lattice's
// cells taken by their middle cell: within the band of its boundary cells), each vertex
// coloured by a working mode that has a region of that sign beside it, the start's first.
TEST(DisplaySampling, DisplaySurfacesAreClosedAndColouredByAWorkingModeThere) {
  const WorkspaceAnalysis analysis = deltaLike(0.01);
  DisplayLimits limits;
  limits.display_step = 0.02;
  const DisplaySurfaces surfaces = displaySurfaces(analysis, limits, 0);
  EXPECT_DOUBLE_EQ(surfaces.cell_size, 0.02);
  for (int s = 0; s < 2; ++s) {
    const AssemblyModeSummary& am = analysis.assemblyModes()[s];
    SCOPED_TRACE(int(am.sign));
    const SurfaceMesh& maximal = surfaces.maximal[s];
    ASSERT_FALSE(maximal.triangles.empty());
    EXPECT_TRUE(test::topology(maximal).closed_and_oriented);
    EXPECT_NEAR(enclosedVolume(maximal), am.maximal_volume, 0.03 * am.maximal_volume);
    EXPECT_TRUE(test::topology(surfaces.traditional[s]).closed_and_oriented);
    EXPECT_NEAR(enclosedVolume(surfaces.traditional[s]), am.traditional_volume, 0.03 * am.traditional_volume);
    ASSERT_EQ(surfaces.maximal_vertex_modes[s].size(), maximal.vertices.size());
    std::set<int> shown(surfaces.maximal_vertex_modes[s].begin(), surfaces.maximal_vertex_modes[s].end());
    EXPECT_GE(shown.size(), 2u);
    EXPECT_EQ(shown.count(analysis.startMode()), 1u);
    // Each working mode's own surface encloses about its regions of that sign.
    ASSERT_EQ(surfaces.modes[s].size(), analysis.modes().size());
    for (std::size_t m = 0; m < analysis.modes().size(); ++m) {
      double volume = 0.0;
      for (const Region& region : analysis.regions()) {
        if (region.mode == static_cast<int>(m) && region.sign == am.sign && !region.debris) volume += region.volume;
      }
      EXPECT_NEAR(enclosedVolume(surfaces.modes[s][m]), volume, 0.05 * volume + 1e-3) << analysis.modes()[m].name;
    }
  }
}

TEST(DisplaySampling, OneMarkPerTransitionOnItsIkpBoundary) {
  const WorkspaceAnalysis analysis = deltaLike(0.02);
  const RobotModel& model = test::deltaLike();
  const std::vector<TransitionMark> marks = transitionMarks(analysis, 0);
  int per_sign[2] = {0, 0};
  for (const TransitionMark& mark : marks) {
    ++per_sign[mark.sign > 0 ? 0 : 1];
    const std::string& from = analysis.modes()[mark.from_mode].name;
    const std::string& to = analysis.modes()[mark.to_mode].name;
    // The two working modes differ in the changing couple's branch alone...
    for (std::size_t letter = 0; letter < from.size(); ++letter) {
      EXPECT_EQ(from[letter] != to[letter], static_cast<int>(letter) == mark.input) << from << " -> " << to;
    }
    // ...and the mark is on that couple's IKP boundary: one of its chains has a zero
    // discriminant there (both branches meet), to the bisection's tolerance, while every
    // other chain assembles.
    Pose pose = analysis.grid().spec().start;
    pose.position = mark.position;
    const IkpResult ikp = solveIkp(model, pose);
    double closest = INFINITY;
    const std::vector<int>& couple = model.inputs[mark.input].chains;
    for (int c = 0; c < model.chainCount(); ++c) {
      if (std::find(couple.begin(), couple.end(), c) != couple.end()) {
        closest = std::min(closest, std::abs(ikp.chains[c].discriminant));
      } else {
        EXPECT_TRUE(ikp.chains[c].assembled) << model.chains[c]->name() << " at " << mark.position.transpose();
      }
    }
    EXPECT_LT(closest, 1e-6) << "mark at " << mark.position.transpose();
    EXPECT_GT(mark.points, 0u);
  }
  // The summary counts the same transitions, between non-debris regions (computed apart).
  EXPECT_EQ(per_sign[0], analysis.assemblyModes()[0].transitions);
  EXPECT_EQ(per_sign[1], analysis.assemblyModes()[1].transitions);
  EXPECT_GT(per_sign[0], 5);
  EXPECT_EQ(transitionMarks(analysis, -1).size(), static_cast<std::size_t>(per_sign[1]));
}

}  // namespace
}  // namespace maximal_workspace
