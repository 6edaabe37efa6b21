#include "io/octree_pyramid.h"

#include <algorithm>

namespace maximal_workspace {

KeyPyramid::KeyPyramid(std::vector<std::int32_t> values, std::array<int, 3> size, std::array<std::uint32_t, 3> first_key) {
  levels_.push_back(Level{first_key, size, std::move(values)});
  buildLevels();
}

KeyPyramid::KeyPyramid(std::vector<std::int32_t> values, std::array<int, 3> size, std::array<std::uint32_t, 3> first_cell,
                       int base_level, FineValue fine)
    : base_level_(base_level), fine_(std::move(fine)) {
  levels_.push_back(Level{first_cell, size, std::move(values)});
  buildLevels();
}

void KeyPyramid::buildLevels() {
  // Each level halves the cells: level l + 1 cell c covers level l cells 2c and 2c + 1.
  while (levels_.back().size[0] > 1 || levels_.back().size[1] > 1 || levels_.back().size[2] > 1) {
    const Level& fine = levels_.back();
    Level coarse;
    for (int d = 0; d < 3; ++d) {
      coarse.origin[d] = fine.origin[d] >> 1;
      coarse.size[d] = static_cast<int>(((fine.origin[d] + fine.size[d] - 1) >> 1) - coarse.origin[d] + 1);
    }
    coarse.values.assign(static_cast<std::size_t>(coarse.size[0]) * coarse.size[1] * coarse.size[2], kEmpty);
    for (int i = 0; i < coarse.size[0]; ++i) {
      for (int j = 0; j < coarse.size[1]; ++j) {
        for (int k = 0; k < coarse.size[2]; ++k) {
          const std::array<std::uint32_t, 3> c = {coarse.origin[0] + i, coarse.origin[1] + j, coarse.origin[2] + k};
          const int finer = base_level_ + static_cast<int>(levels_.size()) - 1;
          std::int32_t combined = value(finer, {c[0] << 1, c[1] << 1, c[2] << 1});
          for (unsigned index = 1; index < 8 && combined != kMixed; ++index) {
            const std::int32_t child = value(finer,
                                             {(c[0] << 1) | (index & 1u), (c[1] << 1) | ((index >> 1) & 1u),
                                              (c[2] << 1) | ((index >> 2) & 1u)});
            if (child != combined) combined = kMixed;
          }
          coarse.values[(static_cast<std::size_t>(i) * coarse.size[1] + j) * coarse.size[2] + k] = combined;
        }
      }
    }
    levels_.push_back(std::move(coarse));
  }
}

std::int32_t KeyPyramid::value(int level, const std::array<std::uint32_t, 3>& cell) const {
  if (level < base_level_) return fine_(level, cell);
  level -= base_level_;
  if (level >= static_cast<int>(levels_.size())) {
    // Above the pyramid's top: the cube holding the whole box is mixed unless the box is
    // empty; every other cube is empty.
    const Level& top = levels_.back();
    const int shift = level - static_cast<int>(levels_.size()) + 1;
    for (int d = 0; d < 3; ++d) {
      if ((top.origin[d] >> shift) != cell[d]) return kEmpty;
    }
    return top.values[0] == kEmpty ? kEmpty : kMixed;
  }
  const Level& at = levels_[level];
  std::size_t index = 0;
  for (int d = 0; d < 3; ++d) {
    if (cell[d] < at.origin[d] || cell[d] >= at.origin[d] + static_cast<std::uint32_t>(at.size[d])) return kEmpty;
    index = index * at.size[d] + (cell[d] - at.origin[d]);
  }
  return at.values[index];
}

}  // namespace maximal_workspace
