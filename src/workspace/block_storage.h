#pragma once
// Storage of the block-structured workspace (internal to the engine): per block either one
// value for all its cells or a page of one value per cell. Pages live in a pool of large
// chunks, so millions of them cost no allocation each.

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "maximal_workspace/workspace/block_layout.h"

namespace maximal_workspace {

// Fixed-size pages of T, appended and then read; not thread-safe to append.
template <class T>
class PagePool {
 public:
  explicit PagePool(int page_size = 0) : page_size_(page_size) {}

  int pageSize() const { return page_size_; }
  std::uint32_t size() const { return count_; }
  T* page(std::uint32_t index) { return chunks_[index / kPagesPerChunk].get() + std::size_t(index % kPagesPerChunk) * page_size_; }
  const T* page(std::uint32_t index) const {
    return chunks_[index / kPagesPerChunk].get() + std::size_t(index % kPagesPerChunk) * page_size_;
  }
  // A new page, its values unset; returns its index.
  std::uint32_t add() {
    if (count_ % kPagesPerChunk == 0) chunks_.emplace_back(new T[std::size_t(kPagesPerChunk) * page_size_]);
    return count_++;
  }
  std::uint64_t bytes() const { return chunks_.size() * std::uint64_t(kPagesPerChunk) * page_size_ * sizeof(T); }

 private:
  static constexpr std::uint32_t kPagesPerChunk = 256;
  int page_size_ = 0;
  std::uint32_t count_ = 0;
  std::vector<std::unique_ptr<T[]>> chunks_;
};

// A cell's classification: an index into the analysis's sign patterns where the cell is
// assembled and connected to the start, else one of the markers below.
using CellCode = std::uint32_t;
constexpr CellCode kCodeOutside = 0xFFFFFFFFu;   // tested: some chain cannot be assembled
constexpr CellCode kCodeDetached = 0xFFFFFFFEu;  // assembled, but not connected to the start
constexpr CellCode kCodeVoid = 0xFFFFFFFDu;      // a block's padding beyond the box: never tested
constexpr CellCode kCodeUnevaluated = 0xFFFFFFFCu;  // scratch only, never stored
constexpr CellCode kCodeQueued = 0xFFFFFFFBu;       // scratch only: waiting in a batch
constexpr CellCode kCodeBlocked = 0xFFFFFFFAu;  // assembled, but every working mode breaks a robot limit
constexpr int kCodeMarkers = 6;
// A code map's block entry keeps 31 bits of a code.
constexpr std::size_t kMaxSignPatterns = 0x7FFFFFFAu;
inline bool codeInside(CellCode code) { return code < kCodeBlocked; }
// The markers a stored map may hold.
inline bool codeStored(CellCode code) { return code == kCodeBlocked || code >= kCodeVoid; }

// A value per code an analysis can hold: one per sign pattern and one per marker.
template <class T>
class CodeTable {
 public:
  CodeTable(std::size_t patterns, T value) : patterns_(patterns), values_(patterns + kCodeMarkers, value) {}
  T& operator[](CellCode code) { return values_[slot(code)]; }
  const T& operator[](CellCode code) const { return values_[slot(code)]; }

 private:
  std::size_t slot(CellCode code) const { return code >= kCodeBlocked ? patterns_ + (code - kCodeBlocked) : code; }
  std::size_t patterns_;
  std::vector<T> values_;
};

// The banded signs of det J_DKP of every working mode at a cell, two bits per mode (0 the
// singular band, 1 positive, 2 negative, 3 blocked: the mode breaks a robot limit there):
// at most 64 working modes.
using SignPattern = std::array<std::uint64_t, 2>;
constexpr int kMaxAnalysedModes = 64;
constexpr unsigned kPatternBlocked = 3;

inline unsigned patternBits(const SignPattern& pattern, int mode) {
  return static_cast<unsigned>(pattern[mode >> 5] >> (2 * (mode & 31)) & 3u);
}
inline int patternSign(const SignPattern& pattern, int mode) {
  const unsigned bits = patternBits(pattern, mode);
  return bits == 1 ? 1 : bits == 2 ? -1 : 0;
}

// The distinct sign patterns of an analysis, in code order. A workspace has few: codes
// index them, so a cell costs two bytes (rarely four) whatever the number of working modes.
struct SignPatterns {
  int modes = 0;
  std::vector<SignPattern> patterns;

