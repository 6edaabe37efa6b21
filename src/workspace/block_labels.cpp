#include "maximal_workspace/workspace/block_labels.h"

namespace maximal_workspace {

namespace {

constexpr int kWholeBlock = kBlockCells;  // node id of a uniform block in the search stack
constexpr std::int16_t kMixedKey = -1;

std::uint64_t node(std::uint64_t block, int cell) { return block << 10 | static_cast<std::uint64_t>(cell); }

}  // namespace

void LabelLayer::shift(std::int32_t offset) {
  for (std::int32_t& entry : block_label_) {
    if (entry >= 0) entry += offset;
  }
  for (const std::unique_ptr<std::int32_t[]>& page : pages_) {
    for (int c = 0; c < kBlockCells; ++c) {
      if (page[c] >= 0) page[c] += offset;
    }
  }
}

std::vector<Component> labelComponents(const AdaptiveWorkspace& workspace, const std::vector<std::uint8_t>& key_of_code,
                                       LabelLayer* layer) {
  const BlockLayout& layout = workspace.layout;
  const CodeMap& codes = workspace.codes;
  const std::uint64_t blocks = layout.blockCount();

  // Each block's key, or kMixedKey; mixed blocks get a page of labels.
  std::vector<std::int16_t> block_key(blocks);
  layer->block_label_.assign(blocks, kNoLabel);
  layer->pages_.clear();
  for (std::uint64_t b = 0; b < blocks; ++b) {
    if (codes.uniform(b)) {
      block_key[b] = key_of_code[codes.uniformCode(b)];
      continue;
    }
    const CellCode* page = codes.page(b);
    const std::uint8_t first = key_of_code[page[0]];
    bool same = true;
    for (int c = 1; c < kBlockCells && same; ++c) same = key_of_code[page[c]] == first;
    if (same) {
      block_key[b] = first;
      continue;
    }
    block_key[b] = kMixedKey;
    layer->block_label_[b] = LabelLayer::kPageMarker - static_cast<std::int32_t>(layer->pages_.size());
    layer->pages_.emplace_back(new std::int32_t[kBlockCells]);
    std::fill_n(layer->pages_.back().get(), kBlockCells, kNoLabel);
  }
  auto key = [&](std::uint64_t b, int c) -> int {
    return block_key[b] != kMixedKey ? block_key[b] : key_of_code[codes.page(b)[c]];
  };
  auto label = [&](std::uint64_t b, int c) -> std::int32_t& {
    std::int32_t& entry = layer->block_label_[b];
    return block_key[b] != kMixedKey ? entry : layer->pages_[LabelLayer::kPageMarker - entry][c];
  };

  std::vector<Component> components;
  std::vector<std::uint64_t> stack;
  for (std::uint64_t seed_block = 0; seed_block < blocks; ++seed_block) {
    const bool whole = block_key[seed_block] != kMixedKey;
    for (int seed_cell = 0; seed_cell < (whole ? 1 : kBlockCells); ++seed_cell) {
      const int seed_key = key(seed_block, seed_cell);
      if (seed_key == 0 || label(seed_block, seed_cell) != kNoLabel) continue;
      Component component;
      component.key = static_cast<std::uint8_t>(seed_key);
      component.seed_block = seed_block;
      component.seed_cell = seed_cell;
      const std::int32_t id = static_cast<std::int32_t>(components.size());
      // Labels are set when a node is pushed, so each node enters the stack once.
      auto visit = [&](std::uint64_t b, int c) {
        std::int32_t& entry = label(b, c);
        if (entry != kNoLabel || key(b, c) != seed_key) return;
        entry = id;
        const bool uniform = block_key[b] != kMixedKey;
        component.cells += uniform ? kBlockCells : 1;
        stack.push_back(node(b, uniform ? kWholeBlock : c));
      };
      visit(seed_block, seed_cell);
      while (!stack.empty()) {
        const std::uint64_t top = stack.back();
        stack.pop_back();
        const std::uint64_t b = top >> 10;
        const int c = static_cast<int>(top & 1023);
        if (c != kWholeBlock) {
          for (int d = 0; d < 3; ++d) {
            for (int direction : {-1, 1}) {
              std::uint64_t nb = 0;
              int nc = 0;
              if (layout.neighbour(b, c, d, direction, &nb, &nc)) visit(nb, nc);
            }
          }
          continue;
        }
        // A uniform block: the facing layer of cells of each neighbouring block.
        const BlockCoords at = layout.blockCoords(b);
        for (int d = 0; d < 3; ++d) {
          for (int direction : {-1, 1}) {
            BlockCoords next = at;
            next[d] += direction;
            if (next[d] < 0 || next[d] >= layout.blocks(d)) continue;
            const std::uint64_t nb = layout.blockIndex(next);
            if (block_key[nb] != kMixedKey) {
              visit(nb, 0);
              continue;
            }
            const int face = direction > 0 ? 0 : kBlockSide - 1;
            for (int i = 0; i < kBlockSide; ++i) {
              for (int j = 0; j < kBlockSide; ++j) {
                const int cell = d == 0 ? blockCellIndex(face, i, j) : d == 1 ? blockCellIndex(i, face, j)
                                                                               : blockCellIndex(i, j, face);
                visit(nb, cell);
              }
            }
          }
        }
      }
      components.push_back(component);
    }
  }
  return components;
}

}  // namespace maximal_workspace
