#pragma once
// Connected components (faces shared) over the block structure of an adaptive workspace,
// without expanding it: a block whose cells share one key is one node of the search, and
// only the cells of mixed blocks are nodes of their own. The key of a cell is a function of
// its code (a table); cells of key 0 belong to no component.

#include <cstdint>
#include <memory>
#include <vector>

#include "maximal_workspace/workspace/adaptive_workspace.h"

namespace maximal_workspace {

constexpr std::int32_t kNoLabel = -1;

// A component label per cell: one per block where the block's key is uniform, a page of
// kBlockCells labels where it is not.
struct Component;

class LabelLayer {
 public:
  bool uniform(std::uint64_t block) const { return block_label_[block] > kPageMarker; }
  std::int32_t label(std::uint64_t block, int cell) const {
    const std::int32_t entry = block_label_[block];
    return entry > kPageMarker ? entry : pages_[kPageMarker - entry][cell];
  }
  // Adds `offset` to every label (components numbered per layer become global ids).
  void shift(std::int32_t offset);

 private:
  friend std::vector<Component> labelComponents(const AdaptiveWorkspace&, const std::vector<std::uint8_t>&, LabelLayer*);
  static constexpr std::int32_t kPageMarker = -2;  // entries <= it: page kPageMarker - entry
  std::vector<std::int32_t> block_label_;
  std::vector<std::unique_ptr<std::int32_t[]>> pages_;
};

struct Component {
  std::uint8_t key = 0;
  std::uint64_t cells = 0;
  std::uint64_t seed_block = 0;  // first node in block order
  int seed_cell = 0;
};

// key_of_code: the key of every code (65536 entries). Components are numbered from 0 in
// block order of their first node.
std::vector<Component> labelComponents(const AdaptiveWorkspace& workspace, const std::vector<std::uint8_t>& key_of_code,
                                       LabelLayer* layer);

}  // namespace maximal_workspace
