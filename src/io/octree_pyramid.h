#pragma once
// Builds an OctoMap tree already pruned, straight from a box of voxel values aligned to
// octree keys, instead of inserting millions of leaves and pruning afterwards (ten times
// slower at 5 mm). A pyramid over key space tells, for every octree node, whether its
// cube holds one value throughout (nothing, or one label) or several; the tree then gets
// exactly the nodes a prune() would leave: a leaf where a cube is uniform, an inner node
// where it is mixed.

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

namespace maximal_workspace {

class KeyPyramid {
 public:
  static constexpr std::int32_t kEmpty = std::numeric_limits<std::int32_t>::min();
  static constexpr std::int32_t kMixed = kEmpty + 1;
  static constexpr int kTreeDepth = 16;

  // The value of a cube below the base level, at cell index `cell` of level `level`.
  using FineValue = std::function<std::int32_t(int level, const std::array<std::uint32_t, 3>& cell)>;

  // `values`: one per box cell, z fastest then y then x (the grid's order), kEmpty where
  // nothing is; `size`: cells per axis; `first_key`: the octree key of cell (0, 0, 0).
  KeyPyramid(std::vector<std::int32_t> values, std::array<int, 3> size, std::array<std::uint32_t, 3> first_key);
  // The same from cubes of 2^base_level keys a side (the adaptive workspace's blocks):
  // `values` per cube, kMixed where it holds several; `first_cell`: the cube index
  // (key >> base_level) of cube (0, 0, 0); `fine` answers for the levels below, and is
  // asked only inside mixed cubes.
  KeyPyramid(std::vector<std::int32_t> values, std::array<int, 3> size, std::array<std::uint32_t, 3> first_cell,
             int base_level, FineValue fine);

  // Value of the cube of 2^level keys per side at cell index `cell` (key >> level):
  // a label, kEmpty, or kMixed.
  std::int32_t value(int level, const std::array<std::uint32_t, 3>& cell) const;

 private:
  struct Level {
    std::array<std::uint32_t, 3> origin{};  // cell index of the level's first cell
    std::array<int, 3> size{};
    std::vector<std::int32_t> values;
  };
  void buildLevels();

  std::vector<Level> levels_;  // from the base level up to the level where the box is one cell
  int base_level_ = 0;
  FineValue fine_;
};

// Creates under `root` (a node covering all key space, already allocated) the children
// the pyramid calls for. set_leaf(node, value) and set_inner(node) give each new node its
// data; create_child(node, index) allocates child `index` (OctoMap's order: bit 0 x,
// bit 1 y, bit 2 z).
template <class Node, class CreateChild, class SetLeaf, class SetInner>
void buildFromPyramid(Node* node, const KeyPyramid& pyramid, int level, const std::array<std::uint32_t, 3>& cell,
                      const CreateChild& create_child, const SetLeaf& set_leaf, const SetInner& set_inner) {
  for (unsigned index = 0; index < 8; ++index) {
    const std::array<std::uint32_t, 3> child_cell = {(cell[0] << 1) | (index & 1u), (cell[1] << 1) | ((index >> 1) & 1u),
                                                     (cell[2] << 1) | ((index >> 2) & 1u)};
    const std::int32_t value = pyramid.value(level - 1, child_cell);
    if (value == KeyPyramid::kEmpty) continue;
    Node* child = create_child(node, index);
    if (value == KeyPyramid::kMixed) {
      set_inner(child);
      buildFromPyramid(child, pyramid, level - 1, child_cell, create_child, set_leaf, set_inner);
    } else {
      set_leaf(child, value);
    }
  }
}

}  // namespace maximal_workspace