  int sign(CellCode code, int mode) const { return patternSign(patterns[code], mode); }
  bool blocked(CellCode code, int mode) const { return patternBits(patterns[code], mode) == kPatternBlocked; }
};

// Codes of every cell of the box, block by block: per block one code, or a page of one a
// cell. Pages take two bytes a cell while the analysis has under 65,530 sign patterns
// (every 3-D analysis so far), four once it has more (say 64 working modes over an
// orientation set): the first page holding a wider code widens every page.
class CodeMap {
 public:
  // The codes of a block's page, whichever width the map has; `empty` for a block
  // without one.
  class Page {
   public:
    Page() = default;
    Page(const std::uint16_t* narrow, const CellCode* wide) : narrow_(narrow), wide_(wide) {}
    bool empty() const { return narrow_ == nullptr && wide_ == nullptr; }
    CellCode operator[](int cell) const { return wide_ != nullptr ? wide_[cell] : fromNarrow(narrow_[cell]); }

   private:
    const std::uint16_t* narrow_ = nullptr;
    const CellCode* wide_ = nullptr;
  };

  // Pattern codes below it, and the markers, fit a two-byte page.
  static constexpr CellCode kNarrowCodes = 0xFFFA;

  CodeMap() = default;
  CodeMap(std::uint64_t blocks, int cells_per_block)
      : entry_(blocks, kUniform | (kCodeVoid & ~kUniform)), narrow_(cells_per_block), wide_(cells_per_block) {}

  bool uniform(std::uint64_t block) const { return entry_[block] & kUniform; }
  CellCode uniformCode(std::uint64_t block) const {
    const CellCode code = entry_[block] & ~kUniform;
    return code >= (kCodeBlocked & ~kUniform) ? code | kUniform : code;
  }
  Page page(std::uint64_t block) const { return pageAt(entry_[block]); }
  CellCode code(std::uint64_t block, int cell) const { return uniform(block) ? uniformCode(block) : page(block)[cell]; }
  // Whether some cell of the block has `code`.
  bool holds(std::uint64_t block, CellCode code) const;

  void setUniform(std::uint64_t block, CellCode code) { entry_[block] = kUniform | (code & ~kUniform); }
  // Gives the block a page of `codes` (one a cell; not thread-safe: callers serialise).
  void addPage(std::uint64_t block, const CellCode* codes);
  // Sets a marker at one cell of a block that has a page.
  void setMarker(std::uint64_t block, int cell, CellCode marker);
  bool widePages() const { return wide_pages_; }
  std::uint64_t blockCount() const { return entry_.size(); }
  std::uint32_t pageCount() const { return wide_pages_ ? wide_.size() : narrow_.size(); }
  std::uint64_t bytes() const { return entry_.size() * sizeof(std::uint32_t) + narrow_.bytes() + wide_.bytes(); }
  // Stores or restores the map through a state archive (io/state_archive.h); reading
  // checks the block count against this map's and every code against the `known` ones.
  template <class Archive>
  void describe(Archive& archive, std::size_t known);

 private:
  static constexpr std::uint32_t kUniform = 0x80000000u;
  // Narrow values from kNarrowCodes up are the markers, in the same order.
  static CellCode fromNarrow(std::uint16_t value) { return value >= kNarrowCodes ? value | 0xFFFF0000u : value; }
  static bool fitsNarrow(CellCode code) { return code < kNarrowCodes || code >= kCodeBlocked; }
  void widen();
  Page pageAt(std::uint32_t index) const {
    return wide_pages_ ? Page(nullptr, wide_.page(index)) : Page(narrow_.page(index), nullptr);
  }

