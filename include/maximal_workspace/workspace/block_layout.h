#pragma once
// The unit of storage of a workspace analysis: the grid's box cut into blocks of side^dims
// cells (side 8 up to three variables, 4 beyond, so a block stays under 4096 cells).
// Block coordinates follow the grid's lattice indices divided by the side, so on a grid
// over x y z each block is one octree node three levels above the leaves. Cells inside a
// block: the last variable fastest, each coordinate a bit field of the cell index.

#include <array>
#include <cstdint>

#include "maximal_workspace/workspace/grid.h"

namespace maximal_workspace {

class BlockLayout {
 public:
  BlockLayout() = default;
  explicit BlockLayout(const Grid& grid);

  int dims() const { return dims_; }
  int sideBits() const { return bits_; }
  int side() const { return 1 << bits_; }
  int cellsPerBlock() const { return 1 << (bits_ * dims_); }
  std::int64_t blocks(int d) const { return blocks_[d]; }
  std::int64_t size(int d) const { return size_[d]; }  // the grid's cells along d
  bool periodic(int d) const { return periodic_[d]; }
  // A TiltTorsion grid's tilt and azimuth dimensions (else -1): the cells of the first
  // tilt layer that differ only in azimuth meet at the pole, one orientation.
  int tiltDim() const { return tilt_dim_; }
  int azimuthDim() const { return azimuth_dim_; }
  std::uint64_t blockCount() const { return block_count_; }
  std::uint64_t blockIndex(const GridCell& block) const;
  GridCell blockCoords(std::uint64_t block) const;
  // In-block coordinate along d of a cell index, and the cell index of coordinates.
  // Inline, as inBox: the thin layers' check calls them for every cell of the ranges it
  // proves (a call each was a tenth of that stage at 2 mm, perf).
  int cellCoord(int cell, int d) const { return cell >> ((dims_ - 1 - d) * bits_) & ((1 << bits_) - 1); }
  int cellIndex(const int* coords) const {
    int cell = 0;
    for (int d = 0; d < dims_; ++d) cell = cell << bits_ | coords[d];
    return cell;
  }
  // Grid coordinates (cell index per variable) of a block's cell; may lie beyond the box.
  GridCell cellCoords(std::uint64_t block, int cell) const;
  // The block and in-block cell of grid coordinates; false beyond the box.
  bool locate(const GridCell& coords, std::uint64_t* block, int* cell) const;
  bool locate(std::uint64_t grid_index, std::uint64_t* block, int* cell) const;
  std::uint64_t gridIndex(std::uint64_t block, int cell) const;
  // What a cell's grid index adds to its block's first cell's: gridIndex(b, c) ==
  // gridIndex(b, 0) + cellGridOffset(c) (modulo 2^64 for padding cells), without the
  // divisions that find a block's coordinates.
  std::uint64_t cellGridOffset(int cell) const {
    std::uint64_t offset = 0;
    for (int d = 0; d < dims_; ++d) offset += static_cast<std::uint64_t>(cellCoord(cell, d)) * grid_stride_[d];
    return offset;
  }
  bool inBox(const GridCell& coords) const {
    for (int d = 0; d < dims_; ++d) {
      if (coords[d] < 0 || coords[d] >= size_[d]) return false;
    }
    return true;
  }
  // The neighbour one cell along d (direction +1 or -1) of (block, cell), wrapping along a
  // periodic variable; false when it leaves the block lattice. It may be a cell beyond the
  // box (a block's padding), never along a periodic variable. Inline: the region
  // labelling calls it for every cell of every page.
  bool neighbour(std::uint64_t block, int cell, int d, int direction, std::uint64_t* neighbour_block,
                 int* neighbour_cell) const {
    if (periodic_[d]) return periodicNeighbour(block, cell, d, direction, neighbour_block, neighbour_cell);
    const int shift = (dims_ - 1 - d) * bits_;
    const int moved = (cell >> shift & ((1 << bits_) - 1)) + direction;
    if (moved >= 0 && moved < (1 << bits_)) {
      *neighbour_block = block;
      *neighbour_cell = cell + direction * (1 << shift);
      return true;
    }
    const std::int64_t at = static_cast<std::int64_t>(block / block_stride_[d] % blocks_[d]);
    if (at + direction < 0 || at + direction >= blocks_[d]) return false;
    *neighbour_block = direction > 0 ? block + block_stride_[d] : block - block_stride_[d];
    *neighbour_cell = cell - direction * (((1 << bits_) - 1) << shift);
    return true;
  }

 private:
  bool periodicNeighbour(std::uint64_t block, int cell, int d, int direction, std::uint64_t* neighbour_block,
                         int* neighbour_cell) const;

  int dims_ = 0;
  int bits_ = 0;
  std::array<std::int64_t, kMaxGridDims> size_{};    // grid cells per variable
  std::array<std::int64_t, kMaxGridDims> offset_{};  // in-block position of grid cell 0
  std::array<std::int64_t, kMaxGridDims> blocks_{};
  std::array<std::uint64_t, kMaxGridDims> block_stride_{};
  std::array<std::uint64_t, kMaxGridDims> grid_stride_{};
  std::array<bool, kMaxGridDims> periodic_{};
  int tilt_dim_ = -1, azimuth_dim_ = -1;
  std::uint64_t block_count_ = 0;
};

}  // namespace maximal_workspace
