#include "workspace/block_components.h"

#include <numeric>
#include <stdexcept>

namespace maximal_workspace {

namespace {

constexpr std::int16_t kMixedKey = -1;
// A pass over a 1 mm box (6.7 M blocks of the delta-like robot) takes seconds: asked this
// often, Ctrl-C stops it within milliseconds.
constexpr std::uint64_t kBlocksBetweenChecks = 4096;
constexpr std::uint32_t kNoNode = 0xFFFFFFFFu;

// Union-find over 32-bit ids, the root kept the smallest id of its set.
class DisjointSets {
 public:
  void resize(std::size_t count) {
    parent_.resize(count);
    std::iota(parent_.begin(), parent_.end(), 0u);
  }
  std::uint32_t root(std::uint32_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void join(std::uint32_t a, std::uint32_t b) {
    a = root(a), b = root(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<std::uint32_t> parent_;
};

// Components in three passes, none of them a search cell by cell: each block that is not
// uniform is labelled on its own (local components, by union-find over its cells); local
// components and uniform blocks are then the nodes of a union-find joined across block
// faces; last, components are numbered in block order of their first cell.
class ComponentLabelling {
 public:
  ComponentLabelling(const BlockLayout& layout, const CodeMap& codes, const std::vector<std::uint8_t>& key_of_code,
                     const FaceCuts& cuts, int cut_mode, LabelLayer* layer, const CancelCheck& cancelled)
      : layout_(layout), codes_(codes), key_of_code_(key_of_code), cuts_(cuts), cut_mode_(cut_mode), layer_(*layer),
        cancelled_(cancelled),
        block_key_(layout.blockCount()), block_node_(layout.blockCount(), kNoNode) {}

  std::vector<Component> run() {
    labelBlocks();
    joinAcrossFaces();
    return number();
  }

 private:
  void checkIn(std::uint64_t b) const {
    if (b % kBlocksBetweenChecks == 0) throwIfCancelled(cancelled_);
  }
  int key(std::uint64_t b, int c) const { return block_key_[b] != kMixedKey ? block_key_[b] : key_of_code_[codes_.page(b)[c]]; }
  std::uint32_t node(std::uint64_t b, int c) const {
    if (block_key_[b] != kMixedKey) return block_node_[b];
    return block_node_[b] + layer_.localPage(b)[c];
  }
  std::uint32_t newNodes(std::uint64_t count) {
    if (node_count_ + count >= kNoNode) throw std::runtime_error("component labelling: more nodes than 32-bit ids");
    const std::uint32_t first = static_cast<std::uint32_t>(node_count_);
    node_count_ += count;
    return first;
  }

  // Every block's key; the local components of the blocks that are not uniform.
  void labelBlocks() {
    const int cells = layout_.cellsPerBlock();
    std::vector<std::uint16_t> parent(cells);
    for (std::uint64_t b = 0; b < layout_.blockCount(); ++b) {
      checkIn(b);
      const std::uint8_t first = key_of_code_[codes_.code(b, 0)];
      bool same = true;
      if (!codes_.uniform(b)) {
        const CellCode* page = codes_.page(b);
        for (int c = 1; c < cells && same; ++c) same = key_of_code_[page[c]] == first;
      }
      // A cut splits what the codes alone would keep whole.
      same = same && !(first != 0 && cuts_.touches(b));
      block_key_[b] = same ? first : kMixedKey;
      if (same) {
        if (first != 0) block_node_[b] = newNodes(1);
        continue;
      }
      labelLocally(b, parent);
    }
    sets_.resize(node_count_);
  }

  void labelLocally(std::uint64_t b, std::vector<std::uint16_t>& parent) {
    const int cells = layout_.cellsPerBlock(), bits = layout_.sideBits(), dims = layout_.dims();
    const CellCode* codes = codes_.page(b);
    const bool cut = cuts_.touches(b);
    auto root = [&parent](int i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    // Each cell joined to its earlier face neighbours of the same key.
    for (int c = 0; c < cells; ++c) {
      parent[c] = static_cast<std::uint16_t>(c);
      const std::uint8_t own = key_of_code_[codes[c]];
      if (own == 0) continue;
      for (int d = 0; d < dims; ++d) {
        const int shift = (dims - 1 - d) * bits;
        if ((c >> shift & ((1 << bits) - 1)) == 0 || key_of_code_[codes[c - (1 << shift)]] != own) continue;
        if (cut && cuts_.cut(layout_.gridIndex(b, c - (1 << shift)), d, cut_mode_)) continue;
        const int a = root(c), r = root(c - (1 << shift));
        parent[std::max(a, r)] = static_cast<std::uint16_t>(std::min(a, r));
      }
    }
    // Local ids in order of first cell.
    std::vector<std::uint16_t>& local = local_scratch_;
    local.assign(cells, LabelLayer::kNoLocal);
    std::uint32_t count = 0;
    for (int c = 0; c < cells; ++c) {
      if (key_of_code_[codes[c]] == 0) continue;
      const int r = root(c);
      if (local[r] == LabelLayer::kNoLocal) local[r] = static_cast<std::uint16_t>(count++);
      local[c] = local[r];
    }
    layer_.addPage(b, local.data(), count);
    block_node_[b] = newNodes(count);
  }

  // Cell ca of block a and its neighbour towards +d, cell cb of block b.
  void join(std::uint64_t a, int ca, std::uint64_t b, int cb, int d) {
    const int key_a = key(a, ca);
    if (key_a == 0 || key_a != key(b, cb)) return;
    if (cuts_.touches(a) && cuts_.cut(layout_.gridIndex(a, ca), d, cut_mode_)) return;
    sets_.join(node(a, ca), node(b, cb));
  }

  // Nodes of face-neighbouring cells in different blocks, each pair once (towards +d),
  // and across the turn of a periodic variable.
  void joinAcrossFaces() {
    const int side = layout_.side(), cells = layout_.cellsPerBlock();
    for (int d = 0; d < layout_.dims(); ++d) {
      const int shift = (layout_.dims() - 1 - d) * layout_.sideBits();
      std::vector<int> last_face;
      for (int c = 0; c < cells; ++c) {
        if ((c >> shift & (side - 1)) == side - 1) last_face.push_back(c);
      }
      for (std::uint64_t b = 0; b < layout_.blockCount(); ++b) {
        checkIn(b);
        if (block_key_[b] == 0) continue;
        GridCell at = layout_.blockCoords(b);
        if (at[d] + 1 < layout_.blocks(d)) {
          ++at[d];
          const std::uint64_t next = layout_.blockIndex(at);
          if (block_key_[b] != kMixedKey && block_key_[next] != kMixedKey) {
            join(b, 0, next, 0, d);
            continue;
          }
          for (int c : last_face) join(b, c, next, c - ((side - 1) << shift), d);
        } else if (layout_.periodic(d)) {
          joinAcrossTheTurn(b, d);
        }
      }
    }
  }

  // The box's last layer along periodic d, in the lattice's last block, to its first.
  void joinAcrossTheTurn(std::uint64_t b, int d) {
    for (int c = 0; c < layout_.cellsPerBlock(); ++c) {
      const GridCell at = layout_.cellCoords(b, c);
      std::uint64_t next = 0;
      int next_cell = 0;
      if (!layout_.inBox(at) || !layout_.neighbour(b, c, d, 1, &next, &next_cell)) continue;
      if (layout_.cellCoords(next, next_cell)[d] == 0) join(b, c, next, next_cell, d);
    }
  }

  // Components in block order of their first cell; every cell gets its label.
  std::vector<Component> number() {
    std::vector<std::int32_t> id_of_root(node_count_, kNoLabel);
    std::vector<Component> components;
    auto component = [&](std::uint64_t b, int c, std::uint64_t cells) {
      std::int32_t& id = id_of_root[sets_.root(node(b, c))];
      if (id == kNoLabel) {
        id = static_cast<std::int32_t>(components.size());
        components.push_back(Component{static_cast<std::uint8_t>(key(b, c)), 0, b, c});
      }
      components[id].cells += cells;
      return id;
    };
    const int cells = layout_.cellsPerBlock();
    for (std::uint64_t b = 0; b < layout_.blockCount(); ++b) {
      checkIn(b);
      if (block_key_[b] == 0) continue;
      if (block_key_[b] != kMixedKey) {
        layer_.setUniform(b, component(b, 0, static_cast<std::uint64_t>(cells)));
        continue;
      }
      const LabelLayer::LocalPage local = layer_.localPage(b);
      std::int32_t* labels = layer_.localLabels(b);
      for (int c = 0; c < cells; ++c) {
        if (local[c] != LabelLayer::kNoLocal) labels[local[c]] = component(b, c, 1);
      }
    }
    return components;
  }

  const BlockLayout& layout_;
  const CodeMap& codes_;
  const std::vector<std::uint8_t>& key_of_code_;
  const FaceCuts& cuts_;
  const int cut_mode_;
  LabelLayer& layer_;
  const CancelCheck& cancelled_;
  std::vector<std::int16_t> block_key_;
  std::vector<std::uint32_t> block_node_;  // a uniform block's node, or a page's first local node
  std::uint64_t node_count_ = 0;
  DisjointSets sets_;
  std::vector<std::uint16_t> local_scratch_;
};

}  // namespace

std::vector<Component> labelComponents(const BlockLayout& layout, const CodeMap& codes,
                                       const std::vector<std::uint8_t>& key_of_code, const FaceCuts& cuts,
                                       int cut_mode, LabelLayer* layer, const CancelCheck& cancelled) {
  *layer = LabelLayer(layout.blockCount(), layout.cellsPerBlock());
  return ComponentLabelling(layout, codes, key_of_code, cuts, cut_mode, layer, cancelled).run();
}

}  // namespace maximal_workspace
