#include "workspace/thin_layers.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "workspace/parallel.h"

namespace maximal_workspace {

namespace {

constexpr std::uint64_t kBlocksPerChunk = 256;
constexpr std::uint32_t kAllChains = ~0u;

// The piece [from, to] of the segment (fractions of `length`).
bool pieceLeaves(const Grid& grid, const MeasureCertificate& certificate, const Pose& start, int d, double length,
                 std::uint32_t chains, double from, double to) {
  const PoseBox box = grid.segmentBox(start, d, 0.5 * (from + to) * length, 0.5 * (to - from) * std::abs(length));
  std::uint32_t open = 0;
  const BoxAssembly assembly = certificate.assemblyOf(box, chains, &open);
  if (assembly != BoxAssembly::Undecided) return assembly == BoxAssembly::Outside;
  if (to - from <= kGapResolution) return false;
  const double middle = 0.5 * (from + to);
  return pieceLeaves(grid, certificate, start, d, length, open, from, middle) ||
         pieceLeaves(grid, certificate, start, d, length, open, middle, to);
}

// A face whose segment stays assembled, waiting for its centre's signs.
struct FaceProbe {
  std::uint64_t face;
  CellCode lower, upper;  // the two cells' codes
  Pose centre;
};

class BlockLayers {
 public:
  BlockLayers(const Grid& grid, const WorkspaceCells& cells, const MeasureCertificate& certificate,
              const PoseClassifier& classifier)
      : grid_(grid), layout_(cells.layout), cells_(cells), certificate_(certificate), classifier_(classifier),
        open_(layout_.cellsPerBlock()), near_(layout_.cellsPerBlock()) {}

  // Proves what it can of block b's cells, then checks the faces of those it cannot, and
  // of those near a chain's reach limit whose working modes' signs are not all proven.
  void run(std::uint64_t b, FaceCuts& found) {
    // The classification's proofs: a cell proven assembled with every working mode's sign
    // over its box has no face to check from this side.
    if (cells_.proven.allProven(b)) return;
    const int count = layout_.cellsPerBlock();
    bool any_open = false, any_unsigned = false;
    for (int c = 0; c < count; ++c) {
      // A cell proven assembled over its box has no gap to check from this side.
      const CellProof proof = cells_.proven.proof(b, c);
      const bool inside = codeInside(cells_.codes.code(b, c));
      const bool open = inside && (!proof.assembly || proof.near_boundary);
      open_[c] = open ? kAllChains : 0;
      near_[c] = inside && proof.modes != cells_.proven.allModes();  // until markNearReach
      any_open = any_open || open;
      any_unsigned = any_unsigned || near_[c];
    }
    const int lows[kMaxGridDims] = {};
    if (any_unsigned) markNearReach(b, lows, layout_.side());
    if (!any_open && std::find(near_.begin(), near_.end(), 1) == near_.end()) return;
    if (any_open) prove(b, lows, layout_.side(), kAllChains);
    for (int c = 0; c < count; ++c) {
      if (!codeInside(cells_.codes.code(b, c))) continue;
      if (open_[c] != 0 || near_[c]) checkFaces(b, c, found);
    }
    checkSigns(b, found);
  }

 private:
  // The box of the cells of block b whose in-block coordinates are low[d] .. low[d] + side - 1.
  PoseBox boxOf(std::uint64_t b, const int* low, int side) const {
    const GridCell first = layout_.cellCoords(b, layout_.cellIndex(low));
    GridCell last = first;
    for (int d = 0; d < grid_.dims(); ++d) last[d] += side - 1;
    return grid_.cellsBox(first, last);
  }

  // Sets open_ of the cells in the range: the chains not proven to assemble over the cell.
  // Only `chains` may not assemble over the range (the others do over a larger box).
  void prove(std::uint64_t b, const int* low, int side, std::uint32_t chains) {
    if (!anyOpen(low, side)) return;
    std::uint32_t open = 0;
    const BoxAssembly assembly = certificate_.assemblyOf(boxOf(b, low, side), chains, &open);
    if (assembly == BoxAssembly::Outside) return;
    if (side == 1) {
      open_[layout_.cellIndex(low)] = open;
      return;
    }
    if (assembly == BoxAssembly::Inside) {
      forRange(low, side, [&](int c) { open_[c] = 0; });
      return;
    }
    forHalves(low, side, [&](const int* sub, int half) { prove(b, sub, half, open); });
  }

