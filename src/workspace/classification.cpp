#include "workspace/classification.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <unordered_map>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "workspace/thin_layers.h"
#include "workspace/block_components.h"
#include "workspace/parallel.h"

namespace maximal_workspace {

namespace {

struct SignPatternHash {
  std::size_t operator()(const SignPattern& pattern) const {
    return static_cast<std::size_t>((pattern[0] * 0x9E3779B97F4A7C15ull) ^ (pattern[1] * 0xC2B2AE3D27D4EB4Full));
  }
};

// The codes of an analysis, shared by the classifying threads.
class PatternInterner {
 public:
  CellCode intern(const SignPattern& pattern) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto found = codes_.find(pattern);
    if (found != codes_.end()) return found->second;
    if (patterns_.size() >= kMaxSignPatterns) {
      throw InputError("the working modes' signs of det J_DKP combine in more than " + std::to_string(kMaxSignPatterns) +
                       " ways over this box; analyse fewer working modes at once (--modes)");
    }
    const CellCode code = static_cast<CellCode>(patterns_.size());
    patterns_.push_back(pattern);
    codes_.emplace(pattern, code);
    return code;
  }
  std::vector<SignPattern> take() { return std::move(patterns_); }

 private:
  std::mutex mutex_;
  std::vector<SignPattern> patterns_;
  std::unordered_map<SignPattern, CellCode, SignPatternHash> codes_;
};

// A thread's way to codes: neighbouring cells mostly share their pattern, and the rest
// are mostly patterns this thread met before.
class PatternEncoder {
 public:
  PatternEncoder(PatternInterner& interner, int modes, double threshold)
      : interner_(interner), modes_(modes), threshold_(threshold) {}

  // kCodeBlocked where every working mode breaks a robot limit.
  CellCode encode(const double* measures) {
    SignPattern pattern{};
    bool admissible = false;
    for (int m = 0; m < modes_; ++m) {
      const int sign = bandedSign(measures[m], threshold_);
      const bool blocked = !modeAdmissible(measures[m]);
      admissible = admissible || !blocked;
      const std::uint64_t bits = blocked ? kPatternBlocked : sign > 0 ? 1 : sign < 0 ? 2 : 0;
      pattern[m >> 5] |= bits << (2 * (m & 31));
    }
    if (!admissible) return kCodeBlocked;
    if (pattern == last_pattern_ && last_code_ != kCodeUnevaluated) return last_code_;
    const auto found = known_.find(pattern);
    last_code_ = found != known_.end() ? found->second : known_.emplace(pattern, interner_.intern(pattern)).first->second;
    last_pattern_ = pattern;
    return last_code_;
  }

 private:
  PatternInterner& interner_;
  const int modes_;
  const double threshold_;
  SignPattern last_pattern_{};
  CellCode last_code_ = kCodeUnevaluated;
  std::unordered_map<SignPattern, CellCode, SignPatternHash> known_;
};

// Calls body(local, x) for the cells of the box [first, last] (inclusive, local
// coordinates x) on whole rows along the last variable where full_row(x) holds for the
// leading coordinates, and on the row's two end cells elsewhere.
template <typename FullRow, typename Body>
void forRows(int dims, const std::size_t* stride, const int* first, const int* last, const FullRow& full_row,
             const Body& body) {
  const int lead = dims - 1;
  int x[kMaxGridDims];
  std::copy(first, first + dims, x);
  while (true) {
    std::size_t base = 0;
    for (int d = 0; d < lead; ++d) base += x[d] * stride[d];
    if (full_row(x)) {
      for (x[lead] = first[lead]; x[lead] <= last[lead]; ++x[lead]) body(base + x[lead], x);
    } else {
      x[lead] = first[lead];
      body(base + x[lead], x);
      if (last[lead] != first[lead]) {
        x[lead] = last[lead];
        body(base + x[lead], x);
      }
    }
    int d = lead - 1;
    while (d >= 0 && ++x[d] > last[d]) x[d] = first[d], --d;
    if (d < 0) return;
  }
}

// The adaptive classification of one top cube of side^dims cells, held in a scratch
// array; local coordinates from the cube's first corner, the last variable fastest.
class TopNodeClassifier {
 public:
  TopNodeClassifier(const Grid& grid, const BlockLayout& layout, const PoseClassifier& classifier,
                    PatternInterner& interner, double threshold, int side)
      : grid_(grid), layout_(layout), classifier_(classifier), encoder_(interner, int(classifier.modes().size()), threshold),
        dims_(grid.dims()), side_(side) {
    std::size_t cells = 1;
    for (int d = dims_ - 1; d >= 0; --d) {
      stride_[d] = cells;
      cells *= static_cast<std::size_t>(side);
    }
    codes_.resize(cells);
    // Where each cell of a block lies in the scratch cube, from the block's first cell.
    for (int c = 0; c < layout.cellsPerBlock(); ++c) {
      std::size_t offset = 0;
      for (int d = 0; d < dims_; ++d) offset += layout.cellCoord(c, d) * stride_[d];
      block_cell_offset_.push_back(offset);
    }
  }

