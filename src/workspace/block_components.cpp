#include "workspace/block_components.h"

#include <array>

namespace maximal_workspace {

namespace {

constexpr std::int16_t kMixedKey = -1;
constexpr int kCellBits = 13;  // in-block cell indices and the whole-block marker below 2^13

std::uint64_t node(std::uint64_t block, int cell) { return block << kCellBits | static_cast<std::uint64_t>(cell); }

// The cells of a block on each of its faces: faces[d][0] at coordinate 0 along d,
// faces[d][1] at the last.
std::array<std::array<std::vector<int>, 2>, kMaxGridDims> faceCells(const BlockLayout& layout) {
  std::array<std::array<std::vector<int>, 2>, kMaxGridDims> faces;
  for (int c = 0; c < layout.cellsPerBlock(); ++c) {
    for (int d = 0; d < layout.dims(); ++d) {
      const int at = layout.cellCoord(c, d);
      if (at == 0) faces[d][0].push_back(c);
      if (at == layout.side() - 1) faces[d][1].push_back(c);
    }
  }
  return faces;
}

// The depth-first search shared by every component of one layer.
class ComponentSearch {
 public:
  ComponentSearch(const BlockLayout& layout, const CodeMap& codes, const std::vector<std::uint8_t>& key_of_code,
                  LabelLayer* layer)
      : layout_(layout), codes_(codes), key_of_code_(key_of_code), layer_(*layer), block_key_(layout.blockCount()),
        faces_(faceCells(layout)), whole_block_(layout.cellsPerBlock()) {}

  std::vector<Component> run() {
    classifyBlocks();
    std::vector<Component> components;
    for (std::uint64_t seed_block = 0; seed_block < layout_.blockCount(); ++seed_block) {
      const bool whole = block_key_[seed_block] != kMixedKey;
      for (int seed_cell = 0; seed_cell < (whole ? 1 : layout_.cellsPerBlock()); ++seed_cell) {
        const int seed_key = key(seed_block, seed_cell);
        if (seed_key == 0 || label(seed_block, seed_cell) != kNoLabel) continue;
        Component component;
        component.key = static_cast<std::uint8_t>(seed_key);
        component.seed_block = seed_block;
        component.seed_cell = seed_cell;
        grow(static_cast<std::int32_t>(components.size()), &component);
        components.push_back(component);
      }
    }
    return components;
  }

 private:
  // Each block's key, or kMixedKey; mixed blocks get a page of labels.
  void classifyBlocks() {
    const int cells = layout_.cellsPerBlock();
    for (std::uint64_t b = 0; b < layout_.blockCount(); ++b) {
      if (codes_.uniform(b)) {
        block_key_[b] = key_of_code_[codes_.uniformCode(b)];
        continue;
      }
      const CellCode* page = codes_.page(b);
      const std::uint8_t first = key_of_code_[page[0]];
      bool same = true;
      for (int c = 1; c < cells && same; ++c) same = key_of_code_[page[c]] == first;
      block_key_[b] = same ? first : kMixedKey;
      if (!same) layer_.addPage(b);
    }
  }
  int key(std::uint64_t b, int c) const { return block_key_[b] != kMixedKey ? block_key_[b] : key_of_code_[codes_.page(b)[c]]; }
  std::int32_t& label(std::uint64_t b, int c) {
    return block_key_[b] != kMixedKey ? layer_.uniformLabel(b) : layer_.page(b)[c];
  }

  // Labels are set when a node is pushed, so each node enters the stack once.
  void visit(std::uint64_t b, int c, int seed_key, std::int32_t id, Component* component) {
    std::int32_t& entry = label(b, c);
    if (entry != kNoLabel || key(b, c) != seed_key) return;
    entry = id;
    const bool uniform = block_key_[b] != kMixedKey;
    component->cells += uniform ? static_cast<std::uint64_t>(whole_block_) : 1;
    stack_.push_back(node(b, uniform ? whole_block_ : c));
  }

  void grow(std::int32_t id, Component* component) {
    const int seed_key = component->key;
    visit(component->seed_block, component->seed_cell, seed_key, id, component);
    while (!stack_.empty()) {
      const std::uint64_t top = stack_.back();
      stack_.pop_back();
      const std::uint64_t b = top >> kCellBits;
      const int c = static_cast<int>(top & ((1u << kCellBits) - 1));
      for (int d = 0; d < layout_.dims(); ++d) {
        for (int direction : {-1, 1}) {
          if (c != whole_block_) {
            std::uint64_t nb = 0;
            int nc = 0;
            if (layout_.neighbour(b, c, d, direction, &nb, &nc)) visit(nb, nc, seed_key, id, component);
          } else {
            growAcrossFace(b, d, direction, seed_key, id, component);
          }
        }
      }
    }
  }

  // From a uniform block across its face along (d, direction): the facing cells of the
  // block beside it, or that block whole when it is uniform too.
  void growAcrossFace(std::uint64_t b, int d, int direction, int seed_key, std::int32_t id, Component* component) {
    const std::vector<int>& own_face = faces_[d][direction > 0 ? 1 : 0];
    if (layout_.periodic(d)) {
      // The neighbours may wrap round the turn to any in-block offset: cell by cell.
      for (int c : own_face) {
        std::uint64_t nb = 0;
        int nc = 0;
        if (layout_.neighbour(b, c, d, direction, &nb, &nc)) visit(nb, nc, seed_key, id, component);
      }
      return;
    }
    GridCell next = layout_.blockCoords(b);
    next[d] += direction;
    if (next[d] < 0 || next[d] >= layout_.blocks(d)) return;
    const std::uint64_t nb = layout_.blockIndex(next);
    if (block_key_[nb] != kMixedKey) {
      visit(nb, 0, seed_key, id, component);
      return;
    }
    for (int cell : faces_[d][direction > 0 ? 0 : 1]) visit(nb, cell, seed_key, id, component);
  }

  const BlockLayout& layout_;
  const CodeMap& codes_;
  const std::vector<std::uint8_t>& key_of_code_;
  LabelLayer& layer_;
  std::vector<std::int16_t> block_key_;
  std::array<std::array<std::vector<int>, 2>, kMaxGridDims> faces_;
  const int whole_block_;  // node id of a uniform block
  std::vector<std::uint64_t> stack_;
};

}  // namespace

std::vector<Component> labelComponents(const BlockLayout& layout, const CodeMap& codes,
                                       const std::vector<std::uint8_t>& key_of_code, LabelLayer* layer) {
  *layer = LabelLayer(layout.blockCount(), layout.cellsPerBlock());
  return ComponentSearch(layout, codes, key_of_code, layer).run();
}

}  // namespace maximal_workspace
