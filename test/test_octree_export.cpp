// The OctoMap export against the analysis it comes from: every cell of the grid's box is
// looked up in the trees and in the files read back by OctoMap itself (and by an
// octomap-tools program).

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/AbstractOcTree.h>
#include <octomap/OcTree.h>

#include "maximal_workspace/io/octree_export.h"
#include "maximal_workspace/io/region_label_octree.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

using OV = OutputVariable;

WorkspaceAnalysis analyse(const RobotModel& model, std::vector<OutputVariable> variables,
                          std::vector<double> steps) {
  GridSpec spec;
  spec.start = model.reference.pose;
  spec.variables = std::move(variables);
  spec.steps = std::move(steps);
  return analyseWorkspace(model, spec, AnalysisOptions{});
}

// Shared by the tests: about 0.1 s to build.
const WorkspaceAnalysis& deltaLikeAnalysis() {
  static const WorkspaceAnalysis analysis = analyse(test::deltaLike(), {OV::X, OV::Y, OV::Z}, {0.02});
  return analysis;
}

int assemblyIndex(std::int8_t sign) { return sign > 0 ? 0 : 1; }

// Max-depth voxels the occupied leaves stand for; a leaf at depth d covers 8^(16 - d).
template <class Tree>
std::uint64_t occupiedVoxels(const Tree& tree) {
  std::uint64_t count = 0;
  for (auto leaf = tree.begin_leafs(); leaf != tree.end_leafs(); ++leaf) {
    if (tree.isNodeOccupied(*leaf)) count += std::uint64_t{1} << (3 * (tree.getTreeDepth() - leaf.getDepth()));
  }
  return count;
}

template <class Tree>
std::uint64_t freeLeaves(const Tree& tree) {
  std::uint64_t count = 0;
  for (auto leaf = tree.begin_leafs(); leaf != tree.end_leafs(); ++leaf) count += !tree.isNodeOccupied(*leaf);
  return count;
}

// The documented definition, from the labels and the region table alone: some working
// mode has a non-debris region of the assembly mode `sign` at the cell.
bool inMaximalByDefinition(const WorkspaceAnalysis& analysis, std::uint64_t cell, std::int8_t sign) {
  for (int m = 0; m < static_cast<int>(analysis.modes().size()); ++m) {
    const std::int32_t label = analysis.label(cell, m);
    if (label >= 0 && analysis.regions()[label].sign == sign && !analysis.regions()[label].debris) return true;
  }
  return false;
}

// Cells of the grid's box (inside the workspace or not) for which expected(cell, node
// found at its centre) is false.
template <class Tree, class Expected>
std::uint64_t mismatchedCells(const WorkspaceAnalysis& analysis, const Tree& tree, Expected expected) {
  std::uint64_t count = 0;
  for (std::uint64_t cell = 0; cell < analysis.grid().cellCount(); ++cell) {
    const Eigen::Vector3d centre = analysis.grid().pose(cell).position;
    count += !expected(cell, tree.search(centre.x(), centre.y(), centre.z()));
  }
  return count;
}

// Exactly the maximal workspace of `sign`, and nothing but occupied leaves.
void expectMaximalWorkspace(const WorkspaceAnalysis& analysis, const octomap::OcTree& tree, std::int8_t sign) {
  std::uint64_t maximal = 0;
  for (std::uint64_t cell = 0; cell < analysis.grid().cellCount(); ++cell) maximal += inMaximalByDefinition(analysis, cell, sign);
  EXPECT_EQ(analysis.assemblyModes()[assemblyIndex(sign)].maximal_voxels, maximal) << "sign " << int{sign};
  EXPECT_DOUBLE_EQ(tree.getResolution(), analysis.grid().step(0));
  EXPECT_EQ(occupiedVoxels(tree), maximal);
  EXPECT_EQ(freeLeaves(tree), 0u);
  EXPECT_EQ(mismatchedCells(analysis, tree,
                            [&](std::uint64_t cell, const octomap::OcTreeNode* node) {
                              return inMaximalByDefinition(analysis, cell, sign) ? node && tree.isNodeOccupied(node)
                                                                                 : node == nullptr;
                            }),
            0u)
      << "sign " << int{sign};
}

