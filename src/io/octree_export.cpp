#include "maximal_workspace/io/octree_export.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <mutex>

#include <octomap/ColorOcTree.h>

#include "maximal_workspace/io/workspace_files.h"  // writeFileAtomically
#include "maximal_workspace/model/input_error.h"
#include "io/octree_pyramid.h"
#include "workspace/parallel.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {
namespace {

struct MaximalFile {
  std::int8_t sign;
  const char* name;
};
constexpr MaximalFile kMaximalFiles[] = {{1, "maximal_positive.bt"}, {-1, "maximal_negative.bt"}};

// OctoMap keys are 16 bits per axis: lattice indices floor(coordinate / resolution) in
// [-2^15, 2^15).
bool insideKeyRange(double coordinate, double resolution) {
  const double lattice = std::floor(coordinate / resolution);
  return lattice >= -32768.0 && lattice < 32768.0;
}

void requireExportable(const Grid& grid) {
  std::string why;
  if (!octreeExportable(grid, &why)) throw InputError("octree export: " + why);
}

// An OcTree filled straight from a pyramid, and written without liboctomap's debug
// print: the same type and file format as any OcTree.
class PyramidOcTree : public octomap::OcTree {
 public:
  using octomap::OcTree::OcTree;

  void buildFrom(const KeyPyramid& pyramid) {
    const std::array<std::uint32_t, 3> everything = {0, 0, 0};
    if (pyramid.value(KeyPyramid::kTreeDepth, everything) == KeyPyramid::kEmpty) return;
    // One value, occupied, for leaves and inner nodes alike (what updateInnerOccupancy gives).
    const float occupied = getClampingThresMaxLog();
    auto set_occupied = [occupied](octomap::OcTreeNode* node, auto...) { node->setLogOdds(occupied); };
    root = new octomap::OcTreeNode();
    root->setLogOdds(occupied);
    ++tree_size;
    buildFromPyramid(
        root, pyramid, KeyPyramid::kTreeDepth, everything,
        [this](octomap::OcTreeNode* node, unsigned index) { return createNodeChild(node, index); }, set_occupied,
        set_occupied);
    size_changed = true;
  }

