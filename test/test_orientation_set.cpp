// Grids over positions and a tilt-and-torsion orientation set: the poses they stand for,
// the pole joining the first tilt layer, and the per-position coverage against a pose by
// pose reference of its own (IKP and an LU determinant per working mode).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/regions/pose_query.h"
#include "maximal_workspace/regions/orientation_coverage.h"
#include "maximal_workspace/workspace/block_layout.h"
#include "orientation_grid.h"
#include "test_support.h"
#include "workspace/block_components.h"

namespace maximal_workspace {
namespace {

using test::orientationGrid;
using test::tiltTorsionRotation;

TEST(OrientationSet, CellsStandForTheirTiltAndTorsion) {
  const RobotModel& model = test::hexapod();
  const Grid grid(model, orientationGrid(model, 0.01, {{-0.05, 0.05}, {-0.05, 0.05}, {0.1, 0.2}},
                                         OrientationSet{0.3, {-0.4, 0.2}, 0.07}));
  ASSERT_TRUE(grid.tiltTorsion());
  EXPECT_TRUE(grid.periodic(3));    // azimuth: a full turn
  EXPECT_FALSE(grid.periodic(5));   // torsion: a part of one
  // The cells cover the set exactly: tilt from the pole to 0.3, torsion -0.4 to 0.2.
  EXPECT_NEAR(grid.centre(4, 0) - 0.5 * grid.step(4), 0.0, 1e-12);
  EXPECT_NEAR(grid.centre(4, grid.size(4) - 1) + 0.5 * grid.step(4), 0.3, 1e-12);
  EXPECT_NEAR(grid.centre(5, 0) - 0.5 * grid.step(5), -0.4, 1e-12);
  EXPECT_NEAR(grid.centre(5, grid.size(5) - 1) + 0.5 * grid.step(5), 0.2, 1e-12);
  const Eigen::Matrix3d reference = model.reference.pose.rotation();
  for (int trial = 0; trial < 500; ++trial) {
    const std::uint64_t index = static_cast<std::uint64_t>(test::uniform(0.0, 1.0) * grid.cellCount()) % grid.cellCount();
    const GridCell cell = grid.cell(index);
    const double a = grid.centre(3, cell[3]), t = grid.centre(4, cell[4]), s = grid.centre(5, cell[5]);
    const Pose pose = grid.pose(index);
    EXPECT_TRUE(pose.rotation().isApprox(tiltTorsionRotation(reference, a, t, s), 1e-12));
    // Tilt: the angle between the platform's axis and the reference one.
    const double tilt = std::acos(std::clamp((reference.col(2)).dot(pose.rotation().col(2)), -1.0, 1.0));
    EXPECT_NEAR(tilt, t, 1e-7);
    std::uint64_t back = 0;
    ASSERT_TRUE(grid.cellOf(pose, &back));
    EXPECT_EQ(back, index);
    // Any pose of the cell, by the definition, is a rotation of the cell's box of ZYZ angles.
    const PoseBox box = grid.cellBox(index);
    const double pa = a + test::uniform(-0.5, 0.5) * grid.step(3), pt = t + test::uniform(-0.5, 0.5) * grid.step(4),
                 ps = s + test::uniform(-0.5, 0.5) * grid.step(5);
    const Eigen::Matrix3d inside = tiltTorsionRotation(reference, pa, pt, ps);
    Pose zyz;
    zyz.euler_zyz = box.centre.euler_zyz + Eigen::Vector3d(pa - a, pt - t, (ps - pa) - (s - a));
    EXPECT_TRUE(zyz.rotation().isApprox(inside, 1e-12));
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE(std::abs(zyz.euler_zyz[k] - box.centre.euler_zyz[k]), box.angle_half_width[k] + 1e-12);
    }
    // And phi + psi, which the certificates' rotation enclosure takes on its own, within
    // the torsion's half step alone.
    ASSERT_TRUE(box.angle_sum_half_width.has_value());
    EXPECT_NEAR(*box.angle_sum_half_width, 0.5 * grid.step(5), 1e-15);
    EXPECT_LE(std::abs((zyz.euler_zyz[0] + zyz.euler_zyz[2]) - (box.centre.euler_zyz[0] + box.centre.euler_zyz[2])),
              *box.angle_sum_half_width + 1e-12);
  }
}

TEST(OrientationSet, ABadSetIsRefusedNamingWhatIsWrong) {
  const RobotModel& model = test::hexapod();
  const auto message = [&](const OrientationSet& set, std::vector<OutputVariable> variables) {
    GridSpec spec;
    spec.variables = std::move(variables);
    spec.steps = {0.01};
    spec.start = model.reference.pose;
    try {
      addOrientationSet(model, set, &spec);
      Grid(model, spec);
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  const std::vector<OutputVariable> xyz = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
  EXPECT_NE(message({0.0, {-0.1, 0.1}, 0.05}, xyz).find("tilt_max must be in (0, pi]"), std::string::npos);
  EXPECT_NE(message({0.3, {0.1, -0.1}, 0.05}, xyz).find("torsion must be [min, max]"), std::string::npos);
  EXPECT_NE(message({0.3, {-0.1, 0.1}, 0.0}, xyz).find("angle_step must be in (0, tilt_max]"), std::string::npos);
  EXPECT_NE(message({0.3, {0.1, 0.2}, 0.05}, xyz).find("start torsion"), std::string::npos);
  EXPECT_NE(message({0.3, {-0.1, 0.1}, 0.05}, {OutputVariable::X, OutputVariable::Y}).find("must be over x y z"),
            std::string::npos);
}

// Positions a cell or two wide and a tilt-and-torsion set: the first tilt layer meets at
// the pole, and the azimuth's full turn spans several blocks.
Grid poleGrid() {
  const RobotModel& model = test::hexapod();
  return Grid(model, orientationGrid(model, 0.01, {{0.0, 0.01}, {0.0, 0.01}, {0.15, 0.16}},
                                     OrientationSet{0.3, {-0.2, 0.2}, 0.1}));
}

// The components of the cells of code 1.
std::size_t componentsOfOnes(const BlockLayout& layout, const CodeMap& codes) {
  CodeTable<std::uint8_t> keys(2, 0);
  keys[1] = 1;
  LabelLayer labels;
  return labelComponents(layout, codes, keys, FaceCuts{}, -1, &labels).size();
}

// Two arcs of the first tilt layer, apart along the azimuth, touch at the pole: one
// component. The same arcs one layer up do not touch: two.
TEST(OrientationSet, TheFirstTiltLayerJoinsAcrossThePole) {
  const Grid grid = poleGrid();
  const BlockLayout layout(grid);
  ASSERT_EQ(layout.tiltDim(), 4);
  const std::int64_t turn = grid.size(3);
  for (const std::int64_t layer : {std::int64_t{0}, std::int64_t{1}}) {
    CodeMap codes(layout.blockCount(), layout.cellsPerBlock());
    for (std::uint64_t b = 0; b < layout.blockCount(); ++b) {
      std::vector<CellCode> page(layout.cellsPerBlock());
      for (int c = 0; c < layout.cellsPerBlock(); ++c) {
        const GridCell at = layout.cellCoords(b, c);
        const bool arc = at[3] < 3 || (at[3] >= turn / 2 && at[3] < turn / 2 + 3);
        page[c] = layout.inBox(at) && at[4] == layer && arc ? 1 : 0;
      }
      codes.addPage(b, page.data());
    }
    // The arcs' cells join along x, y, z and torsion; across the azimuth gap only at the pole.
    EXPECT_EQ(componentsOfOnes(layout, codes), layer == 0 ? 1u : 2u) << "tilt layer " << layer;
  }
}

// Blocks of one code are joined across the pole and the azimuth's turn as wholes, blocks
// with a page cell by cell, each kind beside the other: a block is of code 1 whole, or
// only in the pole's tilt layer, or only above it, or nowhere.
TEST(OrientationSet, BlocksJoinAcrossThePoleAndTheTurnWholeOrCellByCell) {
  const BlockLayout layout(poleGrid());
  ASSERT_EQ(layout.tiltDim(), 4);
  const std::int64_t azimuth_blocks = layout.blocks(3);
  ASSERT_GE(azimuth_blocks, 6);
  ASSERT_EQ(layout.blockCount(), static_cast<std::uint64_t>(azimuth_blocks));  // one block along the others
  enum Kind { kNone, kWhole, kPole, kAbovePole };
  // The components when the blocks at the given azimuth block coordinates are of those kinds.
  const auto components = [&](const std::vector<std::pair<std::int64_t, Kind>>& kinds) {
    CodeMap codes(layout.blockCount(), layout.cellsPerBlock());
    for (std::uint64_t b = 0; b < layout.blockCount(); ++b) codes.setUniform(b, 0);
    for (const auto& [at, kind] : kinds) {
      const std::uint64_t b = static_cast<std::uint64_t>(at);  // the azimuth's block coordinate
      if (kind == kWhole) codes.setUniform(b, 1);
      if (kind != kPole && kind != kAbovePole) continue;
      std::vector<CellCode> page(layout.cellsPerBlock());
      for (int c = 0; c < layout.cellsPerBlock(); ++c) {
        const GridCell cell = layout.cellCoords(b, c);
        page[c] = layout.inBox(cell) && (kind == kPole ? cell[4] == 0 : cell[4] >= 1) ? 1 : 0;
      }
      codes.addPage(b, page.data());
    }
    return componentsOfOnes(layout, codes);
  };
  const std::int64_t middle = azimuth_blocks / 2, last = azimuth_blocks - 1;
  // Apart along the azimuth: joined only at the pole, where both have cells.
  EXPECT_EQ(components({{0, kWhole}, {middle, kWhole}}), 1u);
  EXPECT_EQ(components({{0, kWhole}, {middle, kPole}}), 1u);
  EXPECT_EQ(components({{0, kPole}, {middle, kWhole}}), 1u);
  EXPECT_EQ(components({{0, kWhole}, {middle, kAbovePole}}), 2u);
  EXPECT_EQ(components({{1, kWhole}, {middle, kAbovePole}}), 2u);
  // The first and last blocks along the azimuth, not both at the pole: joined by the turn alone.
  EXPECT_EQ(components({{0, kAbovePole}, {last, kWhole}}), 1u);
  EXPECT_EQ(components({{0, kWhole}, {last, kAbovePole}}), 1u);
  EXPECT_EQ(components({{0, kAbovePole}, {last, kAbovePole}}), 1u);
  EXPECT_EQ(components({{0, kAbovePole}, {last - 1, kWhole}}), 2u);
}

// Whether some working mode has det J_DKP of `sign` at the pose, by an LU determinant of
// the twist form (not where it does not assemble, nor where it is singular).
bool someModeHasSign(const RobotModel& model, const std::vector<WorkingMode>& modes, const Pose& pose, int sign) {
  const IkpResult ikp = solveIkp(model, pose);
  if (!ikp.assembled) return false;
  for (const WorkingMode& mode : modes) {
    const double det = dkpJacobianTwist(model, configurationOf(pose, ikp, mode)).partialPivLu().determinant();
    if (det * sign > 1e-12) return true;
  }
  return false;
}

// Where every assembly mode's regions form one connected group, the maximal workspace
// reachable from the start is where some working mode has that sign: the share of the
// orientation set there, weighted by sin(t), must be what the coverage says.
TEST(OrientationSet, CoverageAgreesWithAPoseByPoseReference) {
  const RobotModel& model = test::hexapod();
  AnalysisOptions options;
  options.threads = 2;
  const GridSpec spec = orientationGrid(model, 0.02, {{-0.04, 0.04}, {-0.04, 0.04}, {0.12, 0.2}},
                                        OrientationSet{0.26, {-0.26, 0.26}, 0.13});
  const WorkspaceAnalysis analysis = analyseWorkspace(model, spec, options);
  const Grid& grid = analysis.grid();
  const OrientationCoverage coverage = orientationCoverage(analysis);
  ASSERT_EQ(coverage.positionCount(), static_cast<std::uint64_t>(grid.size(0) * grid.size(1) * grid.size(2)));
  std::uint64_t compared = 0, agreeing = 0, covered = 0;
  for (int a = 0; a < 2; ++a) {
    if (analysis.assemblyModes()[a].components != 1) continue;
    const int sign = a == 0 ? 1 : -1;
    for (std::int64_t i = 0; i < grid.size(0); ++i) {
      for (std::int64_t j = 0; j < grid.size(1); ++j) {
        for (std::int64_t k = 0; k < grid.size(2); ++k) {
          double inside = 0.0, all = 0.0;
          for (std::int64_t u = 0; u < grid.size(3); ++u) {
            for (std::int64_t v = 0; v < grid.size(4); ++v) {
              const double t = grid.centre(4, v), h = 0.5 * grid.step(4);
              const double weight = std::cos(std::max(0.0, t - h)) - std::cos(t + h);
              for (std::int64_t w = 0; w < grid.size(5); ++w) {
                const std::uint64_t index = grid.index(GridCell{i, j, k, u, v, w});
                all += weight;
                if (someModeHasSign(model, analysis.modes(), grid.pose(index), sign)) inside += weight;
              }
            }
          }
          const float share = coverage.reachable(a, coverage.position(i, j, k));
          ++compared;
          agreeing += std::abs(share - inside / all) < 1e-5;
          covered += share > 0.0f;
        }
      }
    }
  }
  ASSERT_GT(compared, 0u) << "no assembly mode with one connected group";
  EXPECT_GT(covered, compared / 4) << "the test needs positions that reach orientations";
  EXPECT_GE(static_cast<double>(agreeing), 0.99 * static_cast<double>(compared)) << agreeing << " of " << compared;
  // The volumes count the positions reaching all and some of the set.
  for (int a = 0; a < 2; ++a) {
    const CoverageVolumes& volumes = coverage.assemblyModes()[a].reachable;
    std::uint64_t all = 0, some = 0;
    for (std::uint64_t p = 0; p < coverage.positionCount(); ++p) {
      all += coverage.reachable(a, p) >= 1.0f - 1e-6f;
      some += coverage.reachable(a, p) > 0.0f;
    }
    EXPECT_EQ(volumes.total_orientation_positions, all);
    EXPECT_EQ(volumes.inclusion_positions, some);
    EXPECT_NEAR(volumes.inclusion_volume, static_cast<double>(some) * 0.02 * 0.02 * 0.02, 1e-15);
  }
  // One position alone (coverageAt, and /query_pose through queryPose) as the pass over all.
  for (std::int64_t i = 0; i < grid.size(0); ++i) {
    for (std::int64_t k = 0; k < grid.size(2); ++k) {
      const std::array<std::array<double, 2>, 2> shares = coverageAt(analysis, i, 1, k);
      Pose pose = model.reference.pose;
      pose.position = Eigen::Vector3d(grid.centre(0, i), grid.centre(1, 1), grid.centre(2, k));
      const PoseQuery query = queryPose(model, analysis, pose);
      for (int a = 0; a < 2; ++a) {
        EXPECT_NEAR(shares[a][0], coverage.reachable(a, coverage.position(i, 1, k)), 1e-6);
        EXPECT_NEAR(shares[a][1], coverage.traditional(a, coverage.position(i, 1, k)), 1e-6);
        EXPECT_TRUE(query.assembly_modes[a].has_coverage);
        EXPECT_EQ(query.assembly_modes[a].coverage, shares[a][0]);
        EXPECT_EQ(query.assembly_modes[a].traditional_coverage, shares[a][1]);
      }
    }
  }
}

}  // namespace
}  // namespace maximal_workspace