// Every cell carries its region label in `mode`; unlabelled cells have no node.
void expectRegionLabels(const WorkspaceAnalysis& analysis, const RegionLabelOcTree& tree, int mode) {
  EXPECT_EQ(mismatchedCells(analysis, tree,
                            [&](std::uint64_t cell, const RegionLabelNode* node) {
                              const std::int32_t label = analysis.label(cell, mode);
                              if (label < 0) return node == nullptr;
                              return node && tree.isNodeOccupied(node) && node->label() == label;
                            }),
            0u)
      << "mode " << analysis.modes()[mode].name;
}

// The working mode with the most regions: the hardest case for label-preserving pruning.
int modeWithMostRegions(const WorkspaceAnalysis& analysis) {
  std::vector<int> regions(analysis.modes().size(), 0);
  for (const Region& region : analysis.regions()) ++regions[region.mode];
  return static_cast<int>(std::max_element(regions.begin(), regions.end()) - regions.begin());
}

TEST(OctreeExport, DeltaLikeGridIsExportable) {
  std::string why;
  EXPECT_TRUE(octreeExportable(deltaLikeAnalysis().grid(), &why)) << why;
}

TEST(OctreeExport, MaximalWorkspaceTreeHoldsExactlyTheMaximalVoxels) {
  const WorkspaceAnalysis& analysis = deltaLikeAnalysis();
  for (std::int8_t sign : {1, -1}) {
    const std::uint64_t maximal = analysis.assemblyModes()[assemblyIndex(sign)].maximal_voxels;
    ASSERT_GT(maximal, 0u) << "sign " << int{sign};
    const std::unique_ptr<octomap::OcTree> tree = maximalWorkspaceOctree(analysis, sign);
    expectMaximalWorkspace(analysis, *tree, sign);
    EXPECT_LT(tree->getNumLeafNodes(), maximal) << "pruning merged nothing";
    // Inner occupancy was updated: the root is as occupied as its leaves.
    EXPECT_FLOAT_EQ(tree->getRoot()->getLogOdds(), tree->getClampingThresMaxLog());
  }
}

TEST(OctreeExport, BinaryFilesReadBackWithTheSameVoxels) {
  const WorkspaceAnalysis& analysis = deltaLikeAnalysis();
  const test::TemporaryDirectory directory("test_octree_export");
  writeOctrees(analysis, directory.path());
  for (std::int8_t sign : {1, -1}) {
    const std::string name = sign > 0 ? "maximal_positive.bt" : "maximal_negative.bt";
    const octomap::OcTree read(directory.file(name));
    EXPECT_EQ(read.getNumLeafNodes(), maximalWorkspaceOctree(analysis, sign)->getNumLeafNodes()) << name;
    expectMaximalWorkspace(analysis, read, sign);
  }
}