  // Classifies the top cube whose first block has block coordinates `first_block`;
  // returns the number of poses classified.
  std::uint64_t run(const GridCell& first_block) {
    origin_ = layout_.cellCoords(layout_.blockIndex(first_block), 0);
    for (int d = 0; d < dims_; ++d) {
      // The local range the box holds.
      low_[d] = static_cast<int>(std::clamp<std::int64_t>(-origin_[d], 0, side_));
      high_[d] = static_cast<int>(std::clamp<std::int64_t>(grid_.size(d) - origin_[d], 0, side_));
    }
    std::fill(codes_.begin(), codes_.end(), kCodeVoid);
    int first[kMaxGridDims], last[kMaxGridDims];
    for (int d = 0; d < dims_; ++d) first[d] = low_[d], last[d] = high_[d] - 1;
    if (boxHolds(first, last)) {
      forRows(dims_, stride_.data(), first, last, [](const int*) { return true; },
              [&](std::size_t local, const int*) { codes_[local] = kCodeUnevaluated; });
    }
    evaluated_ = 0;
    const int origin[kMaxGridDims] = {};
    refine(origin, side_);
    return evaluated_;
  }
  // The code at a block's cell, the block's first cell at local offset `base`.
  CellCode code(std::size_t base, int cell) const { return codes_[base + block_cell_offset_[cell]]; }
  std::size_t localOffset(const int* local) const {
    std::size_t offset = 0;
    for (int d = 0; d < dims_; ++d) offset += local[d] * stride_[d];
    return offset;
  }

 private:
  bool boxHolds(const int* first, const int* last) const {
    for (int d = 0; d < dims_; ++d) {
      if (first[d] > last[d]) return false;
    }
    return true;
  }

  // Evaluates the cube [origin, origin + side) (local): its shell and its probes first.
  void refine(const int* origin, int side) {
    // The shell of the cube's part in the box: the box may cut the cube.
    int first[kMaxGridDims], last[kMaxGridDims];
    for (int d = 0; d < dims_; ++d) {
      first[d] = std::max(origin[d], low_[d]);
      last[d] = std::min(origin[d] + side, high_[d]) - 1;
    }
    if (!boxHolds(first, last)) return;
    // Shell cells only: whole rows where a leading coordinate is at its first or last
    // value, and the two end cells of every other row.
    const auto shell_row = [&](const int* x) {
      for (int d = 0; d + 1 < dims_; ++d) {
        if (x[d] == first[d] || x[d] == last[d]) return true;
      }
      return false;
    };
    const auto enqueue = [this](std::size_t local, const int* x) { this->enqueue(local, x); };
    forRows(dims_, stride_.data(), first, last, shell_row, enqueue);
    forProbes(first, last, enqueue);
    flush();
    const CellCode shell_code = codes_[localOffset(first)];
    bool uniform = true;
    const auto agrees = [&](std::size_t local, const int*) { uniform = uniform && codes_[local] == shell_code; };
    forRows(dims_, stride_.data(), first, last, shell_row, agrees);
    forProbes(first, last, agrees);
    const auto every_row = [](const int*) { return true; };
    if (uniform) {
      forRows(dims_, stride_.data(), first, last, every_row, [&](std::size_t local, const int*) {
        if (codes_[local] == kCodeUnevaluated) codes_[local] = shell_code;
      });
      return;
    }
    if (side <= layout_.side()) {
      forRows(dims_, stride_.data(), first, last, every_row, enqueue);
      flush();
      return;
    }
    const int half = side / 2;
    for (int child = 0; child < (1 << dims_); ++child) {
      int child_origin[kMaxGridDims];
      for (int d = 0; d < dims_; ++d) child_origin[d] = origin[d] + (child >> (dims_ - 1 - d) & 1) * half;
      refine(child_origin, half);
    }
  }