  std::vector<std::uint32_t> entry_;  // kUniform | a code's low 31 bits, or a page index
  bool wide_pages_ = false;
  PagePool<std::uint16_t> narrow_;
  PagePool<CellCode> wide_;
};

template <class Archive>
void CodeMap::describe(Archive& archive, std::size_t known) {
  const std::size_t blocks = entry_.size();
  archive.values(entry_);
  archive.check(entry_.size() == blocks, "the block table does not fit the grid");
  archive.value(wide_pages_);
  std::uint64_t pages = pageCount();
  archive.count(pages, narrow_.pageSize() * (wide_pages_ ? sizeof(CellCode) : sizeof(std::uint16_t)));
  for (std::uint32_t p = 0; p < pages; ++p) {
    if (Archive::kReading) wide_pages_ ? wide_.add() : narrow_.add();
    if (wide_pages_) {
      archive.array(wide_.page(p), wide_.pageSize());
    } else {
      archive.array(narrow_.page(p), narrow_.pageSize());
    }
  }
  if (!Archive::kReading) return;
  const auto valid = [known](CellCode code) { return code < known || codeStored(code); };
  for (std::uint64_t b = 0; b < blocks; ++b) {
    archive.check(uniform(b) ? valid(uniformCode(b)) : entry_[b] < pages, "a block entry is out of range");
  }
  for (std::uint32_t p = 0; p < pages; ++p) {
    const Page page = pageAt(p);
    for (int c = 0; c < narrow_.pageSize(); ++c) archive.check(valid(page[c]), "a cell code is out of range");
  }
}

// The faces of a block (bit 2d for direction -1 along d, 2d + 1 for +1) whose neighbouring
// block `may_meet(neighbour)` says may hold what a scan of the block's side cells looks for.
// A face without a neighbour is skipped, so a scan of uniform blocks' sides touches only
// blocks near the surfaces; a periodic variable's faces are always kept (the wrap may pair
// one face with two blocks).
template <class MayMeet>
unsigned facesToScan(const BlockLayout& layout, std::uint64_t block, const MayMeet& may_meet) {
  unsigned faces = 0;
  for (int d = 0; d < layout.dims(); ++d) {
    for (int direction : {-1, 1}) {
      const unsigned bit = 1u << (2 * d + (direction > 0));
      if (layout.periodic(d)) {
        faces |= bit;
        continue;
      }
      const int corner = (direction > 0 ? layout.side() - 1 : 0) << ((layout.dims() - 1 - d) * layout.sideBits());
      std::uint64_t other_block = 0;
      int other_cell = 0;
      if (layout.neighbour(block, corner, d, direction, &other_block, &other_cell) && may_meet(other_block)) faces |= bit;
    }
  }
  return faces;
}

// facesToScan where a neighbouring block of one code may meet only if `meets(code)`.
template <class Meets>
unsigned facesMeetingCodes(const BlockLayout& layout, const CodeMap& codes, std::uint64_t block, const Meets& meets) {
  return facesToScan(layout, block,
                     [&](std::uint64_t other) { return !codes.uniform(other) || meets(codes.uniformCode(other)); });
}

// Whether a block's cell lies on one of `faces` (facesToScan's bits).
inline bool onFaces(const BlockLayout& layout, int cell, unsigned faces) {
  const int last = layout.side() - 1;
  for (int d = 0; d < layout.dims(); ++d) {
    const int at = layout.cellCoord(cell, d);
    if ((at == 0 && (faces >> (2 * d) & 1)) || (at == last && (faces >> (2 * d + 1) & 1))) return true;
  }
  return false;
}

constexpr std::int32_t kNoLabel = -1;

// A component label per cell: one per block where the block's key is uniform; where it
// is not, a page of the cells' local components and the label of each local component.
// A page takes a byte a cell when its block has under 255 local components (nearly
// always), two bytes otherwise.
class LabelLayer {
 public:
  static constexpr std::uint16_t kNoLocal = 0xFFFF;  // a cell of no component

  // The local components of a block's cells, whichever width the page has.
  struct LocalPage {
    const std::uint8_t* narrow;
    const std::uint16_t* wide;
    std::uint16_t operator[](int cell) const {
      return narrow == nullptr ? wide[cell] : narrow[cell] == kNarrowNone ? kNoLocal : narrow[cell];
    }
  };

  LabelLayer() = default;
  LabelLayer(std::uint64_t blocks, int cells_per_block)
      : block_label_(blocks, kNoLabel), narrow_(cells_per_block), wide_(cells_per_block) {}

  bool uniform(std::uint64_t block) const { return block_label_[block] > kPageMarker; }
  std::int32_t label(std::uint64_t block, int cell) const {
    const std::int32_t entry = block_label_[block];
    if (entry > kPageMarker) return entry;
    const std::uint16_t local = localPage(block)[cell];
    return local == kNoLocal ? kNoLabel : localLabels(block)[local];
  }
  // A block that is not uniform: its cells' local components, and their labels.
  LocalPage localPage(std::uint64_t block) const {
    const std::uint32_t slot = slot_[pageOf(block)];
    return slot & 1 ? LocalPage{nullptr, wide_.page(slot >> 1)} : LocalPage{narrow_.page(slot >> 1), nullptr};
  }
  const std::int32_t* localLabels(std::uint64_t block) const { return labels_.data() + first_[pageOf(block)]; }
  std::int32_t* localLabels(std::uint64_t block) { return labels_.data() + first_[pageOf(block)]; }

