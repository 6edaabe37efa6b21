#include "workspace/block_components.h"

#include <algorithm>
#include <numeric>
#include <optional>
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
  ComponentLabelling(const BlockLayout& layout, const CodeMap& codes, const CodeTable<std::uint8_t>& key_of_code,
                     const FaceCuts& cuts, int cut_mode, LabelLayer* layer, const CancelCheck& cancelled)
      : layout_(layout), codes_(codes), key_of_code_(key_of_code), cuts_(cuts), cut_mode_(cut_mode), layer_(*layer),
        cancelled_(cancelled),
        block_key_(layout.blockCount()), block_node_(layout.blockCount(), kNoNode) {}

  std::vector<Component> run() {
    labelBlocks();
    joinAcrossFaces();
    joinAcrossThePole();
    return number();
  }

 private:
  void checkIn(std::uint64_t b) const {
    if (b % kBlocksBetweenChecks == 0) throwIfCancelled(cancelled_);
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
        const CodeMap::Page page = codes_.page(b);
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

  // Runs of cells of one key along the last variable are the units: a row of one key is
  // one run, so a block joins a few runs per row rather than every cell to its neighbours.
  struct Run {
    std::uint16_t begin, end;  // cells [begin, end) of one row
    std::uint8_t key;
  };

  void labelLocally(std::uint64_t b, std::vector<std::uint16_t>& parent) {
    const int cells = layout_.cellsPerBlock(), bits = layout_.sideBits(), dims = layout_.dims(), side = 1 << bits;
    const CodeMap::Page codes = codes_.page(b);
    const bool cut = cuts_.touches(b);
    const int lead = dims - 1;
    auto root = [&parent](int i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    auto unite = [&](int a, int r) {
      a = root(a), r = root(r);
      parent[std::max(a, r)] = static_cast<std::uint16_t>(std::min(a, r));
    };
    // Whether cell c joins its neighbour towards +d.
    if (cut) markCutFaces(b);
    auto open = [&](int c, int d) { return !cut || (closed_[c] >> d & 1u) == 0; };
    std::vector<Run>& runs = runs_;
    std::vector<std::uint16_t>& row_first = row_first_;  // per row, its first run; then the end
    runs.clear();
    row_first.clear();
    for (int row = 0; row < cells >> bits; ++row) {
      row_first.push_back(static_cast<std::uint16_t>(runs.size()));
      const int base = row << bits;
      for (int c = base; c < base + side;) {
        const std::uint8_t key = key_of_code_[codes[c]];
        int e = c + 1;
        while (e < base + side && key_of_code_[codes[e]] == key && open(e - 1, lead)) ++e;
        if (key != 0) runs.push_back(Run{static_cast<std::uint16_t>(c), static_cast<std::uint16_t>(e), key});
        c = e;
      }
    }
    row_first.push_back(static_cast<std::uint16_t>(runs.size()));
    for (std::size_t r = 0; r < runs.size(); ++r) parent[r] = static_cast<std::uint16_t>(r);
    // Each row's runs joined to the overlapping runs of its earlier neighbour rows.
    for (int row = 0; row < cells >> bits; ++row) {
      for (int d = 0; d < lead; ++d) {
        const int shift = (lead - 1 - d) * bits;  // of d in the row index
        if ((row >> shift & (side - 1)) == 0) continue;
        const int before = row - (1 << shift), offset = (1 << shift) << bits;  // cells between the rows
        int i = row_first[before];
        for (int j = row_first[row]; j < row_first[row + 1]; ++j) {
          const Run& run = runs[j];
          while (i < row_first[before + 1] && runs[i].end + offset <= run.begin) ++i;
          for (int k = i; k < row_first[before + 1] && runs[k].begin + offset < run.end; ++k) {
            if (runs[k].key != run.key) continue;
            const int from = std::max<int>(run.begin, runs[k].begin + offset), to = std::min<int>(run.end, runs[k].end + offset);
            bool joined = false;
            for (int c = from; c < to && !joined; ++c) joined = open(c - offset, d);
            if (joined) unite(j, k);
          }
        }
      }
    }
    // Local ids in order of first cell: runs are in cell order.
    std::vector<std::uint16_t>& local = local_scratch_;
    local.assign(cells, LabelLayer::kNoLocal);
    std::vector<std::uint16_t>& run_local = run_local_;
    run_local.assign(runs.size(), LabelLayer::kNoLocal);
    std::uint32_t count = 0;
    for (std::size_t r = 0; r < runs.size(); ++r) {
      const int top = root(static_cast<int>(r));
      if (run_local[top] == LabelLayer::kNoLocal) run_local[top] = static_cast<std::uint16_t>(count++);
      std::fill(local.begin() + runs[r].begin, local.begin() + runs[r].end, run_local[top]);
    }
    layer_.addPage(b, local.data(), count);
    block_node_[b] = newNodes(count);
  }

  // closed_: per cell of block b, bit d where its face towards +d is cut in this layer. In
  // 6-D most blocks touch a cut; the cuts are searched once a row of cells inside the box
  // (padding has no faces), not once a cell and variable: that search was 16 % of the
  // CPU of the 64-mode hexapod over an orientation set (perf).
  void markCutFaces(std::uint64_t b) {
    const int cells = layout_.cellsPerBlock(), side = layout_.side(), last = layout_.dims() - 1;
    closed_.assign(cells, 0);
    const std::uint64_t first = layout_.gridIndex(b, 0);
    const GridCell corner = layout_.cellCoords(b, 0);
    const int from = static_cast<int>(std::max<std::int64_t>(0, -corner[last]));
    const int to = static_cast<int>(std::min<std::int64_t>(side, layout_.size(last) - corner[last]));
    for (int row = 0; row < cells && from < to; row += side) {
      GridCell at = corner;
      for (int d = 0; d < last; ++d) at[d] += layout_.cellCoord(row, d);
      at[last] += from;
      if (!layout_.inBox(at)) continue;
      cuts_.forEachCut(first + layout_.cellGridOffset(row) + static_cast<std::uint64_t>(from),
                       static_cast<std::uint64_t>(to - from), cut_mode_,
                       [&](std::uint64_t i, int d) { closed_[row + from + static_cast<int>(i)] |= 1u << d; });
    }
  }

  // What joining reads of a block, looked up once per block rather than once per cell.
  struct BlockView {
    int key;
    CodeMap::Page codes;
    LabelLayer::LocalPage local;
    std::uint32_t first_node;
    bool cut;
    std::uint64_t block;
    std::uint64_t first_index = kUnknownIndex;  // the grid index of its first cell, once a cut is read
  };
  static constexpr std::uint64_t kUnknownIndex = ~std::uint64_t{0};
  BlockView view(std::uint64_t b) const {
    const bool mixed = block_key_[b] == kMixedKey;
    return BlockView{block_key_[b], mixed ? codes_.page(b) : CodeMap::Page(),
                     mixed ? layer_.localPage(b) : LabelLayer::LocalPage{nullptr, nullptr}, block_node_[b],
                     cuts_.touches(b), b};
  }
  int key(const BlockView& v, int c) const { return v.key != kMixedKey ? v.key : key_of_code_[v.codes[c]]; }
  std::uint32_t node(const BlockView& v, int c) const { return v.key != kMixedKey ? v.first_node : v.first_node + v.local[c]; }

  // Cell ca of block a and its neighbour towards +d, cell cb of block b (d -1: across the
  // pole, where no layer is checked).
  void join(BlockView& a, int ca, const BlockView& b, int cb, int d) {
    const int key_a = key(a, ca);
    if (key_a == 0 || key_a != key(b, cb)) return;
    if (d >= 0 && a.cut && cutFace(a, ca, d)) return;
    sets_.join(node(a, ca), node(b, cb));
  }

  // Whether the face of cell c of a block towards +d is cut. In 6-D most blocks touch a
  // cut: the block's first cell's grid index is found once, when first needed.
  bool cutFace(BlockView& v, int c, int d) {
    if (v.first_index == kUnknownIndex) v.first_index = layout_.gridIndex(v.block, 0);
    return cuts_.cut(v.first_index + layout_.cellGridOffset(c), d, cut_mode_);
  }

  // Nodes of face-neighbouring cells in different blocks, each pair once (towards +d),
  // and across the turn of a periodic variable.
  void joinAcrossFaces() {
    const int side = layout_.side(), cells = layout_.cellsPerBlock(), dims = layout_.dims();
    for (int d = 0; d < dims; ++d) {
      const int shift = (dims - 1 - d) * layout_.sideBits();
      std::vector<int> last_face;
      for (int c = 0; c < cells; ++c) {
        if ((c >> shift & (side - 1)) == side - 1) last_face.push_back(c);
      }
      std::uint64_t stride = 1;  // blocks between neighbours along d
      for (int e = d + 1; e < dims; ++e) stride *= static_cast<std::uint64_t>(layout_.blocks(e));
      for (std::uint64_t b = 0; b < layout_.blockCount(); ++b) {
        checkIn(b);
        if (block_key_[b] == 0) continue;
        if (static_cast<std::int64_t>(b / stride % layout_.blocks(d)) + 1 < layout_.blocks(d)) {
          const std::uint64_t next = b + stride;
          if (block_key_[next] == 0) continue;
          BlockView here = view(b);
          const BlockView there = view(next);
          if (here.key != kMixedKey && there.key != kMixedKey) {
            join(here, 0, there, 0, d);
            continue;
          }
          for (int c : last_face) join(here, c, there, c - ((side - 1) << shift), d);
        } else if (layout_.periodic(d)) {
          joinAcrossTheTurn(b, d);
        }
      }
    }
  }

  // The cells of a block whose in-block coordinate along d is `layer`, in cell order, with
  // their grid coordinates (`corner`: the block's first cell's): the turn and the pole
  // join those alone. Visiting every cell of the blocks there, each cell's grid
  // coordinates and its partner's found anew, took a quarter of the region labelling over
  // an orientation set, whose few tilt layers all lie in the pole's blocks (64-mode
  // hexapod, 20 mm, 10 deg: 11.2 s -> 8.3 s).
  template <class Visit>
  void forLayer(int d, int layer, const GridCell& corner, const Visit& visit) const {
    const int bits = layout_.sideBits(), dims = layout_.dims(), shift = (dims - 1 - d) * bits, low = (1 << shift) - 1;
    for (int i = 0; i < layout_.cellsPerBlock() >> bits; ++i) {
      const int c = (i & ~low) << bits | layer << shift | (i & low);
      GridCell at = corner;
      for (int e = 0; e < dims; ++e) at[e] += layout_.cellCoord(c, e);
      if (layout_.inBox(at)) visit(c, at);
    }
  }
  // Cell c with its in-block coordinate along d taken from cell `from`.
  int withCoordOf(int c, int from, int d) const {
    const int field = (layout_.side() - 1) << (layout_.dims() - 1 - d) * layout_.sideBits();
    return (c & ~field) | (from & field);
  }

  // The box's last layer along periodic d, in the lattice's last block, to its first: its
  // cells all wrap into one block, at one in-block coordinate along d.
  void joinAcrossTheTurn(std::uint64_t b, int d) {
    const GridCell corner = layout_.cellCoords(b, 0);
    const std::int64_t layer = layout_.size(d) - 1 - corner[d];
    if (layer < 0 || layer >= layout_.side()) return;
    BlockView here = view(b);
    std::optional<BlockView> there;
    int wrapped = 0;  // a wrapped cell, for its coordinate along d
    forLayer(d, static_cast<int>(layer), corner, [&](int c, const GridCell&) {
      if (!there) {
        std::uint64_t next = 0;
        if (!layout_.neighbour(b, c, d, 1, &next, &wrapped)) return;
        there = view(next);
      } else if (here.key != kMixedKey && there->key != kMixedKey) {
        return;  // two uniform blocks: one join holds for all
      }
      join(here, c, *there, withCoordOf(c, wrapped, d), d);
    });
  }

  // Each cell of the first tilt layer to the cell of azimuth index 0 beside it in every
  // other variable: they share the pole's orientations, so one key there is one component.
  // A block's anchors all lie in one block, at one in-block azimuth coordinate.
  void joinAcrossThePole() {
    const int tilt = layout_.tiltDim(), azimuth = layout_.azimuthDim();
    if (tilt < 0) return;
    for (std::uint64_t b = 0; b < layout_.blockCount(); ++b) {
      checkIn(b);
      if (block_key_[b] == 0) continue;
      const GridCell corner = layout_.cellCoords(b, 0);
      if (corner[tilt] > 0 || -corner[tilt] >= layout_.side()) continue;
      BlockView here = view(b);
      std::optional<BlockView> anchors;
      int anchor_cell = 0;  // an anchor, for its in-block azimuth coordinate
      forLayer(tilt, static_cast<int>(-corner[tilt]), corner, [&](int c, const GridCell& at) {
        if (at[azimuth] == 0) return;
        if (!anchors) {
          GridCell pole = at;
          pole[azimuth] = 0;
          std::uint64_t anchor = 0;
          if (!layout_.locate(pole, &anchor, &anchor_cell)) return;
          anchors = view(anchor);
        } else if (here.key != kMixedKey && anchors->key != kMixedKey) {
          return;  // two uniform blocks: one join holds for all
        }
        join(here, c, *anchors, withCoordOf(c, anchor_cell, azimuth), -1);
      });
    }
  }

  // Components in block order of their first cell; every cell gets its label.
  std::vector<Component> number() {
    std::vector<std::int32_t> id_of_root(node_count_, kNoLabel);
    std::vector<Component> components;
    auto component = [&](std::uint32_t node, int key, std::uint64_t b, int c, std::uint64_t cells) {
      std::int32_t& id = id_of_root[sets_.root(node)];
      if (id == kNoLabel) {
        id = static_cast<std::int32_t>(components.size());
        components.push_back(Component{static_cast<std::uint8_t>(key), 0, b, c});
      }
      components[id].cells += cells;
      return id;
    };
    const int cells = layout_.cellsPerBlock();
    // Per local component of a block: its cells and its first cell (local ids are in
    // order of first cell, so going through them meets components as the cells would).
    std::vector<std::uint32_t> local_cells(cells);
    std::vector<int> local_first(cells);
    for (std::uint64_t b = 0; b < layout_.blockCount(); ++b) {
      checkIn(b);
      if (block_key_[b] == 0) continue;
      if (block_key_[b] != kMixedKey) {
        layer_.setUniform(b, component(block_node_[b], block_key_[b], b, 0, static_cast<std::uint64_t>(cells)));
        continue;
      }
      const LabelLayer::LocalPage local = layer_.localPage(b);
      int count = 0;
      for (int c = 0; c < cells; ++c) {
        const std::uint16_t id = local[c];
        if (id == LabelLayer::kNoLocal) continue;
        if (id == count) local_cells[count] = 0, local_first[count++] = c;
        ++local_cells[id];
      }
      std::int32_t* labels = layer_.localLabels(b);
      const CodeMap::Page codes = codes_.page(b);
      for (int id = 0; id < count; ++id) {
        labels[id] = component(block_node_[b] + id, key_of_code_[codes[local_first[id]]], b, local_first[id], local_cells[id]);
      }
    }
    return components;
  }

  const BlockLayout& layout_;
  const CodeMap& codes_;
  const CodeTable<std::uint8_t>& key_of_code_;
  const FaceCuts& cuts_;
  const int cut_mode_;
  LabelLayer& layer_;
  const CancelCheck& cancelled_;
  std::vector<std::int16_t> block_key_;
  std::vector<std::uint32_t> block_node_;  // a uniform block's node, or a page's first local node
  std::uint64_t node_count_ = 0;
  DisjointSets sets_;
  std::vector<std::uint16_t> local_scratch_, row_first_, run_local_;
  static_assert(kMaxGridDims <= 8, "closed_ holds a bit a variable");
  std::vector<std::uint8_t> closed_;  // markCutFaces's
  std::vector<Run> runs_;
};

}  // namespace

std::vector<Component> labelComponents(const BlockLayout& layout, const CodeMap& codes,
                                       const CodeTable<std::uint8_t>& key_of_code, const FaceCuts& cuts,
                                       int cut_mode, LabelLayer* layer, const CancelCheck& cancelled) {
  *layer = LabelLayer(layout.blockCount(), layout.cellsPerBlock());
  return ComponentLabelling(layout, codes, key_of_code, cuts, cut_mode, layer, cancelled).run();
}

}  // namespace maximal_workspace
