#include "maximal_workspace/workspace/block_layout.h"

namespace maximal_workspace {

namespace {

std::int64_t floorDiv(std::int64_t a, std::int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

BlockLayout::BlockLayout(const Grid& grid) : dims_(grid.dims()), bits_(grid.dims() <= 3 ? 3 : 2) {
  const std::int64_t side = std::int64_t{1} << bits_;
  block_count_ = 1;
  for (int d = 0; d < dims_; ++d) {
    size_[d] = grid.size(d);
    periodic_[d] = grid.periodic(d);
    // Only a tilt grid from t = 0 has its first layer at the pole.
    if (grid.tiltDim() >= 0 && grid.firstLatticeIndex(grid.tiltDim()) == 0) {
      tilt_dim_ = grid.tiltDim(), azimuth_dim_ = grid.azimuthDim();
    }
    const std::int64_t first = grid.firstLatticeIndex(d);
    offset_[d] = first - floorDiv(first, side) * side;
    blocks_[d] = (offset_[d] + size_[d] + side - 1) / side;
    block_count_ *= static_cast<std::uint64_t>(blocks_[d]);
  }
  std::uint64_t block_stride = 1, grid_stride = 1;
  for (int d = dims_ - 1; d >= 0; --d) {
    block_stride_[d] = block_stride;
    grid_stride_[d] = grid_stride;
    block_stride *= static_cast<std::uint64_t>(blocks_[d]);
    grid_stride *= static_cast<std::uint64_t>(size_[d]);
  }
}

std::uint64_t BlockLayout::blockIndex(const GridCell& block) const {
  std::uint64_t index = 0;
  for (int d = 0; d < dims_; ++d) index += static_cast<std::uint64_t>(block[d]) * block_stride_[d];
  return index;
}

GridCell BlockLayout::blockCoords(std::uint64_t block) const {
  GridCell coords{};
  for (int d = 0; d < dims_; ++d) coords[d] = static_cast<std::int64_t>(block / block_stride_[d] % blocks_[d]);
  return coords;
}

GridCell BlockLayout::cellCoords(std::uint64_t block, int cell) const {
  GridCell coords = blockCoords(block);
  for (int d = 0; d < dims_; ++d) coords[d] = (coords[d] << bits_) + cellCoord(cell, d) - offset_[d];
  return coords;
}

bool BlockLayout::locate(const GridCell& coords, std::uint64_t* block, int* cell) const {
  if (!inBox(coords)) return false;
  GridCell at{};
  int in_block[kMaxGridDims];
  for (int d = 0; d < dims_; ++d) {
    const std::int64_t shifted = coords[d] + offset_[d];
    at[d] = shifted >> bits_;
    in_block[d] = static_cast<int>(shifted & ((std::int64_t{1} << bits_) - 1));
  }
  *block = blockIndex(at);
  *cell = cellIndex(in_block);
  return true;
}

bool BlockLayout::locate(std::uint64_t grid_index, std::uint64_t* block, int* cell) const {
  GridCell coords{};
  for (int d = 0; d < dims_; ++d) {
    coords[d] = static_cast<std::int64_t>(grid_index / grid_stride_[d]);
    grid_index %= grid_stride_[d];
  }
  return locate(coords, block, cell);
}

std::uint64_t BlockLayout::gridIndex(std::uint64_t block, int cell) const {
  const GridCell coords = cellCoords(block, cell);
  std::uint64_t index = 0;
  for (int d = 0; d < dims_; ++d) index += static_cast<std::uint64_t>(coords[d]) * grid_stride_[d];
  return index;
}

bool BlockLayout::periodicNeighbour(std::uint64_t block, int cell, int d, int direction, std::uint64_t* neighbour_block,
                                    int* neighbour_cell) const {
  // Along d alone: the other coordinates stay (all of them would cost a division each).
  const std::int64_t at = static_cast<std::int64_t>(block / block_stride_[d] % blocks_[d]);
  std::int64_t coord = (at << bits_) + cellCoord(cell, d) - offset_[d];
  const bool in_box = coord >= 0 && coord < size_[d];
  coord += direction;
  // Padding beyond the box is no part of the turn: only cells of the box wrap.
  if (in_box) coord = (coord + size_[d]) % size_[d];
  const std::int64_t shifted = coord + offset_[d];
  if (shifted < 0 || (shifted >> bits_) >= blocks_[d]) return false;
  *neighbour_block = block + static_cast<std::uint64_t>((shifted >> bits_) - at) * block_stride_[d];
  const int shift = (dims_ - 1 - d) * bits_;
  const int mask = (1 << bits_) - 1;
  *neighbour_cell = (cell & ~(mask << shift)) | static_cast<int>(shifted & mask) << shift;
  return true;
}

}  // namespace maximal_workspace