  void setUniform(std::uint64_t block, std::int32_t label) { block_label_[block] = label; }
  // Gives the block a page: the local component of each cell (kNoLocal for none), and
  // `components` labels, each kNoLabel.
  void addPage(std::uint64_t block, const std::uint16_t* local, std::uint32_t components);
  // Adds `offset` to every label (components numbered per layer become global ids).
  void shift(std::int32_t offset);
  std::uint32_t pageCount() const { return narrow_.size() + wide_.size(); }
  std::uint64_t bytes() const {
    return block_label_.size() * sizeof(std::int32_t) + narrow_.bytes() + wide_.bytes() +
           (slot_.size() + first_.size()) * sizeof(std::uint32_t) + labels_.size() * sizeof(std::int32_t);
  }

 private:
  static constexpr std::uint8_t kNarrowNone = 0xFF;
  static constexpr std::int32_t kPageMarker = -2;  // entries <= it: page kPageMarker - entry
  std::uint32_t pageOf(std::uint64_t block) const { return static_cast<std::uint32_t>(kPageMarker - block_label_[block]); }
  std::vector<std::int32_t> block_label_;
  PagePool<std::uint8_t> narrow_;
  PagePool<std::uint16_t> wide_;
  std::vector<std::uint32_t> slot_;   // per page: 2 i for narrow page i, 2 i + 1 for wide page i
  std::vector<std::uint32_t> first_;  // per page: its local components' first entry in labels_
  std::vector<std::int32_t> labels_;
};

// The classification of every cell of the box, and where the workspace is.
// A face between two assembled cells across which the straight segment between their
// centres leaves the workspace, or changes some working mode's sign (workspace/
// thin_layers.h): a layer thinner than the step that the cell centres do not see.
struct FaceCut {
  std::uint64_t face = 0;   // grid index * kMaxGridDims + d: the cell's face towards +d
  bool gap = false;         // a pose on the segment is not assembled
  std::uint64_t modes = 0;  // bit m: working mode m's sign changes on the segment
};

// Components do not join across cuts: the workspace's across gaps, a working mode's regions
// across gaps and that mode's sign changes.
struct FaceCuts {
  std::vector<FaceCut> faces;         // sorted by face
  std::vector<std::uint64_t> blocks;  // sorted: the blocks holding a cell of a cut face

  // `mode` -1: the workspace's components.
  bool cut(std::uint64_t grid_index, int d, int mode) const {
    const std::uint64_t face = grid_index * kMaxGridDims + static_cast<std::uint64_t>(d);
    const auto at = std::lower_bound(faces.begin(), faces.end(), face,
                                     [](const FaceCut& cut, std::uint64_t key) { return cut.face < key; });
    return at != faces.end() && at->face == face && (at->gap || (mode >= 0 && (at->modes >> mode & 1u)));
  }
  bool touches(std::uint64_t block) const { return std::binary_search(blocks.begin(), blocks.end(), block); }
  // Calls visit(i, d) for each face cut in `mode` (as cut()) towards +d of the cells of
  // grid indices first + i, i < count: one search for a row of cells.
  template <class Visit>
  void forEachCut(std::uint64_t first, std::uint64_t count, int mode, const Visit& visit) const {
    const std::uint64_t begin = first * kMaxGridDims, end = (first + count) * kMaxGridDims;
    auto at = std::lower_bound(faces.begin(), faces.end(), begin,
                               [](const FaceCut& cut, std::uint64_t key) { return cut.face < key; });
    for (; at != faces.end() && at->face < end; ++at) {
      if (at->gap || (mode >= 0 && (at->modes >> mode & 1u))) {
        visit(at->face / kMaxGridDims - first, static_cast<int>(at->face % kMaxGridDims));
      }
    }
  }
};

// What the classification proved of a cell over its whole box: `assembly`, that every pose
// of it is in the workspace as its centre is (assembled, with some working mode keeping
// every limit) or that none is (none assembled; or, for kCodeBlocked, every mode breaking
// a limit everywhere); `modes` (bit m), that working mode m keeps its part of the code over
// it: every limit and one sign beyond the margin, or a limit broken everywhere (every bit
// for a cell proven outside). The others took their centre's classification.
// `near_boundary`: assembled, proven over the cell alone by the mean-value form
// (MeasureCertificate::assemblyOfCell), so the workspace's boundary may pass within a
// cell of it; the thin layers' check treats its faces as those of a cell not proven.
struct CellProof {
  bool assembly = false;
  std::uint64_t modes = 0;
  bool near_boundary = false;
};

// The proofs of every cell: per block all proven, none, or a page: a cell's mode set
// itself up to 8 working modes (a byte), beyond an index into a palette of the distinct
// mode sets (two bytes; a workspace has few, in runs); and a bit a cell for near_boundary
// and, on pages where some cells are assembled and others not, one for assembly. (A
// one-byte palette of whole proofs overflowed at 2 mm on the delta-like robot, whose 8
// modes' 255 mode sets nearly all occur: which one lost its modes then depended on the
// threads' order.) The classifier's scratch packs them in 1 + modes / 8 bytes a cell
// (pack, unpack); storing a page turns those into pages.
class ProofMap {
 public:
  ProofMap() = default;
  ProofMap(std::uint64_t blocks, int cells_per_block, int modes)
      : entry_(blocks, kNone), modes_(modes), width_(1 + (modes + 7) / 8), index_bytes_(modes <= 8 ? 1 : 2),
        pages_(cells_per_block * index_bytes_), near_pages_((cells_per_block + 63) / 64),
        assembled_pages_((cells_per_block + 63) / 64), palette_{0} {}