  // Calls body(local, x) for the probes within [first, last]: the middle cell of every
  // block. A feature larger than a block that the shell does not touch still meets one,
  // so its cube is refined: the shell test alone would miss a whole small workspace
  // inside one top cube.
  template <typename Body>
  void forProbes(const int* first, const int* last, const Body& body) const {
    const int side = layout_.side(), middle = side / 2;
    int from[kMaxGridDims], to[kMaxGridDims], x[kMaxGridDims];
    for (int d = 0; d < dims_; ++d) {
      // Local cube coordinates are block-aligned: probes sit at k side + middle.
      from[d] = (first[d] - middle + side - 1) / side * side + middle;
      to[d] = last[d];
      if (from[d] > to[d]) return;
      x[d] = from[d];
    }
    while (true) {
      body(localOffset(x), x);
      int d = dims_ - 1;
      while (d >= 0 && (x[d] += side) > to[d]) x[d] = from[d], --d;
      if (d < 0) return;
    }
  }

  // Queues a cell for classification unless it has its code already.
  void enqueue(std::size_t local, const int* x) {
    if (codes_[local] != kCodeUnevaluated) return;
    codes_[local] = kCodeQueued;
    slots_.push_back(local);
    Pose pose = grid_.spec().start;
    for (int d = 0; d < dims_; ++d) pose.setValue(grid_.variable(d), grid_.centre(d, origin_[d] + x[d]));
    poses_.push_back(pose);
  }

  // Classifies the queued cells, in batches: of TCP positions when the orientation is
  // fixed, else of whole poses.
  void flush() {
    if (slots_.empty()) return;
    const std::size_t modes = classifier_.modes().size();
    inside_.resize(slots_.size());
    measures_.resize(slots_.size() * modes);
    if (classifier_.orientationFixed()) {
      px_.resize(poses_.size()), py_.resize(poses_.size()), pz_.resize(poses_.size());
      for (std::size_t i = 0; i < poses_.size(); ++i) {
        px_[i] = poses_[i].position.x(), py_[i] = poses_[i].position.y(), pz_[i] = poses_[i].position.z();
      }
      classifier_.classify(PointBatch{px_.data(), py_.data(), pz_.data(), poses_.size()}, inside_.data(), measures_.data());
    } else {
      classifier_.classify(poses_.data(), poses_.size(), inside_.data(), measures_.data());
    }
    for (std::size_t i = 0; i < slots_.size(); ++i) {
      codes_[slots_[i]] = inside_[i] ? encoder_.encode(&measures_[i * modes]) : kCodeOutside;
    }
    evaluated_ += slots_.size();
    slots_.clear();
    poses_.clear();
  }

  const Grid& grid_;
  const BlockLayout& layout_;
  const PoseClassifier& classifier_;
  PatternEncoder encoder_;
  const int dims_;
  const int side_;
  std::array<std::size_t, kMaxGridDims> stride_{};
  std::vector<CellCode> codes_;
  std::vector<std::size_t> block_cell_offset_;
  GridCell origin_{};
  int low_[kMaxGridDims] = {}, high_[kMaxGridDims] = {};
  std::uint64_t evaluated_ = 0;
  std::vector<std::size_t> slots_;
  std::vector<Pose> poses_;
  std::vector<double> px_, py_, pz_;
  std::vector<std::uint8_t> inside_;
  std::vector<double> measures_;
};

// The stage's share of sampling the cells; the rest is the check of thin layers (the
// delta-like robot at 2 mm: 2.8 s and 1.8 s).
constexpr double kSamplingShare = 0.6;

// Progress from any thread, at most ten calls a second.
class ThrottledProgress {
 public:
  explicit ThrottledProgress(const std::function<void(double, std::uint64_t)>& report) : report_(report) {}
  void update(double fraction, std::uint64_t evaluated) {
    if (!report_) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    report_(fraction, evaluated);
  }