TEST(OctreeExport, WritesEveryFileAndNoTemporaryOne) {
  const WorkspaceAnalysis& analysis = deltaLikeAnalysis();
  const test::TemporaryDirectory directory("test_octree_export");
  std::vector<std::string> expected = {"maximal_positive.bt", "maximal_negative.bt"};
  for (const WorkingMode& mode : analysis.modes()) expected.push_back("regions_" + mode.name + ".ot");
  EXPECT_EQ(writeOctrees(analysis, directory.path()), expected);
  std::vector<std::string> present;
  for (const auto& entry : std::filesystem::directory_iterator(directory.path())) {
    present.push_back(entry.path().filename().string());
  }
  std::sort(present.begin(), present.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(present, expected);
}

TEST(OctreeExport, UnwritableDirectoryThrowsNamingTheFile) {
  try {
    writeOctrees(deltaLikeAnalysis(), "/nonexistent/octrees");
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent/octrees/maximal_positive.bt"), std::string::npos)
        << error.what();
  }
}

TEST(OctreeExport, LabelTreeKeepsEveryVoxelsRegion) {
  const WorkspaceAnalysis& analysis = deltaLikeAnalysis();
  const int mode = modeWithMostRegions(analysis);
  std::uint64_t labelled = 0;
  std::set<std::int32_t> labels;
  for (std::uint64_t cell = 0; cell < analysis.grid().cellCount(); ++cell) {
    const std::int32_t label = analysis.label(cell, mode);
    labelled += label >= 0;
    if (label >= 0) labels.insert(label);
  }
  ASSERT_GE(labels.size(), 2u) << "no region boundary for pruning to respect";
  const std::unique_ptr<RegionLabelOcTree> tree = regionLabelOctree(analysis, mode);
  expectRegionLabels(analysis, *tree, mode);
  EXPECT_EQ(occupiedVoxels(*tree), labelled);
  EXPECT_LT(tree->getNumLeafNodes(), labelled) << "pruning merged nothing";
}

// Eight sibling leaves at the finest depth: seven with kLabel and kLogOdds, the last one
// (child 7) with the given values.
constexpr std::int32_t kLabel = 7;
constexpr float kLogOdds = 2.0f;

octomap::OcTreeKey siblingKey(const RegionLabelOcTree& tree, unsigned child) {
  const octomap::OcTreeKey first = tree.coordToKey(0.05, 0.05, 0.05);  // even key: child 0
  return octomap::OcTreeKey(first[0] + (child & 1), first[1] + ((child >> 1) & 1), first[2] + (child >> 2));
}

std::unique_ptr<RegionLabelOcTree> eightSiblings(std::int32_t last_label, float last_log_odds) {
  auto tree = std::make_unique<RegionLabelOcTree>(0.1);
  for (unsigned child = 0; child < 8; ++child) {
    const bool last = child == 7;
    tree->setNodeValue(siblingKey(*tree, child), last ? last_log_odds : kLogOdds, true)
        ->setLabel(last ? last_label : kLabel);
  }
  tree->prune();
  return tree;
}

// The trees are built already pruned from the blocks (src/io/octree_pyramid.h); they must
// equal what OctoMap itself makes of the same cells inserted one by one and pruned.
TEST(OctreeExport, DirectBuildEqualsInsertionThenPrune) {
  const WorkspaceAnalysis& analysis = deltaLikeAnalysis();
  const int mode = modeWithMostRegions(analysis);
  RegionLabelOcTree inserted(analysis.grid().step(0));
  octomap::OcTree inserted_maximal(analysis.grid().step(0));
  for (std::uint64_t cell = 0; cell < analysis.grid().cellCount(); ++cell) {
    const Eigen::Vector3d centre = analysis.grid().pose(cell).position;
    const octomap::OcTreeKey key = inserted.coordToKey(centre.x(), centre.y(), centre.z());
    const std::int32_t label = analysis.label(cell, mode);
    if (label >= 0) inserted.setNodeValue(key, inserted.getClampingThresMaxLog(), true)->setLabel(label);
    if (inMaximalByDefinition(analysis, cell, 1)) {
      inserted_maximal.setNodeValue(key, inserted_maximal.getClampingThresMaxLog(), true);
    }
  }
  inserted.prune();
  inserted_maximal.prune();
  const auto built = regionLabelOctree(analysis, mode);
  const auto built_maximal = maximalWorkspaceOctree(analysis, 1);
  EXPECT_EQ(built->size(), inserted.size());
  EXPECT_EQ(built->getNumLeafNodes(), inserted.getNumLeafNodes());
  EXPECT_EQ(built_maximal->size(), inserted_maximal.size());
  EXPECT_EQ(built_maximal->getNumLeafNodes(), inserted_maximal.getNumLeafNodes());
  // Leaf by leaf: same key, depth and label.
  auto leaf = inserted.begin_leafs();
  for (auto it = built->begin_leafs(); it != built->end_leafs(); ++it, ++leaf) {
    ASSERT_NE(leaf, inserted.end_leafs());
    EXPECT_EQ(it.getKey(), leaf.getKey());
    EXPECT_EQ(it.getDepth(), leaf.getDepth());
    EXPECT_EQ(it->label(), leaf->label());
  }
}

TEST(RegionLabelOcTree, EqualSiblingsCollapseIntoTheirParent) {
  const std::unique_ptr<RegionLabelOcTree> tree = eightSiblings(kLabel, kLogOdds);
  ASSERT_EQ(tree->getNumLeafNodes(), 1u);
  const auto parent = tree->begin_leafs();
  EXPECT_EQ(parent.getDepth(), tree->getTreeDepth() - 1);
  EXPECT_EQ(parent->label(), kLabel);
  EXPECT_FLOAT_EQ(parent->getLogOdds(), kLogOdds);
}

TEST(RegionLabelOcTree, SiblingsWithADifferentLabelOrOccupancyStay) {
  const std::pair<std::int32_t, float> lasts[] = {{kLabel + 1, kLogOdds}, {kLabel, kLogOdds - 1.0f}};
  for (const auto& [last_label, last_log_odds] : lasts) {
    const std::unique_ptr<RegionLabelOcTree> tree = eightSiblings(last_label, last_log_odds);
    ASSERT_EQ(tree->getNumLeafNodes(), 8u);
    for (unsigned child = 0; child < 8; ++child) {
      const RegionLabelNode* leaf = tree->search(siblingKey(*tree, child));
      ASSERT_NE(leaf, nullptr);
      const bool last = child == 7;
      EXPECT_EQ(leaf->label(), last ? last_label : kLabel);
      EXPECT_FLOAT_EQ(leaf->getLogOdds(), last ? last_log_odds : kLogOdds);
    }
  }
}

TEST(OctreeExport, LabelFilesReadBackAsRegionLabelOcTrees) {
  const WorkspaceAnalysis& analysis = deltaLikeAnalysis();
  const test::TemporaryDirectory directory("test_octree_export");
  writeOctrees(analysis, directory.path());
  for (std::size_t mode = 0; mode < analysis.modes().size(); ++mode) {
    const std::string path = directory.file("regions_" + analysis.modes()[mode].name + ".ot");
    const std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(path));
    ASSERT_NE(read, nullptr) << path;
    const auto* tree = dynamic_cast<const RegionLabelOcTree*>(read.get());
    ASSERT_NE(tree, nullptr) << path << " read as " << read->getTreeType();
    EXPECT_EQ(tree->getNumLeafNodes(), regionLabelOctree(analysis, static_cast<int>(mode))->getNumLeafNodes());
    expectRegionLabels(analysis, *tree, static_cast<int>(mode));
  }
}