  int width() const { return width_; }
  std::uint64_t allModes() const { return modes_ >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << modes_) - 1; }
  CellProof proof(std::uint64_t block, int cell) const {
    const std::uint32_t entry = entry_[block];
    if (entry == kAll) return {true, allModes()};
    if (entry == kNone) return {};
    const std::uint8_t* page = pages_.page(entry);
    CellProof proof;
    proof.modes = index_bytes_ == 1 ? page[cell] : palette_[page[2 * cell] | page[2 * cell + 1] << 8];
    const std::uint32_t assembled = assembled_entry_[entry];
    proof.assembly =
        assembled == kAll || (assembled != kNone && (assembled_pages_.page(assembled)[cell >> 6] >> (cell & 63) & 1u) != 0);
    proof.near_boundary = (near_pages_.page(entry)[cell >> 6] >> (cell & 63) & 1u) != 0;
    return proof;
  }
  bool allProven(std::uint64_t block) const { return entry_[block] == kAll; }
  bool noneProven(std::uint64_t block) const { return entry_[block] == kNone; }
  void setAll(std::uint64_t block) { entry_[block] = kAll; }
  // Gives the block a page of `cells` proofs packed as pack() writes them (not thread-safe:
  // callers serialise).
  void addPage(std::uint64_t block, const std::uint8_t* packed);
  void pack(const CellProof& proof, std::uint8_t* bytes) const {
    bytes[0] = static_cast<std::uint8_t>(proof.assembly | proof.near_boundary << 1);
    for (int i = 1; i < width_; ++i) bytes[i] = static_cast<std::uint8_t>(proof.modes >> (8 * (i - 1)));
  }
  CellProof unpack(const std::uint8_t* bytes) const {
    CellProof proof{(bytes[0] & 1) != 0, 0, (bytes[0] & 2) != 0};
    for (int i = 1; i < width_; ++i) proof.modes |= std::uint64_t{bytes[i]} << (8 * (i - 1));
    return proof;
  }
  std::uint64_t bytes() const {
    return (entry_.size() + assembled_entry_.size()) * sizeof(std::uint32_t) + pages_.bytes() + near_pages_.bytes() +
           assembled_pages_.bytes();
  }

 private:
  // The palette index of a mode set (beyond 8 working modes); past 65536 distinct ones,
  // that of none (a proof dropped leaves the rest true).
  std::uint32_t index(std::uint64_t modes);

  static constexpr std::uint32_t kAll = 0xFFFFFFFFu, kNone = 0xFFFFFFFEu;
  std::vector<std::uint32_t> entry_;  // kAll, kNone or a page index
  int modes_ = 0, width_ = 1, index_bytes_ = 1;
  PagePool<std::uint8_t> pages_;
  PagePool<std::uint64_t> near_pages_;  // bits, added with pages_, one for one
  // Per page of pages_: kAll or kNone where its cells are all assembled or none (most
  // pages), else the index of its bits in assembled_pages_.
  std::vector<std::uint32_t> assembled_entry_;
  PagePool<std::uint64_t> assembled_pages_;
  std::vector<std::uint64_t> palette_;                     // mode sets, beyond 8 working modes
  std::unordered_map<std::uint64_t, std::uint32_t> palette_index_;
};

struct WorkspaceCells {
  BlockLayout layout;
  CodeMap codes;
  SignPatterns patterns;
  std::uint64_t evaluated = 0;     // poses classified
  std::uint64_t proofs = 0;        // boxes the enclosures were asked to decide
  ProofMap proven;  // until the summary has the certified volumes
  std::uint64_t inside_cells = 0;  // cells connected to the start: the workspace's voxels
  std::uint64_t start_block = 0;
  int start_cell = 0;
  FaceCuts cuts;

  int sign(std::uint64_t block, int cell, int mode) const {
    const CellCode code = codes.code(block, cell);
    return codeInside(code) ? patterns.sign(code, mode) : 0;
  }
};

}  // namespace maximal_workspace