 private:
  const std::function<void(double, std::uint64_t)>& report_;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point last_{};
};

// Moves the blocks of a classified top cube into the code map: one code for a block
// whose cells all share it, else a page.
void storeBlocks(const TopNodeClassifier& top, const GridCell& first_block, int top_blocks, const BlockLayout& layout,
                 CodeMap* codes, std::mutex* pages_mutex) {
  const int dims = layout.dims(), cells = layout.cellsPerBlock();
  int offset[kMaxGridDims] = {};
  while (true) {
    GridCell block = first_block;
    bool in_lattice = true;
    int local[kMaxGridDims];
    for (int d = 0; d < dims; ++d) {
      block[d] += offset[d];
      in_lattice = in_lattice && block[d] < layout.blocks(d);
      local[d] = offset[d] * layout.side();
    }
    if (in_lattice) {
      const std::size_t base = top.localOffset(local);
      const CellCode first_code = top.code(base, 0);
      int c = 1;
      while (c < cells && top.code(base, c) == first_code) ++c;
      const std::uint64_t index = layout.blockIndex(block);
      if (c == cells) {
        codes->setUniform(index, first_code);
      } else {
        CellCode* page = nullptr;
        {
          const std::lock_guard<std::mutex> lock(*pages_mutex);
          page = codes->addPage(index);
        }
        for (c = 0; c < cells; ++c) page[c] = top.code(base, c);
      }
    }
    int d = dims - 1;
    while (d >= 0 && ++offset[d] == top_blocks) offset[d] = 0, --d;
    if (d < 0) return;
  }
}

// The wave front's workspace: the inside cells face-connected to the start; the others
// become kCodeDetached.
void keepConnected(WorkspaceCells& cells) {
  std::vector<std::uint8_t> inside_key(65536, 0);
  for (std::size_t code = 0; code < kMaxSignPatterns; ++code) inside_key[code] = 1;
  LabelLayer connected;
  const std::vector<Component> components = labelComponents(cells.layout, cells.codes, inside_key, cells.cuts, -1, &connected);
  const std::int32_t start_component = connected.label(cells.start_block, cells.start_cell);
  if (start_component == kNoLabel) {
    // The shell test's assumption failed at the start's own cell.
    throw std::runtime_error("the adaptive classification missed the start cell; use a smaller step");
  }
  cells.inside_cells = components[start_component].cells;
  for (std::uint64_t b = 0; b < cells.layout.blockCount(); ++b) {
    if (cells.codes.uniform(b)) {
      const std::int32_t label = connected.label(b, 0);
      if (label != kNoLabel && label != start_component) cells.codes.setUniform(b, kCodeDetached);
      continue;
    }
    CellCode* page = cells.codes.page(b);
    for (int c = 0; c < cells.layout.cellsPerBlock(); ++c) {
      const std::int32_t label = connected.label(b, c);
      if (label != kNoLabel && label != start_component) page[c] = kCodeDetached;
    }
  }
}

}  // namespace

int topNodeSide(const Grid& grid, const BlockLayout& layout) {
  const auto fits = [&](std::uint64_t side) {
    std::uint64_t cells = 1;
    for (int d = 0; d < grid.dims(); ++d) {
      cells *= side;
      if (static_cast<double>(side) * grid.step(d) > kTopNodeLength * (1 + 1e-9)) return false;
    }
    return cells <= kMaxTopNodeCells;
  };
  int side = layout.side();
  while (fits(2 * static_cast<std::uint64_t>(side))) side *= 2;  // 128 cells at 2 mm
  return side;
}