  // The .bt layout: header line, comments, id, size, res, data, then the binary nodes.
  bool writeBinaryFile(std::ostream& stream, const std::string& note) const {
    stream << binaryFileHeader << "\n# maximal operational workspace (" << note << "), written by maximal_workspace\n";
    stream << "id " << getTreeType() << "\nsize " << size() << "\nres " << getResolution() << "\ndata\n";
    writeBinaryData(stream);
    return stream.good();
  }
};

// Blocks read between two ticks of a tree's build: at 1 mm a tree reads millions.
constexpr std::uint64_t kBlocksBetweenTicks = 4096;

// Key of the box's first cell: its centre, at the start's z on a planar grid.
template <class Tree>
octomap::OcTreeKey firstKey(const Tree& tree, const Grid& grid) {
  const double z = grid.dims() == 3 ? grid.centre(2, 0) : grid.spec().start.position.z();
  return tree.coordToKey(grid.centre(0, 0), grid.centre(1, 0), z);
}

// The values of an analysis's cells as a pyramid, KeyPyramid::kEmpty where nothing is:
// block_values(block, values, n) fills a block's first n cells at once. Over x y z the base is the
// blocks, and only blocks that are not uniform are looked into, each once (the last one
// is kept, as the tree is built block by block); a planar grid is one layer of cells,
// small enough to take whole.
template <class BlockValues>
KeyPyramid analysisPyramid(const WorkspaceAnalysis& analysis, const octomap::OcTreeKey& grid_first_key,
                           const BlockValues& block_values) {
  const BlockLayout& layout = analysis.blocks();
  std::vector<std::int32_t> values_of_block(layout.cellsPerBlock());
  if (layout.dims() == 2) {
    const Grid& grid = analysis.grid();
    std::vector<std::int32_t> values(grid.cellCount(), KeyPyramid::kEmpty);
    for (std::uint64_t b = 0; b < layout.blockCount(); ++b) {
      block_values(b, values_of_block.data(), layout.cellsPerBlock());
      for (int c = 0; c < layout.cellsPerBlock(); ++c) {
        if (layout.inBox(layout.cellCoords(b, c))) values[layout.gridIndex(b, c)] = values_of_block[c];
      }
    }
    return KeyPyramid(std::move(values), {static_cast<int>(grid.size(0)), static_cast<int>(grid.size(1)), 1},
                      {grid_first_key[0], grid_first_key[1], grid_first_key[2]});
  }
  std::vector<std::int32_t> values(layout.blockCount());
  for (std::uint64_t b = 0; b < layout.blockCount(); ++b) {
    // A uniform block's first cell answers for it.
    const bool uniform = analysis.blockUniform(b);
    block_values(b, values_of_block.data(), uniform ? 1 : layout.cellsPerBlock());
    const std::int32_t first = values_of_block[0];
    const bool same = uniform || std::all_of(values_of_block.begin(), values_of_block.end(),
                                             [first](std::int32_t v) { return v == first; });
    values[b] = same ? first : KeyPyramid::kMixed;
  }
  // Grid cell (0, 0, 0) has key grid_first_key; block 0's first cell lies before it.
  const GridCell origin = layout.cellCoords(0, 0);
  std::array<std::uint32_t, 3> first_block{};
  for (int d = 0; d < 3; ++d) first_block[d] = static_cast<std::uint32_t>(grid_first_key[d] + origin[d]) >> layout.sideBits();
  struct Cached {
    std::uint64_t block = ~std::uint64_t{0};
    std::vector<std::int32_t> values;
  };
  auto cached = std::make_shared<Cached>();
  cached->values.resize(layout.cellsPerBlock());
  auto fine = [&layout, first_block, &block_values, cached](int level, const std::array<std::uint32_t, 3>& cell) {
    // The cube's block, and its first cell and side within the block.
    GridCell block{};
    int corner[3];
    for (int d = 0; d < 3; ++d) {
      const std::uint32_t key = cell[d] << level;
      block[d] = static_cast<std::int64_t>(key >> layout.sideBits()) - first_block[d];
      corner[d] = static_cast<int>(key & (layout.side() - 1));
    }
    const std::uint64_t b = layout.blockIndex(block);
    if (cached->block != b) {
      block_values(b, cached->values.data(), layout.cellsPerBlock());
      cached->block = b;
    }
    const int side = 1 << level;
    const std::int32_t first = cached->values[layout.cellIndex(corner)];
    for (int x = 0; x < side; ++x) {
      for (int y = 0; y < side; ++y) {
        for (int z = 0; z < side; ++z) {
          const int at[3] = {corner[0] + x, corner[1] + y, corner[2] + z};
          if (cached->values[layout.cellIndex(at)] != first) return KeyPyramid::kMixed;
        }
      }
    }
    return first;
  };
  return KeyPyramid(std::move(values), {static_cast<int>(layout.blocks(0)), static_cast<int>(layout.blocks(1)),
                                         static_cast<int>(layout.blocks(2))},
                    first_block, layout.sideBits(), fine);
}

// Why the first `dims` grid variables leave the octree's key range, or "".
std::string keyRangeRefusal(const Grid& grid, int dims) {
  const double step = grid.step(0);
  for (int d = 0; d < dims; ++d) {
    if (!insideKeyRange(grid.centre(d, 0), step) || !insideKeyRange(grid.centre(d, grid.size(d) - 1), step)) {
      return std::string("the grid along ") + outputVariableName(grid.variable(d)) +
             " exceeds the octree's range of +/-32768 steps from the origin";
    }
  }
  return "";
}

// Streamed into a file written atomically: a failed write names its reason and leaves no
// file under the final name. (Serialised in memory first, a 1 mm analysis's trees held
// each file twice, in a buffer grown by copying and in the string taken from it.)
void writeFile(const std::string& directory, const std::string& name,
               const std::function<bool(std::ostream&)>& write) {
  const std::string path = directory + "/" + name;
  writeFileAtomically(path, [&](std::ostream& stream) {
    // A stream that failed is reported by writeFileAtomically, with the system's reason.
    if (!write(stream) && stream.good()) throw InputError("octree export: cannot serialise " + path);
  });
}

}  // namespace