  // Keeps near_ (set on the cells inside whose working modes' signs are not all proven)
  // only on the cells of the range where some chain may come near its reach limit
  // (MeasureCertificate::chainsNearReach): where sign layers come. Defined by the
  // enclosures over the cell alone, not by whether the classification proved the cell
  // assembled, so that tighter enclosures do not narrow the band checked. Only the
  // chains near over the range are enclosed over its halves.
  void markNearReach(std::uint64_t b, const int* low, int side, std::uint32_t chains = kAllChains) {
    if (!anyNear(low, side)) return;
    const std::uint32_t near = certificate_.chainsNearReach(boxOf(b, low, side), MeasureCertificate::kNearReachSpreads, chains);
    if (near == 0) {
      setNear(low, side, 0);
      return;
    }
    if (side == 1) return;
    forHalves(low, side, [&](const int* sub, int half) { markNearReach(b, sub, half, near); });
  }

  bool anyNear(const int* low, int side) const {
    bool any = false;
    forRange(low, side, [&](int c) { any = any || near_[c]; });
    return any;
  }
  void setNear(const int* low, int side, std::uint8_t value) {
    forRange(low, side, [&](int c) { near_[c] = value; });
  }
  // Whether a cell of the range is still open (not proven assembled over its box).
  bool anyOpen(const int* low, int side) const {
    bool any = false;
    forRange(low, side, [&](int c) { any = any || open_[c] != 0; });
    return any;
  }

  // Calls visit(cell) for each cell of the block whose in-block coordinates are low[d] ..
  // low[d] + side - 1, the last coordinate fastest.
  template <class Visit>
  void forRange(const int* low, int side, const Visit& visit) const {
    const int dims = layout_.dims();
    int at[kMaxGridDims];
    std::copy(low, low + dims, at);
    for (int d = 0; d >= 0;) {
      visit(layout_.cellIndex(at));
      for (d = dims - 1; d >= 0 && ++at[d] == low[d] + side; --d) at[d] = low[d];
    }
  }
  // Calls visit(sub, half) for each of the 2^dims half-size ranges of the range.
  template <class Visit>
  void forHalves(const int* low, int side, const Visit& visit) const {
    const int half = side / 2;
    for (int corner = 0; corner < (1 << layout_.dims()); ++corner) {
      int sub[kMaxGridDims];
      for (int d = 0; d < layout_.dims(); ++d) sub[d] = low[d] + ((corner >> d) & 1) * half;
      visit(sub, half);
    }
  }

  // Faces towards both neighbours along every variable. A face between two unproven cells
  // of the block is checked once, from the cell below it; across blocks it may be checked
  // from both sides (findThinLayers merges the two).
  void checkFaces(std::uint64_t b, int c, FaceCuts& found) {
    const std::uint64_t index = layout_.gridIndex(b, c);
    for (int d = 0; d < layout_.dims(); ++d) {
      for (int direction : {-1, 1}) {
        std::uint64_t nb = 0;
        int nc = 0;
        if (!layout_.neighbour(b, c, d, direction, &nb, &nc) || !codeInside(cells_.codes.code(nb, nc))) continue;
        // Both checked: the face is checked once, from the cell below it.
        if (direction < 0 && nb == b && (open_[nc] != 0 || near_[nc])) continue;
        // A chain that assembles over both cells' boxes does so on the segment.
        std::uint32_t chains = open_[c] | (nb == b ? open_[nc] : openChains(nb, nc));
        // Both centres assemble: along a translation no gap lies between them for a chain
        // whose discriminant is concave (the delta-like robot's four sliders: 3.1 M
        // enclosures at 3 mm instead of 10.1 M).
        if (!isRotational(grid_.variable(d))) chains &= ~certificate_.chainsAssembledAlongTranslations();
        const Pose centre = grid_.pose(index);
        const std::uint64_t lower = direction > 0 ? index : layout_.gridIndex(nb, nc);
        const std::uint64_t face = lower * kMaxGridDims + static_cast<std::uint64_t>(d);
        if (chains != 0 && segmentLeavesWorkspace(grid_, certificate_, centre, d, direction * grid_.step(d), chains)) {
          addCut(FaceCut{face, true, 0}, b, nb, found);
          continue;
        }
        FaceProbe probe{face, cells_.codes.code(b, c), cells_.codes.code(nb, nc), centre};
        grid_.move(&probe.centre, d, 0.5 * direction * grid_.step(d));
        if (direction < 0) std::swap(probe.lower, probe.upper);
        probes_.push_back(probe);
        probe_blocks_.push_back(nb);
      }
    }
  }

  static void addCut(const FaceCut& cut, std::uint64_t b, std::uint64_t nb, FaceCuts& found) {
    found.faces.push_back(cut);
    found.blocks.push_back(b);
    found.blocks.push_back(nb);
  }