std::uint64_t startCell(const Grid& grid, const PoseClassifier& classifier, double* measures) {
  std::uint64_t start_cell = 0;
  if (!grid.cellOf(grid.spec().start, &start_cell)) throw InputError("grid: the start pose is outside the grid's box");
  const Pose start_centre = grid.pose(start_cell);
  std::string where;
  for (int d = 0; d < grid.dims(); ++d) {
    where += std::string(d ? " " : "") + outputVariableName(grid.variable(d)) + "=" +
             numberText(start_centre.value(grid.variable(d)));
  }
  if (!classifier.classify(start_centre, measures)) {
    throw InputError("grid: the start pose is outside the workspace (the centre of its cell, " + where +
                     ", cannot be assembled)");
  }
  const std::size_t modes = classifier.modes().size();
  if (std::none_of(measures, measures + modes, modeAdmissible)) {
    throw InputError("grid: the start pose is outside the workspace (at the centre of its cell, " + where +
                     ", every working mode breaks a limit of the robot: `mow eval` gives the margins)");
  }
  return start_cell;
}

WorkspaceCells classifyWorkspace(const Grid& grid, const PoseClassifier& classifier, const ClassificationOptions& options) {
  const int modes = static_cast<int>(classifier.modes().size());
  if (modes > kMaxAnalysedModes) {
    throw InputError("an analysis handles at most " + std::to_string(kMaxAnalysedModes) + " working modes, got " +
                     std::to_string(modes));
  }
  WorkspaceCells cells;
  cells.layout = BlockLayout(grid);
  const BlockLayout& layout = cells.layout;
  cells.codes = CodeMap(layout.blockCount(), layout.cellsPerBlock());
  std::vector<double> start_measures(modes);
  const std::uint64_t start = startCell(grid, classifier, start_measures.data());
  layout.locate(start, &cells.start_block, &cells.start_cell);

  // Top cubes handed out one at a time: their cost varies a hundredfold.
  const int top_side = topNodeSide(grid, layout);
  const int top_blocks = top_side / layout.side();
  GridCell tops{};
  std::uint64_t top_count = 1;
  for (int d = 0; d < grid.dims(); ++d) {
    tops[d] = (layout.blocks(d) + top_blocks - 1) / top_blocks;
    top_count *= static_cast<std::uint64_t>(tops[d]);
  }
  PatternInterner interner;
  std::atomic<std::uint64_t> next{0}, done{0}, evaluated{0};
  std::mutex pages_mutex;
  ThrottledProgress progress(options.progress);
  const int workers = resolveThreadCount(options.threads);
  parallelFor(workers, workers, [&](std::size_t, std::size_t) {
    TopNodeClassifier top(grid, layout, classifier, interner, options.margin, top_side);
    for (std::uint64_t t = next++; t < top_count; t = next++) {
      throwIfCancelled(options.cancelled);
      GridCell first{};
      std::uint64_t rest = t;
      for (int d = grid.dims() - 1; d >= 0; --d) {
        first[d] = static_cast<std::int64_t>(rest % tops[d]) * top_blocks;
        rest /= tops[d];
      }
      evaluated += top.run(first);
      storeBlocks(top, first, top_blocks, layout, &cells.codes, &pages_mutex);
      progress.update(kSamplingShare * static_cast<double>(++done) / top_count, evaluated);
    }
  }, 1);
  cells.evaluated = evaluated;
  cells.patterns = SignPatterns{modes, interner.take()};
  if (options.certificate != nullptr) {
    const std::uint64_t sampled = evaluated;
    cells.cuts = findThinLayers(grid, cells, *options.certificate, classifier, options.threads, options.cancelled,
                                [&](double fraction) {
                                  progress.update(kSamplingShare + (1.0 - kSamplingShare) * fraction, sampled);
                                });
    // The labelling reads a cut's blocks cell by cell.
    for (std::uint64_t b : cells.cuts.blocks) {
      if (!cells.codes.uniform(b)) continue;
      const CellCode code = cells.codes.uniformCode(b);
      CellCode* page = cells.codes.addPage(b);
      std::fill(page, page + layout.cellsPerBlock(), code);
    }
  }
  keepConnected(cells);
  return cells;
}

}  // namespace maximal_workspace
