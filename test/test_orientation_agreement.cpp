// Random poses of orientation-set analyses, each decided on its own (mow eval's path),
// against the verdicts of their cells, on both 6-DOF robots of issue 30. A Monte-Carlo check
// of accuracy, not of memory safety: catkin only, out of the sanitized run (it takes minutes
// there), like test_memory_estimate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "maximal_workspace/kinematics/pose_analysis.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "orientation_grid.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

using test::orientationGrid;
using test::tiltTorsionRotation;


// Whether an analysed working mode keeps every limit with det J_DKP of `sign` at the pose,
// by mow eval's path (analysePose), not the engine's.
bool admissibleWithSign(const RobotModel& model, const std::vector<WorkingMode>& modes, const Pose& pose, int sign) {
  const PoseAnalysis analysis = analysePose(model, pose, modes);
  if (!analysis.ikp.assembled) return false;
  for (const WorkingModeAnalysis& mode : analysis.modes) {
    if (mode.limits.satisfied() && mode.singularity.measure * sign > kMeasureTolerance) return true;
  }
  return false;
}

// Poses drawn anywhere in the cells of an orientation-set analysis (seeded), each decided on
// its own; the cell's verdict (in the maximal workspace: a non-debris region of the
// assembly mode in some working mode; with one connected group, the set the coverage
// counts) must agree at 99 % of those whose cell has the verdict of all its face
// neighbours, away from the set's boundaries.
void expectRandomPosesAgree(const std::string& robot, const std::vector<std::string>& modes,
                            std::vector<std::array<double, 2>> positions) {
  const RobotModel model = loadRobotFile(test::sourcePath(robot));
  AnalysisOptions options;
  options.threads = 2;
  options.working_modes = modes;
  const double envelope = 10.0 * M_PI / 180.0;
  const WorkspaceAnalysis analysis =
      analyseWorkspace(model, orientationGrid(model, 0.02, std::move(positions), OrientationSet{envelope, {-envelope, envelope}, envelope / 2.0}), options);
  const Grid& grid = analysis.grid();
  int checked_modes = 0;
  for (int a = 0; a < 2; ++a) {
    const AssemblyModeSummary& am = analysis.assemblyModes()[a];
    if (am.maximal_voxels == 0) continue;
    ++checked_modes;
    const auto inSet = [&](std::uint64_t cell) { return analysis.inMaximalWorkspace(cell, am.sign); };
    std::mt19937 random(2026);
    std::uniform_real_distribution<double> unit(-0.5, 0.5);
    int compared = 0, agreeing = 0, inside = 0;
    for (int sample = 0; sample < 3000; ++sample) {
      const std::uint64_t cell = random() % grid.cellCount();
      const bool verdict = inSet(cell);
      bool interior = true;
      for (int d = 0; d < grid.dims() && interior; ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t next = 0;
          if (grid.neighbour(cell, d, direction, &next) && inSet(next) != verdict) interior = false;
        }
      }
      if (!interior) continue;
      // The pose from the definition of the angles, not from the grid's own map.
      const GridCell at = grid.cell(cell);
      double value[6];
      for (int d = 0; d < 6; ++d) value[d] = grid.centre(d, at[d]) + unit(random) * grid.step(d);
      Pose pose;
      pose.position = Eigen::Vector3d(value[0], value[1], value[2]);
      pose.setRotation(tiltTorsionRotation(model.reference.pose.rotation(), value[3], value[4], value[5]));
      ++compared;
      inside += verdict;
      agreeing += admissibleWithSign(model, analysis.modes(), pose, am.sign) == verdict;
    }
    std::printf("%s, assembly mode %+d: %d of %d poses away from the boundaries agree (%d in the set)\n", robot.c_str(),
                am.sign, agreeing, compared, inside);
    EXPECT_GT(inside, 25) << robot << ": too few samples in the set";
    EXPECT_GT(compared - inside, 25) << robot << ": too few samples out of the set";
    EXPECT_GE(agreeing, 0.99 * compared) << robot << " assembly mode " << int(am.sign);
  }
  EXPECT_GT(checked_modes, 0) << robot << ": an empty maximal workspace";
}

TEST(OrientationSet, RandomPosesAgreeWithTheirCellsOnBothNewRobots) {
  expectRandomPosesAgree("config/hexapod_6rss_long.yaml",
                         {"nnnnnn", "pnnnnn", "npnnnn", "nnpnnn", "nnnpnn", "nnnnpn", "nnnnnp"},
                         {{-0.12, 0.12}, {-0.12, 0.12}, {0.08, 0.28}});
  expectRandomPosesAgree("config/hexaglide_6pss.yaml",
                         {"ppnnpp", "npnnpp", "pnnnpp", "pppnpp", "ppnppp", "ppnnnp", "ppnnpn"},
                         {{-0.2, 0.2}, {-0.12, 0.12}, {0.2, 0.4}});
}

}  // namespace
}  // namespace maximal_workspace
