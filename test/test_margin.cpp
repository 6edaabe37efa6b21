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

GridSpec deltaGrid(double step) {
  GridSpec spec;
  spec.variables = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
  spec.steps = {step};
  spec.start = test::deltaLike().reference.pose;
  return spec;
}

WorkspaceAnalysis deltaAnalysis(double step, double margin) {
  AnalysisOptions options;
  options.margin = margin;
  return analyseWorkspace(test::deltaLike(), deltaGrid(step), options);
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

// A cell beside `cell` in a non-debris region of the neck's working mode in `analysis`,
// inside the neck's exact region.
bool partNeighbour(const WorkspaceAnalysis& exact, const WorkspaceAnalysis& analysis, const Neck& neck,
                   std::uint64_t cell, std::uint64_t* found) {
  const int mode = neck.mode;
  for (int d = 0; d < analysis.grid().dims(); ++d) {
    for (int direction : {-1, 1}) {
      std::uint64_t next = 0;
      if (!analysis.grid().neighbour(cell, d, direction, &next)) continue;
      const std::int32_t label = analysis.label(next, mode);
      if (label >= 0 && !analysis.regions()[label].debris &&
          exact.label(next, mode) == static_cast<std::int32_t>(neck.exact_region)) {
        *found = next;
        return true;
      }
    }
  }
  return false;
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

// Two groups per assembly mode that were one: at least one neck in each.
TEST_F(Necks, EveryAssemblyModeThatSplitsHasANeck) {
  for (const AssemblyModeSummary& am : margin_->assemblyModes()) {
    ASSERT_GT(am.components, 1);
    EXPECT_TRUE(std::any_of(necks_->begin(), necks_->end(), [&](const Neck& n) { return n.sign == am.sign; }));
  }
}

// The passage is a chain of neighbouring cells of the exact region, under the margin and
// never under the neck's measure, which is the neck cell's own |measure|.
TEST_F(Necks, PassageIsAChainOfCellsWhoseSmallestMeasureIsTheNeck) {
  const Grid& grid = exact_->grid();
  const PoseClassifier classifier(test::deltaLike(), exact_->modes(), grid.spec().start, true);
  std::vector<double> measures(exact_->modes().size());
  for (const Neck& neck : *necks_) {
    ASSERT_FALSE(neck.passage.empty());
    ASSERT_TRUE(classifier.classify(neck.pose, measures.data()));
    EXPECT_NEAR(std::abs(measures[neck.mode]), neck.measure, 1e-15);
    double smallest = 1.0;
    std::uint64_t previous = 0;
    for (std::size_t k = 0; k < neck.passage.size(); ++k) {
      std::uint64_t cell = 0;
      ASSERT_TRUE(grid.cellOf(neck.passage[k].pose, &cell));
      EXPECT_EQ(exact_->label(cell, neck.mode), static_cast<std::int32_t>(neck.exact_region));
      smallest = std::min(smallest, neck.passage[k].measure);
      if (k > 0) {
        const GridCell a = grid.cell(previous), b = grid.cell(cell);
        std::int64_t distance = 0;
        for (int d = 0; d < grid.dims(); ++d) distance += std::abs(a[d] - b[d]);
        EXPECT_EQ(distance, 1) << "passage cells " << k - 1 << " and " << k;
      }
      previous = cell;
    }
    EXPECT_EQ(smallest, neck.measure);
    EXPECT_GE(neck.cross_section_cells, 1u);
    ASSERT_GE(neck.cross_section_normal, 0);
    for (int d = 0; d < grid.dims(); ++d) {
      if (d != neck.cross_section_normal) EXPECT_GE(neck.cross_section_extent[d], grid.step(d) - 1e-12);
    }
  }
}

// The engine's own labelling at margins 1 % under and over a neck's measure: the parts
// at both ends of the passage are one region under it and two regions over it.
TEST_F(Necks, MeasureIsTheMarginAtWhichThePartsSeparate) {
  const Grid& grid = exact_->grid();
  for (const Neck& neck : *necks_) {
    if (neck.measure < 1e-5) continue;  // bounds the test's time; the largest necks decide
    std::uint64_t first = 0, last = 0, part_a = 0, part_b = 0;
    ASSERT_TRUE(grid.cellOf(neck.passage.front().pose, &first));
    ASSERT_TRUE(grid.cellOf(neck.passage.back().pose, &last));
    ASSERT_TRUE(partNeighbour(*exact_, *margin_, neck, first, &part_a));
    ASSERT_TRUE(partNeighbour(*exact_, *margin_, neck, last, &part_b));
    const WorkspaceAnalysis under = deltaAnalysis(0.01, 0.99 * neck.measure);
    const WorkspaceAnalysis over = deltaAnalysis(0.01, 1.01 * neck.measure);
    EXPECT_EQ(under.label(part_a, neck.mode), under.label(part_b, neck.mode)) << "neck at " << neck.measure;
    EXPECT_NE(over.label(part_a, neck.mode), over.label(part_b, neck.mode)) << "neck at " << neck.measure;
    EXPECT_NE(neck.groups[0], neck.groups[1]);
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