TEST(OctreeExport, PlanarFiveBarIsOneLayerAtTheStartZ) {
  const WorkspaceAnalysis analysis = analyse(test::fiveBar(), {OV::X, OV::Y}, {0.005});
  std::string why;
  ASSERT_TRUE(octreeExportable(analysis.grid(), &why)) << why;
  for (std::int8_t sign : {1, -1}) {
    const std::unique_ptr<octomap::OcTree> tree = maximalWorkspaceOctree(analysis, sign);
    expectMaximalWorkspace(analysis, *tree, sign);
    const octomap::key_type start_z = tree->coordToKey(analysis.grid().spec().start.position.z());
    std::uint64_t off_layer = 0;
    for (auto leaf = tree->begin_leafs(); leaf != tree->end_leafs(); ++leaf) {
      off_layer += leaf.getDepth() != tree->getTreeDepth() || leaf.getKey()[2] != start_z;
    }
    EXPECT_EQ(off_layer, 0u) << "sign " << int{sign};
  }
  EXPECT_GT(analysis.assemblyModes()[0].maximal_voxels + analysis.assemblyModes()[1].maximal_voxels, 0u);
}

TEST(OctreeExport, UnequalStepsAreNotExportable) {
  const WorkspaceAnalysis analysis = analyse(test::deltaLike(), {OV::X, OV::Y, OV::Z}, {0.02, 0.03, 0.02});
  std::string why;
  EXPECT_FALSE(octreeExportable(analysis.grid(), &why));
  EXPECT_NE(why.find("steps differ"), std::string::npos) << why;
  EXPECT_THROW(maximalWorkspaceOctree(analysis, 1), InputError);
  EXPECT_THROW(regionLabelOctree(analysis, 0), InputError);
}

// OctoMap's own command-line tools open the binary file: convert_octree reads the .bt (it
// exits non-zero when it cannot) and writes it back as a .ot with the same voxels.
TEST(OctreeExport, OctomapToolsOpenTheBinaryFile) {
  const std::string tool = "/usr/bin/convert_octree";
  if (access(tool.c_str(), X_OK) != 0) GTEST_SKIP() << tool << " is not installed (Debian package octomap-tools)";
  const WorkspaceAnalysis& analysis = deltaLikeAnalysis();
  const test::TemporaryDirectory directory("test_octree_export");
  writeOctrees(analysis, directory.path());
  const std::string converted = directory.file("converted.ot");
  const std::string command =
      tool + " '" + directory.file("maximal_positive.bt") + "' '" + converted + "' > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << command << ": status " << status;
  ASSERT_EQ(WEXITSTATUS(status), 0) << command;
  const std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(converted));
  const auto* tree = dynamic_cast<const octomap::OcTree*>(read.get());
  ASSERT_NE(tree, nullptr) << converted;
  expectMaximalWorkspace(analysis, *tree, 1);
}

}  // namespace
}  // namespace maximal_workspace
