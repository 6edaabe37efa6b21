#pragma once
// The workspace at a fine step without a per-cell array over the box (issue 7): the box is
// cut into cubes of kBlockSide^3 cells, aligned to octree keys. A block whose cells all
// share one classification code is stored as that code alone; a mixed block keeps a page
// of codes, one per cell. The classification itself is adaptive: a top cube (see
// topNodeSide) has only its one-cell surface shell evaluated; when the shell holds one code
// throughout, so does the cube, otherwise it splits into eight and each half-size cube is
// treated the same way, down to a block, which is then evaluated whole.
// The shell test assumes no singularity surface or workspace boundary lies wholly inside a
// cube without touching its shell; test_adaptive checks the result against the dense wave
// front at 10 and 5 mm, voxel by voxel, where the top cubes are 32 and 64 cells a side.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/workspace/grid.h"

namespace maximal_workspace {

// One cell's classification. Inside the workspace: sum over working modes m of
// (sign_m + 1) 3^m, sign_m the banded sign of det J_DKP, hence at most 10 working modes.
using CellCode = std::uint16_t;
constexpr CellCode kCodeOutside = 0xFFFF;   // tested: some chain cannot be assembled
constexpr CellCode kCodeDetached = 0xFFFE;  // assembled, but not connected to the start
constexpr CellCode kCodeVoid = 0xFFFD;      // beyond the box: never tested
constexpr int kMaxAdaptiveModes = 10;       // 3^10 codes stay below the markers

inline bool codeInside(CellCode code) { return code < kCodeVoid; }
// Banded sign of det J_DKP of working mode m in an inside code: +1, -1, or 0.
int codeSign(CellCode code, int mode);

constexpr int kBlockSide = 8;  // a power of two: in-block coordinates are bit fields
constexpr int kBlockBits = 3;
constexpr int kBlockCells = kBlockSide * kBlockSide * kBlockSide;
// The shell test's assumption is about size in metres, so top cubes keep one size in
// metres too: their shells then cost as the surfaces do, ~1/step^2, where cubes of a fixed
// number of cells would cost a fixed fraction of the box, ~1/step^3.
constexpr double kTopNodeLength = 0.32;
constexpr int kMaxTopNodeSide = 256;  // bounds each thread's scratch cube: 32 MiB
// Cells a side of a top cube: the largest power of two from kBlockSide to kMaxTopNodeSide
// whose cube spans at most kTopNodeLength along every axis.
int topNodeSide(const Grid& grid);

using BlockCoords = std::array<std::int64_t, 3>;

// Blocks over a three-variable grid. Block coordinates follow the grid's lattice indices
// divided by kBlockSide, so each block is one octree node when the grid's step is the
// octree's resolution. Cells inside a block: z fastest, then y, then x, like the grid.
class BlockLayout {
 public:
  BlockLayout() = default;
  explicit BlockLayout(const Grid& grid);

  std::int64_t blocks(int d) const { return blocks_[d]; }
  std::uint64_t blockCount() const { return block_count_; }
  std::uint64_t blockIndex(const BlockCoords& block) const;
  BlockCoords blockCoords(std::uint64_t block) const;
  // Grid coordinates (cell index per dimension) of a block's cell; may lie beyond the box.
  BlockCoords cellCoords(std::uint64_t block, int cell) const;
  // The block and in-block cell of grid coordinates; false beyond the box.
  bool locate(const BlockCoords& coords, std::uint64_t* block, int* cell) const;
  bool inBox(const BlockCoords& coords) const;
  std::uint64_t gridIndex(const BlockCoords& coords) const;
  // Neighbour one cell along d (direction +1 or -1) of (block, cell); false when it leaves
  // the block lattice. Inline: the region labelling calls it for every cell of every page.
  bool neighbour(std::uint64_t block, int cell, int d, int direction, std::uint64_t* neighbour_block,
                 int* neighbour_cell) const {
    const int shift = (2 - d) * kBlockBits;
    const int moved = (cell >> shift & (kBlockSide - 1)) + direction;
    const int step = direction * (1 << shift);
    if (moved >= 0 && moved < kBlockSide) {
      *neighbour_block = block;
      *neighbour_cell = cell + step;
      return true;
    }
    const std::int64_t at = static_cast<std::int64_t>(block / block_stride_[d] % blocks_[d]);
    if (at + direction < 0 || at + direction >= blocks_[d]) return false;
    *neighbour_block = direction > 0 ? block + block_stride_[d] : block - block_stride_[d];
    *neighbour_cell = cell - step * (kBlockSide - 1);
    return true;
  }

 private:
  std::array<std::int64_t, 3> size_{};    // grid cells per dimension
  std::array<std::int64_t, 3> offset_{};  // in-block position of grid cell 0
  std::array<std::int64_t, 3> blocks_{};
  std::array<std::uint64_t, 3> block_stride_{};
  std::uint64_t block_count_ = 0;
};

inline int blockCellIndex(int x, int y, int z) { return (x << kBlockBits | y) << kBlockBits | z; }
static_assert(kBlockSide == 1 << kBlockBits, "blocks are 2^kBlockBits cells a side");

// Codes of every box cell, block by block.
class CodeMap {
 public:
  CodeMap() = default;
  explicit CodeMap(std::uint64_t blocks) : entry_(blocks, kUniform | kCodeVoid) {}

  bool uniform(std::uint64_t block) const { return entry_[block] & kUniform; }
  // The code of a uniform block.
  CellCode uniformCode(std::uint64_t block) const { return static_cast<CellCode>(entry_[block]); }
  // The page of a mixed block: kBlockCells codes.
  const CellCode* page(std::uint64_t block) const { return pages_[entry_[block]].get(); }
  CellCode* page(std::uint64_t block) { return pages_[entry_[block]].get(); }
  CellCode code(std::uint64_t block, int cell) const { return uniform(block) ? uniformCode(block) : page(block)[cell]; }

  void setUniform(std::uint64_t block, CellCode code) { entry_[block] = kUniform | code; }
  // Stores a page (not thread-safe: callers serialise).
  void setPage(std::uint64_t block, std::unique_ptr<CellCode[]> page);
  std::uint64_t blockCount() const { return entry_.size(); }
  std::uint64_t pageCount() const { return pages_.size(); }

 private:
  static constexpr std::uint32_t kUniform = 0x80000000u;
  std::vector<std::uint32_t> entry_;  // kUniform | code, or a page index
  std::vector<std::unique_ptr<CellCode[]>> pages_;
};

struct AdaptiveWorkspace {
  AdaptiveWorkspace() = default;
  explicit AdaptiveWorkspace(const Grid& grid) : layout(grid), codes(layout.blockCount()) {}

  BlockLayout layout;
  CodeMap codes;
  int mode_count = 0;
  std::uint64_t evaluated = 0;       // poses classified
  std::uint64_t inside_cells = 0;    // cells connected to the start: the workspace's voxels
  std::uint64_t start_block = 0;
  int start_cell = 0;
};

struct AdaptiveOptions {
  double singular_threshold = 1e-3;
  int threads = 0;
};

// Classifies the box adaptively, then keeps as inside only the cells face-connected to the
// start, as the wave front does. Throws InputError for a grid that is not three-variable,
// an orientation that is not fixed, more than kMaxAdaptiveModes working modes, or a start
// outside the box or the workspace.
AdaptiveWorkspace classifyAdaptive(const Grid& grid, const PoseClassifier& classifier, const AdaptiveOptions& options);

}  // namespace maximal_workspace