  // The working modes' signs at the centres of the faces probed, in one batch.
  void checkSigns(std::uint64_t b, FaceCuts& found) {
    const std::size_t count = probes_.size(), modes = classifier_.modes().size();
    if (count == 0) return;
    poses_.resize(count);
    for (std::size_t i = 0; i < count; ++i) poses_[i] = probes_[i].centre;
    inside_.resize(count);
    measures_.resize(count * modes);
    classifier_.classify(poses_.data(), count, inside_.data(), measures_.data());
    for (std::size_t i = 0; i < count; ++i) {
      const FaceProbe& probe = probes_[i];
      FaceCut cut{probe.face, inside_[i] == 0, 0};
      for (std::size_t m = 0; m < modes && !cut.gap; ++m) {
        const int sign = cells_.patterns.sign(probe.lower, static_cast<int>(m));
        if (sign != 0 && sign == cells_.patterns.sign(probe.upper, static_cast<int>(m)) &&
            bandedSign(measures_[i * modes + m], 0.0) != sign) {
          cut.modes |= std::uint64_t{1} << m;
        }
      }
      if (cut.gap || cut.modes != 0) addCut(cut, b, probe_blocks_[i], found);
    }
    probes_.clear();
    probe_blocks_.clear();
  }

  // The chains not proven to assemble over a cell of another block.
  std::uint32_t openChains(std::uint64_t b, int c) const {
    const CellProof proof = cells_.proven.proof(b, c);
    if (proof.assembly && !proof.near_boundary) return 0;
    int at[kMaxGridDims];
    for (int d = 0; d < layout_.dims(); ++d) at[d] = layout_.cellCoord(c, d);
    std::uint32_t open = 0;
    certificate_.assemblyOf(boxOf(b, at, 1), kAllChains, &open);
    return open;
  }

  const Grid& grid_;
  const BlockLayout& layout_;
  const WorkspaceCells& cells_;
  const MeasureCertificate& certificate_;
  const PoseClassifier& classifier_;
  std::vector<std::uint32_t> open_;  // per cell of the block in hand: chains not proven to assemble
  std::vector<std::uint8_t> near_;   // per cell of the block in hand: some chain near its reach
  std::vector<FaceProbe> probes_;
  std::vector<std::uint64_t> probe_blocks_;  // the block of each probe's other cell
  // Scratch of checkSigns, kept from block to block.
  std::vector<Pose> poses_;
  std::vector<std::uint8_t> inside_;
  std::vector<double> measures_;
};

}  // namespace

bool segmentLeavesWorkspace(const Grid& grid, const MeasureCertificate& certificate, const Pose& start, int d,
                            double length, std::uint32_t chains) {
  return pieceLeaves(grid, certificate, start, d, length, chains, 0.0, 1.0);
}

FaceCuts findThinLayers(const Grid& grid, const WorkspaceCells& cells, const MeasureCertificate& certificate,
                        const PoseClassifier& classifier, int threads, const CancelCheck& cancelled,
                        const std::function<void(double)>& progress) {
  FaceCuts result;
  std::mutex mutex;
  // Chunks go to threads as they come free: the faces to check lie near the workspace's
  // boundary, in some chunks only (delta-like robot at 2 mm, halves of the blocks: 1.69
  // and 2.03 s).
  const std::uint64_t block_count = cells.layout.blockCount();
  const std::size_t chunks = static_cast<std::size_t>((block_count + kBlocksPerChunk - 1) / kBlocksPerChunk);
  ItemProgress chunks_done(progress, chunks);
  parallelForEach(chunks, threads, [&](std::size_t chunk, std::size_t) {
    throwIfCancelled(cancelled);
    BlockLayers layers(grid, cells, certificate, classifier);
    FaceCuts found;
    const std::uint64_t end = std::min(block_count, (chunk + 1) * kBlocksPerChunk);
    for (std::uint64_t b = chunk * kBlocksPerChunk; b < end; ++b) layers.run(b, found);
    {
      const std::lock_guard<std::mutex> lock(mutex);
      result.faces.insert(result.faces.end(), found.faces.begin(), found.faces.end());
      result.blocks.insert(result.blocks.end(), found.blocks.begin(), found.blocks.end());
    }
    chunks_done.finished();
  });
  // A face seen from both sides is one cut, with what either side found.
  std::vector<FaceCut>& faces = result.faces;
  std::sort(faces.begin(), faces.end(), [](const FaceCut& a, const FaceCut& b) { return a.face < b.face; });
  std::size_t kept = 0;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    if (kept > 0 && faces[kept - 1].face == faces[i].face) {
      faces[kept - 1].gap = faces[kept - 1].gap || faces[i].gap;
      faces[kept - 1].modes |= faces[i].modes;
    } else {
      faces[kept++] = faces[i];
    }
  }
  faces.resize(kept);
  std::vector<std::uint64_t>& blocks = result.blocks;
  std::sort(blocks.begin(), blocks.end());
  blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
  return result;
}

}  // namespace maximal_workspace
