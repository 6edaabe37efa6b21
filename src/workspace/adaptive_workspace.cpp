#include "maximal_workspace/workspace/adaptive_workspace.h"

#include <algorithm>
#include <atomic>
#include <mutex>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/workspace/block_labels.h"
#include "maximal_workspace/workspace/parallel.h"
#include "maximal_workspace/workspace/workspace_map.h"  // bandedSign, startCell

namespace maximal_workspace {

namespace {

constexpr CellCode kUnevaluated = 0xFFFC;  // scratch marker, never stored

std::int64_t floorDiv(std::int64_t a, std::int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

CellCode encode(const double* measures, int modes, double threshold) {
  int code = 0, weight = 1;
  for (int m = 0; m < modes; ++m, weight *= 3) code += (bandedSign(measures[m], threshold) + 1) * weight;
  return static_cast<CellCode>(code);
}

// Calls body(x, y, z) for the cells of the box [first, last] (inclusive) on whole rows along
// z where full_row(x, y), and on the row's two end cells elsewhere.
template <typename FullRow, typename Body>
void forRows(const int* first, const int* last, const FullRow& full_row, const Body& body) {
  for (int x = first[0]; x <= last[0]; ++x) {
    for (int y = first[1]; y <= last[1]; ++y) {
      if (full_row(x, y)) {
        for (int z = first[2]; z <= last[2]; ++z) body(x, y, z);
      } else {
        body(x, y, first[2]);
        if (last[2] != first[2]) body(x, y, last[2]);
      }
    }
  }
}

// The adaptive classification of one top node: a cube of side^3 cells held in a scratch
// array, local coordinates (x, y, z) from the cube's first corner.
class TopNodeClassifier {
 public:
  TopNodeClassifier(const Grid& grid, const BlockLayout& layout, const PoseClassifier& classifier, double threshold,
                    int side)
      : grid_(grid), layout_(layout), classifier_(classifier), threshold_(threshold), side_(side),
        codes_(static_cast<std::size_t>(side) * side * side) {}

  // Classifies the top node whose first block has block coordinates `first_block`; returns
  // the number of poses classified.
  std::uint64_t run(const BlockCoords& first_block) {
    origin_ = layout_.cellCoords(layout_.blockIndex(first_block), 0);
    for (int d = 0; d < 3; ++d) {
      // The local range the box holds.
      low_[d] = static_cast<int>(std::clamp<std::int64_t>(-origin_[d], 0, side_));
      high_[d] = static_cast<int>(std::clamp<std::int64_t>(grid_.size(d) - origin_[d], 0, side_));
    }
    for (int x = 0; x < side_; ++x) {
      for (int y = 0; y < side_; ++y) {
        for (int z = 0; z < side_; ++z) codes_[local(x, y, z)] = inBox(x, y, z) ? kUnevaluated : kCodeVoid;
      }
    }
    evaluated_ = 0;
    refine(0, 0, 0, side_);
    return evaluated_;
  }
  CellCode code(int x, int y, int z) const { return codes_[local(x, y, z)]; }

 private:
  std::size_t local(int x, int y, int z) const { return (static_cast<std::size_t>(x) * side_ + y) * side_ + z; }
  bool inBox(int x, int y, int z) const {
    return x >= low_[0] && x < high_[0] && y >= low_[1] && y < high_[1] && z >= low_[2] && z < high_[2];
  }

  // Evaluates the cube [x0, x0 + side)^3 (local), shell first.
  void refine(int x0, int y0, int z0, int side) {
    // The shell of the cube's part in the box: the box may cut the cube.
    int first[3], last[3];
    const int origin[3] = {x0, y0, z0};
    for (int d = 0; d < 3; ++d) {
      first[d] = std::max(origin[d], low_[d]);
      last[d] = std::min(origin[d] + side, high_[d]) - 1;
    }
    if (first[0] > last[0] || first[1] > last[1] || first[2] > last[2]) return;  // beyond the box
    // Shell cells only: whole planes at the first and last x, whole rows at the first and
    // last y, and the two end cells of every other row.
    const auto shell_row = [&](int x, int y) { return x == first[0] || x == last[0] || y == first[1] || y == last[1]; };
    evaluate(first, last, shell_row);
    const CellCode shell_code = codes_[local(first[0], first[1], first[2])];
    bool uniform = true;
    forRows(first, last, shell_row, [&](int x, int y, int z) { uniform = uniform && codes_[local(x, y, z)] == shell_code; });
    if (uniform) {
      forRows(first, last, [](int, int) { return true; }, [&](int x, int y, int z) {
        CellCode& code = codes_[local(x, y, z)];
        if (code == kUnevaluated) code = shell_code;
      });
      return;
    }
    if (side <= kBlockSide) {
      evaluate(first, last, [](int, int) { return true; });
      return;
    }
    const int half = side / 2;
    for (int i = 0; i < 8; ++i) refine(x0 + (i >> 2 & 1) * half, y0 + (i >> 1 & 1) * half, z0 + (i & 1) * half, half);
  }

  // Classifies the unevaluated cells forRows visits, in batches of TCP positions.
  template <typename FullRow>
  void evaluate(const int* first, const int* last, const FullRow& full_row) {
    slots_.clear();
    px_.clear(), py_.clear(), pz_.clear();
    forRows(first, last, full_row, [&](int x, int y, int z) {
      CellCode& code = codes_[local(x, y, z)];
      if (code != kUnevaluated) return;
      slots_.push_back(&code);
      px_.push_back(grid_.centre(0, origin_[0] + x));
      py_.push_back(grid_.centre(1, origin_[1] + y));
      pz_.push_back(grid_.centre(2, origin_[2] + z));
    });
    if (slots_.empty()) return;
    const int modes = static_cast<int>(classifier_.modes().size());
    inside_.resize(slots_.size());
    measures_.resize(slots_.size() * modes);
    classifier_.classify(PointBatch{px_.data(), py_.data(), pz_.data(), slots_.size()}, inside_.data(), measures_.data());
    for (std::size_t i = 0; i < slots_.size(); ++i) {
      *slots_[i] = inside_[i] ? encode(&measures_[i * modes], modes, threshold_) : kCodeOutside;
    }
    evaluated_ += slots_.size();
  }

  const Grid& grid_;
  const BlockLayout& layout_;
  const PoseClassifier& classifier_;
  const double threshold_;
  const int side_;
  std::vector<CellCode> codes_;
  BlockCoords origin_{};
  int low_[3] = {}, high_[3] = {};
  std::uint64_t evaluated_ = 0;
  std::vector<CellCode*> slots_;
  std::vector<double> px_, py_, pz_;
  std::vector<std::uint8_t> inside_;
  std::vector<double> measures_;
};

}  // namespace

int topNodeSide(const Grid& grid) {
  double step = 0;
  for (int d = 0; d < grid.dims(); ++d) step = std::max(step, grid.step(d));
  int side = kBlockSide;
  while (side < kMaxTopNodeSide && 2 * side * step <= kTopNodeLength * (1 + 1e-9)) side *= 2;  // 0.32 m at 5 mm
  return side;
}

int codeSign(CellCode code, int mode) {
  int value = code;
  for (int m = 0; m < mode; ++m) value /= 3;
  return value % 3 - 1;
}

BlockLayout::BlockLayout(const Grid& grid) {
  if (grid.dims() != 3) throw InputError("adaptive refinement needs a grid of three variables");
  block_count_ = 1;
  for (int d = 0; d < 3; ++d) {
    size_[d] = grid.size(d);
    const std::int64_t first = grid.firstLatticeIndex(d);
    offset_[d] = first - floorDiv(first, kBlockSide) * kBlockSide;
    blocks_[d] = (offset_[d] + size_[d] + kBlockSide - 1) / kBlockSide;
    block_count_ *= static_cast<std::uint64_t>(blocks_[d]);
  }
  block_stride_ = {static_cast<std::uint64_t>(blocks_[1] * blocks_[2]), static_cast<std::uint64_t>(blocks_[2]), 1};
}

std::uint64_t BlockLayout::blockIndex(const BlockCoords& block) const {
  return (static_cast<std::uint64_t>(block[0]) * blocks_[1] + block[1]) * blocks_[2] + block[2];
}

BlockCoords BlockLayout::blockCoords(std::uint64_t block) const {
  const std::int64_t z = static_cast<std::int64_t>(block % blocks_[2]);
  block /= blocks_[2];
  return {static_cast<std::int64_t>(block / blocks_[1]), static_cast<std::int64_t>(block % blocks_[1]), z};
}

BlockCoords BlockLayout::cellCoords(std::uint64_t block, int cell) const {
  const BlockCoords b = blockCoords(block);
  const int in_block[3] = {cell / (kBlockSide * kBlockSide), cell / kBlockSide % kBlockSide, cell % kBlockSide};
  BlockCoords result{};
  for (int d = 0; d < 3; ++d) result[d] = b[d] * kBlockSide + in_block[d] - offset_[d];
  return result;
}

bool BlockLayout::inBox(const BlockCoords& coords) const {
  for (int d = 0; d < 3; ++d) {
    if (coords[d] < 0 || coords[d] >= size_[d]) return false;
  }
  return true;
}

bool BlockLayout::locate(const BlockCoords& coords, std::uint64_t* block, int* cell) const {
  if (!inBox(coords)) return false;
  BlockCoords b{};
  int in_block[3];
  for (int d = 0; d < 3; ++d) {
    b[d] = (coords[d] + offset_[d]) / kBlockSide;
    in_block[d] = static_cast<int>((coords[d] + offset_[d]) % kBlockSide);
  }
  *block = blockIndex(b);
  *cell = blockCellIndex(in_block[0], in_block[1], in_block[2]);
  return true;
}

std::uint64_t BlockLayout::gridIndex(const BlockCoords& coords) const {
  return (static_cast<std::uint64_t>(coords[0]) * size_[1] + coords[1]) * size_[2] + coords[2];
}

void CodeMap::setPage(std::uint64_t block, std::unique_ptr<CellCode[]> page) {
  entry_[block] = static_cast<std::uint32_t>(pages_.size());
  pages_.push_back(std::move(page));
}

AdaptiveWorkspace classifyAdaptive(const Grid& grid, const PoseClassifier& classifier, const AdaptiveOptions& options) {
  const int modes = static_cast<int>(classifier.modes().size());
  if (modes > kMaxAdaptiveModes) {
    throw InputError("adaptive refinement handles at most " + std::to_string(kMaxAdaptiveModes) + " working modes, got " +
                     std::to_string(modes));
  }
  if (!classifier.orientationFixed()) throw InputError("adaptive refinement needs a fixed platform orientation");
  AdaptiveWorkspace workspace(grid);
  workspace.mode_count = modes;
  const BlockLayout& layout = workspace.layout;

  std::vector<double> start_measures(modes);
  const GridCell start = grid.cell(startCell(grid, classifier, start_measures.data()));
  layout.locate({start[0], start[1], start[2]}, &workspace.start_block, &workspace.start_cell);

  // Top nodes handed out one at a time: their cost varies a hundredfold.
  const int top_side = topNodeSide(grid);
  const int top_blocks = top_side / kBlockSide;
  std::array<std::int64_t, 3> tops{};
  for (int d = 0; d < 3; ++d) tops[d] = (layout.blocks(d) + top_blocks - 1) / top_blocks;
  const std::uint64_t top_count = static_cast<std::uint64_t>(tops[0] * tops[1] * tops[2]);
  std::atomic<std::uint64_t> next{0}, evaluated{0};
  std::mutex pages;
  const int workers = resolveThreadCount(options.threads);
  parallelFor(workers, workers, [&](std::size_t, std::size_t) {
    TopNodeClassifier top(grid, layout, classifier, options.singular_threshold, top_side);
    for (std::uint64_t t = next++; t < top_count; t = next++) {
      const BlockCoords first = {static_cast<std::int64_t>(t / (tops[1] * tops[2])) * top_blocks,
                                 static_cast<std::int64_t>(t / tops[2] % tops[1]) * top_blocks,
                                 static_cast<std::int64_t>(t % tops[2]) * top_blocks};
      evaluated += top.run(first);
      for (int i = 0; i < top_blocks * top_blocks * top_blocks; ++i) {
        const BlockCoords b = {first[0] + i / (top_blocks * top_blocks), first[1] + i / top_blocks % top_blocks,
                               first[2] + i % top_blocks};
        if (b[0] >= layout.blocks(0) || b[1] >= layout.blocks(1) || b[2] >= layout.blocks(2)) continue;
        const int base[3] = {static_cast<int>(b[0] - first[0]) * kBlockSide, static_cast<int>(b[1] - first[1]) * kBlockSide,
                             static_cast<int>(b[2] - first[2]) * kBlockSide};
        const CellCode first_code = top.code(base[0], base[1], base[2]);
        bool uniform = true;
        for (int c = 0; c < kBlockCells && uniform; ++c) {
          uniform = top.code(base[0] + (c >> 2 * kBlockBits), base[1] + (c >> kBlockBits & (kBlockSide - 1)),
                             base[2] + (c & (kBlockSide - 1))) == first_code;
        }
        const std::uint64_t block = layout.blockIndex(b);
        if (uniform) {
          workspace.codes.setUniform(block, first_code);
          continue;
        }
        std::unique_ptr<CellCode[]> page(new CellCode[kBlockCells]);
        for (int c = 0; c < kBlockCells; ++c) {
          page[c] = top.code(base[0] + (c >> 2 * kBlockBits), base[1] + (c >> kBlockBits & (kBlockSide - 1)),
                             base[2] + (c & (kBlockSide - 1)));
        }
        const std::lock_guard<std::mutex> lock(pages);
        workspace.codes.setPage(block, std::move(page));
      }
    }
  }, 1);
  workspace.evaluated = evaluated;

  // The wave front's workspace: the inside cells face-connected to the start.
  std::vector<std::uint8_t> inside_key(65536, 0);
  for (int code = 0; code < kCodeVoid; ++code) inside_key[code] = 1;
  LabelLayer connected;
  const std::vector<Component> components = labelComponents(workspace, inside_key, &connected);
  const std::int32_t start_component = connected.label(workspace.start_block, workspace.start_cell);
  workspace.inside_cells = components[start_component].cells;
  for (std::uint64_t b = 0; b < layout.blockCount(); ++b) {
    if (workspace.codes.uniform(b)) {
      const std::int32_t label = connected.label(b, 0);
      if (label != kNoLabel && label != start_component) workspace.codes.setUniform(b, kCodeDetached);
      continue;
    }
    CellCode* page = workspace.codes.page(b);
    for (int c = 0; c < kBlockCells; ++c) {
      const std::int32_t label = connected.label(b, c);
      if (label != kNoLabel && label != start_component) page[c] = kCodeDetached;
    }
  }
  return workspace;
}

}  // namespace maximal_workspace
