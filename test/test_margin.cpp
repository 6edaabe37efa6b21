// Exact signs by default and a dexterity margin as a labelled choice (issue 20), and the
// necks a margin cuts (regions/necks.h), checked against analyses at margins just under
// and just over each neck's measure.

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/regions/necks.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

WorkspaceAnalysis deltaAnalysis(double step, double margin) {
  AnalysisOptions options;
  options.margin = margin;
  return analyseWorkspace(test::deltaLike(), test::referenceGrid(test::deltaLike(), step), options);
}

double percent(const WorkspaceAnalysis& analysis, double volume) { return 100.0 * volume / analysis.workspaceVolume(); }

TEST(Margin, ExactAnalysisIsOneGroupPerAssemblyModeAt10mm) {
  const WorkspaceAnalysis analysis = deltaAnalysis(0.01, 0.0);
  EXPECT_EQ(analysis.settings().margin, 0.0);
  for (const AssemblyModeSummary& am : analysis.assemblyModes()) {
    EXPECT_EQ(am.components, 1) << "assembly mode " << int(am.sign);
    ASSERT_GE(am.traditional_region, 0);
    // The start's group holds every non-debris region of the assembly mode.
    EXPECT_EQ(am.reachable_voxels, am.maximal_voxels) << "assembly mode " << int(am.sign);
  }
}

// Convergence with the step: the exact figures at 20, 10 and 5 mm within 0.5 points.
TEST(Margin, ExactFiguresAgreeAt20And10And5mm) {
  std::vector<WorkspaceAnalysis> analyses;
  for (double step : {0.02, 0.01, 0.005}) analyses.push_back(deltaAnalysis(step, 0.0));
  for (int am = 0; am < 2; ++am) {
    for (std::size_t k = 1; k < analyses.size(); ++k) {
      const AssemblyModeSummary &a = analyses[0].assemblyModes()[am], &b = analyses[k].assemblyModes()[am];
      EXPECT_NEAR(percent(analyses[0], a.traditional_volume), percent(analyses[k], b.traditional_volume), 0.5);
      EXPECT_NEAR(percent(analyses[0], a.reachable_volume), percent(analyses[k], b.reachable_volume), 0.5);
      EXPECT_NEAR(percent(analyses[0], a.maximal_volume), percent(analyses[k], b.maximal_volume), 0.5);
      EXPECT_EQ(a.components, b.components);
    }
  }
}

// The figures of the old default band, measured on main before exact signs (issue 20's
// table, 10 mm): (+) traditional 56.6 %, reachable 85.9 %, 3 groups; (-) 71.7 %, 82.4 %, 2.
TEST(Margin, Margin1e3GivesTheFiguresOfTheOldBand) {
  const WorkspaceAnalysis analysis = deltaAnalysis(0.01, 1e-3);
  EXPECT_EQ(analysis.settings().margin, 1e-3);
  const AssemblyModeSummary &plus = analysis.assemblyModes()[0], &minus = analysis.assemblyModes()[1];
  EXPECT_NEAR(percent(analysis, plus.traditional_volume), 56.6, 0.05);
  EXPECT_NEAR(percent(analysis, plus.reachable_volume), 85.9, 0.05);
  EXPECT_EQ(plus.components, 3);
  EXPECT_NEAR(percent(analysis, minus.traditional_volume), 71.7, 0.05);
  EXPECT_NEAR(percent(analysis, minus.reachable_volume), 82.4, 0.05);
  EXPECT_EQ(minus.components, 2);
}

class Necks : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    exact_ = new WorkspaceAnalysis(deltaAnalysis(0.01, 0.0));
    margin_ = new WorkspaceAnalysis(deltaAnalysis(0.01, 1e-3));
    necks_ = new std::vector<Neck>(findNecks(test::deltaLike(), *exact_, *margin_));
  }
  static void TearDownTestSuite() {
    delete necks_;
    delete margin_;
    delete exact_;
  }
  static const WorkspaceAnalysis* exact_;
  static const WorkspaceAnalysis* margin_;
  static const std::vector<Neck>* necks_;
};
const WorkspaceAnalysis* Necks::exact_ = nullptr;
const WorkspaceAnalysis* Necks::margin_ = nullptr;
const std::vector<Neck>* Necks::necks_ = nullptr;