bool octreeExportable(const Grid& grid, std::string* why) {
  auto refuse = [why](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  if (!grid.isSpatial()) return refuse("the grid variables must be x y z, or x y for a planar robot");
  const double step = grid.step(0);
  for (int d = 1; d < grid.dims(); ++d) {
    if (grid.step(d) != step) {
      return refuse("an octree has one resolution, but the grid steps differ (" + numberText(step) + " along " +
                    outputVariableName(grid.variable(0)) + ", " + numberText(grid.step(d)) + " along " +
                    outputVariableName(grid.variable(d)) + ")");
    }
  }
  const std::string out_of_range = keyRangeRefusal(grid, grid.dims());
  if (!out_of_range.empty()) return refuse(out_of_range);
  if (grid.dims() == 2 && !insideKeyRange(grid.spec().start.position.z(), step)) {
    return refuse("the start z exceeds the octree's range of +/-32768 steps from the origin");
  }
  return true;
}

std::unique_ptr<octomap::OcTree> maximalWorkspaceOctree(const WorkspaceAnalysis& analysis, std::int8_t sign,
                                                        const std::function<void()>& tick) {
  requireExportable(analysis.grid());
  auto tree = std::make_unique<PyramidOcTree>(analysis.grid().step(0));
  const std::vector<Region>& regions = analysis.regions();
  const int modes = static_cast<int>(analysis.modes().size());
  std::vector<std::int32_t> labels(analysis.blocks().cellsPerBlock());
  std::uint64_t blocks_read = 0;
  // In the maximal workspace: some working mode's non-debris region of this sign.
  const auto block_values = [&](std::uint64_t block, std::int32_t* values, int cells) {
    if (tick && ++blocks_read % kBlocksBetweenTicks == 0) tick();
    std::fill_n(values, cells, KeyPyramid::kEmpty);
    for (int m = 0; m < modes; ++m) {
      if (cells == 1) {
        labels[0] = analysis.label(block, 0, m);
      } else {
        analysis.blockLabels(block, m, labels.data());
      }
      for (int c = 0; c < cells; ++c) {
        const std::int32_t label = labels[c];
        if (label >= 0 && regions[label].sign == sign && !regions[label].debris) values[c] = 1;
      }
    }
  };
  tree->buildFrom(analysisPyramid(analysis, firstKey(*tree, analysis.grid()), block_values));
  return tree;
}

std::unique_ptr<RegionLabelOcTree> regionLabelOctree(const WorkspaceAnalysis& analysis, int mode,
                                                     const std::function<void()>& tick) {
  requireExportable(analysis.grid());
  auto tree = std::make_unique<RegionLabelOcTree>(analysis.grid().step(0));
  std::uint64_t blocks_read = 0;
  const auto block_values = [&](std::uint64_t block, std::int32_t* values, int cells) {
    if (tick && ++blocks_read % kBlocksBetweenTicks == 0) tick();
    if (cells == 1) {
      values[0] = analysis.label(block, 0, mode);
    } else {
      analysis.blockLabels(block, mode, values);
    }
    for (int c = 0; c < cells; ++c) {
      if (values[c] < 0) values[c] = KeyPyramid::kEmpty;
    }
  };
  tree->buildFrom(analysisPyramid(analysis, firstKey(*tree, analysis.grid()), block_values));
  return tree;
}

std::vector<std::string> writeOctrees(const WorkspaceAnalysis& analysis, const std::string& directory,
                                      const std::function<void(std::size_t, std::size_t)>& written) {
  requireExportable(analysis.grid());
  // One file per task, built and written concurrently (each tree is independent).
  std::vector<std::string> names;
  std::vector<std::function<void(const std::function<void()>&)>> tasks;
  for (const MaximalFile& file : kMaximalFiles) {
    names.push_back(file.name);
    tasks.push_back([&analysis, &directory, file](const std::function<void()>& tick) {
      const std::unique_ptr<octomap::OcTree> tree = maximalWorkspaceOctree(analysis, file.sign, tick);
      writeFile(directory, file.name,
                [&](std::ostream& stream) {
                  return static_cast<const PyramidOcTree&>(*tree).writeBinaryFile(stream,
                                                                                  marginText(analysis.settings().margin));
                });
    });
  }
  for (std::size_t mode = 0; mode < analysis.modes().size(); ++mode) {
    const std::string name = "regions_" + analysis.modes()[mode].name + ".ot";
    names.push_back(name);
    tasks.push_back([&analysis, &directory, mode, name](const std::function<void()>& tick) {
      const std::unique_ptr<RegionLabelOcTree> tree = regionLabelOctree(analysis, static_cast<int>(mode), tick);
      writeFile(directory, name, [&](std::ostream& stream) { return tree->write(stream); });
    });
  }
  std::mutex mutex;
  std::size_t done = 0;
  const std::function<void()> tick = [&] {
    const std::lock_guard<std::mutex> lock(mutex);
    if (written) written(done, tasks.size());
  };
  parallelFor(tasks.size(), 0, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t) {
      tasks[t](tick);
      const std::lock_guard<std::mutex> lock(mutex);
      if (written) written(++done, tasks.size());
    }
  }, 1);
  return names;
}

std::vector<std::string> writeCoverageOctrees(const WorkspaceAnalysis& analysis, const OrientationCoverage& coverage,
                                              const std::string& directory) {
  const Grid& grid = analysis.grid();
  const double step = grid.step(0);
  if (grid.step(1) != step || grid.step(2) != step) {
    throw InputError("octree export: an octree has one resolution, but the position steps differ");
  }
  const std::string out_of_range = keyRangeRefusal(grid, 3);
  if (!out_of_range.empty()) throw InputError("octree export: " + out_of_range);
  std::vector<std::string> names;
  for (int a = 0; a < 2; ++a) {
    const std::string sign = a == 0 ? "positive" : "negative";
    octomap::OcTree total(step);
    octomap::ColorOcTree shares(step);
    for (std::int64_t i = 0; i < coverage.size(0); ++i) {
      for (std::int64_t j = 0; j < coverage.size(1); ++j) {
        for (std::int64_t k = 0; k < coverage.size(2); ++k) {
          const float share = coverage.reachable(a, coverage.position(i, j, k));
          if (!(share > 0.0f)) continue;
          const octomap::point3d centre(static_cast<float>(grid.centre(0, i)), static_cast<float>(grid.centre(1, j)),
                                        static_cast<float>(grid.centre(2, k)));
          if (share >= 1.0f - 1e-6f) total.updateNode(centre, true);
          const std::array<std::uint8_t, 3> colour = coverageColour(share);
          shares.updateNode(centre, true)->setColor(colour[0], colour[1], colour[2]);
        }
      }
    }
    // OctoMap's inner update dereferences the root: an empty tree has none.
    if (total.size() > 0) total.updateInnerOccupancy(), total.prune();
    if (shares.size() > 0) shares.updateInnerOccupancy();
    const std::string total_name = "total_orientation_" + sign + ".bt", shares_name = "coverage_" + sign + ".ot";
    writeFile(directory, total_name, [&](std::ostream& stream) { return total.writeBinary(stream); });
    writeFile(directory, shares_name, [&](std::ostream& stream) { return shares.write(stream); });
    names.push_back(total_name);
    names.push_back(shares_name);
  }
  return names;
}

}  // namespace maximal_workspace