// One neck per topology change: groups - 1 per assembly mode, as the exact analysis has one
// group in each.
TEST_F(Necks, OneNeckPerGroupThatWasJoined) {
  for (const AssemblyModeSummary& am : margin_->assemblyModes()) {
    const auto count = std::count_if(necks_->begin(), necks_->end(), [&](const Neck& n) { return n.sign == am.sign; });
    EXPECT_EQ(count, am.components - 1) << "assembly mode " << int(am.sign);
  }
}

// The passage is a chain of cells, each the previous one's face neighbour in the same
// working mode or the same cell in another (a transition); all under the margin and none
// under the neck's measure, which the passage or its ends' edge reaches.
TEST_F(Necks, PassageIsAChainOfCellsNoneUnderTheNeck) {
  const Grid& grid = exact_->grid();
  const PoseClassifier classifier(test::deltaLike(), exact_->modes(), grid.spec().start, true);
  std::vector<double> measures(exact_->modes().size());
  for (const Neck& neck : *necks_) {
    std::uint64_t previous = 0;
    for (std::size_t k = 0; k < neck.passage.size(); ++k) {
      const NeckSample& sample = neck.passage[k];
      std::uint64_t cell = 0;
      ASSERT_TRUE(grid.cellOf(sample.pose, &cell));
      ASSERT_TRUE(classifier.classify(sample.pose, measures.data()));
      EXPECT_NEAR(std::abs(measures[sample.mode]), sample.measure, 1e-15);
      EXPECT_GE(sample.measure, neck.measure);
      EXPECT_LT(sample.measure, 1e-3 + 1e-3);  // under the margin, or in debris just over it
      EXPECT_EQ(exact_->regions()[exact_->label(cell, sample.mode)].sign, neck.sign);
      if (k > 0) {
        const GridCell a = grid.cell(previous), b = grid.cell(cell);
        std::int64_t distance = 0;
        for (int d = 0; d < grid.dims(); ++d) distance += std::abs(a[d] - b[d]);
        const bool face = distance == 1 && sample.mode == neck.passage[k - 1].mode;
        const bool transition = distance == 0 && sample.mode != neck.passage[k - 1].mode;
        EXPECT_TRUE(face || transition) << "passage cells " << k - 1 << " and " << k;
      }
      previous = cell;
    }
    EXPECT_GE(neck.cross_section_cells, 1u);  // the neck's own cell or point
    if (neck.kind == Neck::Kind::Region) {
      ASSERT_GE(neck.cross_section_normal, 0);
      for (int d = 0; d < grid.dims(); ++d) {
        if (d != neck.cross_section_normal) {
          EXPECT_GE(neck.cross_section_extent[d], grid.step(d) - 1e-12);
        }
      }
    }
  }
}

// The engine's own analyses at margins 1 % under and over a neck's measure: the regions at
// the passage's two ends are in one group under it, and in two over it.
TEST_F(Necks, MeasureIsTheMarginAtWhichTheGroupsSeparate) {
  const Grid& grid = exact_->grid();
  for (const Neck& neck : *necks_) {
    std::array<std::uint64_t, 2> cells{};
    for (int side = 0; side < 2; ++side) ASSERT_TRUE(grid.cellOf(neck.ends[side].pose, &cells[side]));
    const auto group = [&](const WorkspaceAnalysis& analysis, int side) {
      const std::int32_t region = analysis.label(cells[side], neck.ends[side].mode);
      return region < 0 ? -1 : analysis.transitions().component[region];
    };
    ASSERT_GE(group(*margin_, 0), 0);
    EXPECT_NE(group(*margin_, 0), group(*margin_, 1));
    const WorkspaceAnalysis under = deltaAnalysis(0.01, 0.99 * neck.measure);
    const WorkspaceAnalysis over = deltaAnalysis(0.01, 1.01 * neck.measure);
    EXPECT_GE(group(under, 0), 0);
    EXPECT_EQ(group(under, 0), group(under, 1)) << "neck at " << neck.measure;
    EXPECT_NE(group(over, 0), group(over, 1)) << "neck at " << neck.measure;
  }
}

TEST_F(Necks, RefusesAnalysesThatCannotBeCompared) {
  EXPECT_THROW(findNecks(test::deltaLike(), *margin_, *exact_), InputError);
  EXPECT_THROW(findNecks(test::deltaLike(), *exact_, *exact_), InputError);
  const WorkspaceAnalysis coarse = deltaAnalysis(0.02, 1e-3);
  EXPECT_THROW(findNecks(test::deltaLike(), *exact_, coarse), InputError);
}

}  // namespace
}  // namespace maximal_workspace
