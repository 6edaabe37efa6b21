#include "workspace/classification.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <optional>
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

// Whether two cells' coordinates are the same: a loop, where std::equal calls memcmp
// (2 % of a 2 mm run's samples, for a few ints at a time).
inline bool sameCell(const int* a, const int* b, int dims) {
  for (int d = 0; d < dims; ++d) {
    if (a[d] != b[d]) return false;
  }
  return true;
}

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

// What a sampled measure may differ from the exact one by, away from IKP singularities
// (docs/kinematics.md, "How exact the sign is").
constexpr double kSignSlack = 1e-12;

// Cubes the workspace's boundary may cross split down to this many cells a side. Down to
// single cells: an `assemblyOf` costs about two samples, and a cell it proves in or out
// leaves the certified band (delta-like robot at 2 mm: workspace band 4.66 -> 2.82 %).
constexpr int kSmallestOutsideProof = 1;
// Below this many cells a side, sampling a cube costs less than its certificate.
constexpr int kSmallestCertifiedSide = 4;
// An assembled box whose certificate bounds no variation is split as one the boundary may
// cross where a chain's discriminant over it is within this many of its spreads of zero
// (off the factorised path): on the 5R at 5 mm, 2 took the poses from 17,616 (half a
// spread, the thin layers' band) to 13,904 and its maximal band from 40.0 to 15.4 %; 4
// changed nothing more, nor did 2 on the delta-like robot or the long-crank hexapod.
constexpr double kSplitNearReachSpreads = 2.0;

// What the classification of top cubes did.
struct ClassificationWork {
  std::uint64_t evaluated = 0;     // cell centres classified
  std::uint64_t proofs = 0;        // boxes given to the enclosures
};

// The adaptive classification of one top cube of side^dims cells, held in a scratch
// array; local coordinates from the cube's first corner, the last variable fastest.
class TopNodeClassifier {
 public:
  TopNodeClassifier(const Grid& grid, const BlockLayout& layout, const PoseClassifier& classifier,
                    const MeasureCertificate& certificate, PatternInterner& interner, double threshold, int side)
      : grid_(grid), layout_(layout), classifier_(classifier), certificate_(certificate),
        encoder_(interner, int(classifier.modes().size()), threshold),
        band_(std::max(threshold, kMeasureTolerance)), dims_(grid.dims()), side_(side),
        proofs_map_(0, 0, static_cast<int>(classifier.modes().size())), proof_width_(proofs_map_.width()) {
    std::size_t cells = 1;
    for (int d = dims_ - 1; d >= 0; --d) {
      stride_[d] = cells;
      cells *= static_cast<std::size_t>(side);
    }
    codes_.resize(cells);
    proven_.resize(cells * proof_width_);
    std::size_t blocks = 1;
    for (int d = 0; d < dims_; ++d) blocks *= static_cast<std::size_t>(side / layout.side());
    whole_blocks_.resize(blocks);
    // Where each cell of a block lies in the scratch cube, from the block's first cell.
    for (int c = 0; c < layout.cellsPerBlock(); ++c) {
      std::size_t offset = 0;
      for (int d = 0; d < dims_; ++d) offset += layout.cellCoord(c, d) * stride_[d];
      block_cell_offset_.push_back(offset);
    }
    cell_measures_.resize(classifier.modes().size());
  }

  // Classifies the top cube whose first block has block coordinates `first_block`;
  // returns what it did.
  ClassificationWork run(const GridCell& first_block) {
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
    std::fill(proven_.begin(), proven_.end(), 0);
    std::fill(whole_blocks_.begin(), whole_blocks_.end(), kNotWhole);
    evaluated_ = proofs_ = 0;
    const int origin[kMaxGridDims] = {};
    refine(origin, side_);
    return {evaluated_, proofs_};
  }
  // Whether a proof filled the block at `offset` (block coordinates in the top cube) whole,
  // and with which code.
  bool wholeBlock(const int* offset, CellCode* code) const {
    std::size_t index = 0;
    for (int d = 0; d < dims_; ++d) index = index * static_cast<std::size_t>(side_ / layout_.side()) + offset[d];
    if (whole_blocks_[index] == kNotWhole) return false;
    *code = whole_blocks_[index];
    return true;
  }
  // The code at a block's cell, the block's first cell at local offset `base`, and what
  // the proofs say of it (ProofMap::pack's bytes).
  CellCode code(std::size_t base, int cell) const { return codes_[base + block_cell_offset_[cell]]; }
  const std::uint8_t* proof(std::size_t base, int cell) const {
    return &proven_[(base + block_cell_offset_[cell]) * proof_width_];
  }
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

  // Decides the cube [origin, origin + side) (local): by proof over its box where the
  // enclosures allow, else in 2^dims half-size cubes, down to a block (a leaf). Only the
  // chains of `chains` may fail to assemble somewhere in it (the others assemble over its
  // parent); the working modes of `known` are proven over it (over its parent), so its
  // certificate is made for the others.
  void refine(const int* origin, int side, std::uint32_t chains = ~0u, std::uint64_t known = 0) {
    int first[kMaxGridDims], last[kMaxGridDims];  // the part of the cube in the box
    for (int d = 0; d < dims_; ++d) {
      first[d] = std::max(origin[d], low_[d]);
      last[d] = std::min(origin[d] + side, high_[d]) - 1;
    }
    if (!boxHolds(first, last)) return;
    BoxCertificate proof;
    if (fillByProof(first, last, proof, &chains, &known)) return;
    if (side <= layout_.side()) {
      classifyLeaf(first, last, side, proof, chains, known);
      return;
    }
    const int half = side / 2;
    for (int child = 0; child < (1 << dims_); ++child) {
      int child_origin[kMaxGridDims];
      for (int d = 0; d < dims_; ++d) child_origin[d] = origin[d] + (child >> (dims_ - 1 - d) & 1) * half;
      refine(child_origin, half, chains, known);
    }
  }

  // Gives every cell of the box [first, last] (local) the code the enclosures prove for
  // the whole box, if they do: no chain assembles anywhere in it, or every chain does and
  // each working mode keeps one sign beyond the margin throughout. Those are the codes of
  // the cells' centres; the sampled measure is within kSignSlack of the exact one. `proof`
  // gets the certificate of a box every chain assembles over, made for the working modes
  // not in `known` (proven over the box before), which gets those it proves; `chains`,
  // those of its own that may fail to assemble somewhere in the box.
  bool fillByProof(const int* first, const int* last, BoxCertificate& proof, std::uint32_t* chains,
                   std::uint64_t* known) {
    const BoxAssembly assembly = assemblyOf(first, last, chains);
    if (assembly == BoxAssembly::Undecided) return false;
    CellCode code = kCodeOutside;
    if (assembly == BoxAssembly::Inside) {
      proof = certificate_.certify(boxOf(first, last), proofs_map_.allModes() & ~*known);
      if (!provenCode(proof, &code, *known)) {
        *known |= modesProven(proof);
        return false;
      }
    }
    fill(first, last, code);
    return true;
  }

  // The code of every cell of a box whose certificate proves it assembled with every
  // working mode's part of the code fixed (modeProven); false where it does not.
  // `known`: modes proven over the box before (the certificate was made for the others).
  bool provenCode(const BoxCertificate& proof, CellCode* code, std::uint64_t known = 0) {
    if (proof.assembly != BoxAssembly::Inside || (known | modesProven(proof)) != proofs_map_.allModes()) return false;
    *code = encoder_.encode(proof.centre_measure.data());
    return true;
  }

  // Whether working mode m keeps its part of the code over a box inside the one `proof`
  // certifies, where `floor` bounds |measure| from below: it breaks a limit at every pose
  // (blocked throughout), or keeps every limit and its sign beyond the margin.
  bool modeProven(const BoxCertificate& proof, std::size_t m, double floor) const {
    const std::uint64_t bit = std::uint64_t{1} << m;
    return (proof.limits_broken & bit) != 0 || ((proof.limits_kept & bit) != 0 && signProven(floor));
  }
  // The working modes (bit m) modeProven over the whole box `proof` certifies.
  std::uint64_t modesProven(const BoxCertificate& proof) const {
    std::uint64_t proven = 0;
    for (std::size_t m = 0; m < proof.measure_floor.size(); ++m) {
      if (modeProven(proof, m, proof.measure_floor[m])) proven |= std::uint64_t{1} << m;
    }
    return proven;
  }
  // Whether a floor of |measure| proves the sign beyond the margin.
  bool signProven(double floor) const { return floor > band_ + kSignSlack; }

  // Whether a cell of `code` inside a box `proof` certifies assembled is, at every pose of
  // its box, in the workspace as its centre is (some working mode keeping every limit) or
  // out of it (kCodeBlocked: every mode breaking one).
  bool membershipProven(const BoxCertificate& proof, CellCode code) const {
    return membershipProven(proof.limits_kept, proof.limits_broken, code);
  }
  bool membershipProven(std::uint64_t limits_kept, std::uint64_t limits_broken, CellCode code) const {
    return code == kCodeBlocked ? limits_broken == proofs_map_.allModes() : limits_kept != 0;
  }

  PoseBox boxOf(const int* first, const int* last) const {
    GridCell low{}, high{};
    for (int d = 0; d < dims_; ++d) low[d] = origin_[d] + first[d], high[d] = origin_[d] + last[d];
    return grid_.cellsBox(low, high);
  }

  // `chains`: the chains that may fail to assemble somewhere in the box, narrowed to those
  // that still may.
  BoxAssembly assemblyOf(const int* first, const int* last, std::uint32_t* chains) {
    ++proofs_;
    return certificate_.assemblyOf(boxOf(first, last), *chains, chains);
  }

  void fill(const int* first, const int* last, CellCode code) {
    if (markWholeBlocks(first, last, code)) return;
    forRows(dims_, stride_.data(), first, last, [](const int*) { return true; }, [&](std::size_t local, const int*) {
      codes_[local] = code;
      proofs_map_.pack(CellProof{true, proofs_map_.allModes()}, &proven_[local * proof_width_]);
    });
  }

  // When [first, last] is made of whole blocks, records their code for storeBlocks (their
  // cells are not written: nothing reads them) and returns true.
  bool markWholeBlocks(const int* first, const int* last, CellCode code) {
    const int side = layout_.side(), top_blocks = side_ / side;
    int from[kMaxGridDims], to[kMaxGridDims], x[kMaxGridDims];
    for (int d = 0; d < dims_; ++d) {
      if (first[d] % side != 0 || (last[d] + 1) % side != 0) return false;
      x[d] = from[d] = first[d] / side;
      to[d] = last[d] / side;
    }
    while (true) {
      std::size_t index = 0;
      for (int d = 0; d < dims_; ++d) index = index * top_blocks + x[d];
      whole_blocks_[index] = code;
      int d = dims_ - 1;
      while (d >= 0 && ++x[d] > to[d]) x[d] = from[d], --d;
      if (d < 0) return true;
    }
  }

  // Classifies the cells of a leaf [first, last] (local, `side` cells a side before the
  // box cut it). Where `proof` bounds how far the measure moves over the leaf, cubes of
  // half its side are decided from the sample at their middle cell and split down to
  // cells where that does not prove them; where the workspace's boundary may cross the
  // leaf, cubes proven outside are left out. The samples follow the surfaces. The working
  // modes of `known` are proven over the leaf (`proof` is made for the others).
  void classifyLeaf(const int* first, const int* last, int side, const BoxCertificate& proof,
                    std::uint32_t chains = ~0u, std::uint64_t known = 0) {
    cubes_.clear();
    if (proof.assembly == BoxAssembly::Inside) {
      if ((proof.limits_kept | proof.limits_broken) != proofs_map_.allModes() && side >= 2 * kSmallestCertifiedSide) {
        certifyHalves(first, last, side);
        return;
      }
      if (proof.boundsVariation()) {
        cubes_.push_back(wholeCube(first, last, side));
        cubes_.back().known = known;
        provenByVariation(proof);
        return;
      }
      if (side <= kSmallestOutsideProof || !nearReach(first, last, proof)) {
        sampleProven(first, last, proof, known);
        flush();
        return;
      }
    }
    if (side > kSmallestOutsideProof) {
      split(first, last, side, cubes_, chains);
      provenOutside();
      return;
    } else {
      sample(first, last);
    }
    flush();
  }

  // An assembled leaf where some working mode may keep a limit on part of it only: its
  // half-size cubes get certificates of their own, down to kSmallestCertifiedSide cells a
  // side, and are leaves of their own.
  void certifyHalves(const int* first, const int* last, int side) {
    std::vector<LeafCube> halves;
    split(first, last, side, halves);
    for (const LeafCube& cube : halves) {
      const BoxCertificate proof = certificate_.certify(boxOf(cube.first, cube.last));
      CellCode code = kCodeOutside;
      if (provenCode(proof, &code)) {
        fill(cube.first, cube.last, code);
      } else {
        classifyLeaf(cube.first, cube.last, cube.side, proof);
      }
    }
  }

  // Samples the cubes_ (split from an assembled leaf whose certificate is `proof`) as
  // classifyLeaf says. A cube split from one its middle's sample did not prove is first
  // tried from that sample: near it the bound moves less, so many are proven without a
  // sample of their own. A cube of kSmallestCertifiedSide cells a side (smaller than the
  // leaf) that its sample does not prove gets, before it is split, a certificate of its
  // own: over the smaller box the gradient's enclosure is tighter, and its cells are proven
  // nearer the surface that split it (delta-like robot at 2 mm: 14.8 M poses -> 11.2 M,
  // for 0.4 M more boxes). Single cells are tried from every sample near them, working
  // mode by working mode (cellFromSamples), half of them before the other half is sampled.
  void provenByVariation(const BoxCertificate& proof) {
    const std::size_t modes = classifier_.modes().size();
    startLeaf(proof);
    while (!cubes_.empty() && cubes_.front().side > 1) {
      for (LeafCube& cube : cubes_) {
        for (int d = 0; d < dims_; ++d) cube.middle[d] = std::min(cube.first[d] + cube.side / 2, cube.last[d]);
        const double* parent = cube.has_parent ? leafSample(cube.parent_middle) : nullptr;
        if (parent != nullptr && filledFrom(cube, cube.parent_middle, parent)) {
          cube.slot = kFilledFromParent;
          continue;
        }
        cube.slot = enqueue(localOffset(cube.middle), cube.middle);
      }
      flush();
      next_cubes_.clear();
      for (LeafCube& cube : cubes_) {
        if (cube.slot == kFilledFromParent) continue;
        if (cube.slot < 0) {  // its middle cell was sampled, and tried alone, before
          split(cube.first, cube.last, cube.side, next_cubes_);
          continue;
        }
        const double* measures = keepLeafSample(cube.middle, &measures_[cube.slot * modes]);
        std::uint64_t over_cube = 0;
        if (filledFrom(cube, cube.middle, measures, &over_cube)) continue;
        if (cube.side == kSmallestCertifiedSide && cube.side < leaf_.side && cube.proof == kLeafProof &&
            certifiedCube(cube, measures, over_cube)) {
          continue;
        }
        keepOwnProof(cube.middle, cube.proof, measures);
        const std::size_t from = next_cubes_.size();
        split(cube.first, cube.last, cube.side, next_cubes_);
        for (std::size_t i = from; i < next_cubes_.size(); ++i) {
          next_cubes_[i].proof = cube.proof;
          next_cubes_[i].has_parent = true;
          std::copy(cube.middle, cube.middle + dims_, next_cubes_[i].parent_middle);
        }
      }
      cubes_.swap(next_cubes_);
    }
    // Single cells: those not proven from the samples near them are sampled, every other
    // one first (by the parity of its coordinates' sum), so that each of the others has
    // sampled face neighbours to be proven from.
    for (int parity = 0; parity < 2 && !cubes_.empty(); ++parity) {
      next_cubes_.clear();
      for (LeafCube& cube : cubes_) {
        cube.slot = -1;
        if (codes_[localOffset(cube.first)] != kCodeUnevaluated) continue;  // a middle sampled above
        if (cellFromSamples(cube.first, cube.has_parent ? cube.parent_middle : nullptr, cube.proof)) continue;
        int sum = 0;
        for (int d = 0; d < dims_; ++d) sum += cube.first[d];
        if (parity == 0 && sum % 2 != 0) {
          next_cubes_.push_back(cube);
          continue;
        }
        cube.slot = enqueue(localOffset(cube.first), cube.first);
      }
      flush();
      for (const LeafCube& cube : cubes_) {
        if (cube.slot < 0) continue;
        keepOwnProof(cube.first, cube.proof, keepLeafSample(cube.first, &measures_[cube.slot * modes]));
      }
      cubes_.swap(next_cubes_);
    }
    cubes_.clear();
  }

  // Empties provenByVariation's stores for the leaf cubes_.front(), certified by `proof`:
  // its samples, its cubes' certificates and the thresholds kept from them.
  void startLeaf(const BoxCertificate& proof) {
    leaf_ = cubes_.front();
    leaf_proof_ = &proof;
    // A leaf keeps the modes proven over it before its certificate: over a cube holding it,
    // or, inside a BoundaryCube, by its natural floors.
    known_modes_ = leaf_.known;
    if (leaf_.boundary_cube != kNoBoundaryCube) known_modes_ |= boundary_cubes_[leaf_.boundary_cube].modes.value_or(0);
    cube_proofs_.clear();
    std::size_t leaf_cells = 1, offsets = 2, certified_cubes = 1;
    for (int d = 0; d < dims_; ++d) {
      leaf_cells *= static_cast<std::size_t>(leaf_.side);
      offsets *= static_cast<std::size_t>(2 * leaf_.side - 1);
      certified_cubes *= static_cast<std::size_t>(std::max(1, leaf_.side / kSmallestCertifiedSide));
    }
    leaf_sample_.assign(leaf_cells, kNoSample);
    leaf_measures_.clear();
    offsets_per_proof_ = offsets;
    offsets *= 1 + certified_cubes;
    if (cell_threshold_leaf_.size() < offsets) {
      cell_threshold_leaf_.assign(offsets, 0);
      cell_threshold_at_.resize(offsets);
    }
    ++leaf_number_;
    cell_thresholds_.clear();
  }

  // What the proofs say of a sampled cell of an assembled leaf, mode by mode, for the
  // certified volumes: from its own sample and the certificate `proof` (proofOf).
  void keepOwnProof(const int* x, int proof, const double* measures) {
    const LeafCube cell = singleCell(x);
    const std::size_t local = localOffset(x);
    proofs_map_.pack(
        CellProof{membershipProven(proofOf(proof), codes_[local]), provenModes(cell, x, proof, measures, false)},
        &proven_[local * proof_width_]);
  }

  // The sample store of the leaf provenByVariation works on (leaf_): per cell, its place
  // in leaf_measures_, or kNoSample.
  std::size_t leafIndex(const int* x) const {
    std::size_t index = 0;
    for (int d = 0; d < dims_; ++d) index = index * static_cast<std::size_t>(leaf_.side) + (x[d] - leaf_.first[d]);
    return index;
  }
  const double* leafSample(const int* x) const {
    const std::int32_t at = leaf_sample_[leafIndex(x)];
    return at == kNoSample ? nullptr : &leaf_measures_[static_cast<std::size_t>(at) * classifier_.modes().size()];
  }
  const double* keepLeafSample(const int* x, const double* measures) {
    const std::size_t modes = classifier_.modes().size();
    leaf_sample_[leafIndex(x)] = static_cast<std::int32_t>(leaf_measures_.size() / modes);
    leaf_measures_.insert(leaf_measures_.end(), measures, measures + modes);
    return &leaf_measures_[leaf_measures_.size() - modes];
  }

  // Gives a cell of the leaf its code where each working mode's part of it is proven at the
  // cell's centre from some sample of the leaf near it: its parent cube's middle first,
  // then its face neighbours. A mode is then proven from a sample on its side of the mode's
  // singular surface, whichever side the others' samples lie on. The cell keeps the modes
  // proven over its whole box from those samples. (The 26 cells within one along each
  // variable spared 2 % more samples on the delta-like robot at 2 mm, for four times the
  // lookups of the 6 face neighbours.)
  bool cellFromSamples(const int* x, const int* parent, int cube_proof) {
    const std::uint64_t all = proofs_map_.allModes();
    const std::size_t modes = classifier_.modes().size();
    const LeafCube cell = singleCell(x);
    std::uint64_t at_centre = 0, over_box = 0;
    const auto tryReference = [&](const int* reference) {
      const double* measures = leafSample(reference);
      if (measures == nullptr) return;
      const int proof = proofFrom(cube_proof, reference);
      const std::uint64_t proven = provenModes(cell, reference, proof, measures, false, 0.0, all & ~at_centre);
      if (proven == 0) return;
      for (std::size_t m = 0; m < modes; ++m) {
        if (proven >> m & 1) cell_measures_[m] = measures[m];
      }
      at_centre |= proven;
      over_box |= provenModes(cell, reference, proof, measures, false, 0.5, proven);
    };
    if (parent != nullptr) tryReference(parent);
    int reference[kMaxGridDims];
    std::copy(x, x + dims_, reference);
    for (int d = 0; d < dims_ && at_centre != all; ++d) {
      for (int direction : {-1, 1}) {
        reference[d] = x[d] + direction;
        const bool in_leaf = reference[d] >= leaf_.first[d] && reference[d] <= leaf_.last[d];
        const bool is_parent = parent != nullptr && sameCell(reference, parent, dims_);
        if (at_centre != all && in_leaf && !is_parent) tryReference(reference);
      }
      reference[d] = x[d];
    }
    if (at_centre != all) return false;
    const std::size_t local = localOffset(x);
    codes_[local] = encoder_.encode(cell_measures_.data());
    proofs_map_.pack(CellProof{membershipProven(proofOf(cube_proof), codes_[local]), over_box},
                     &proven_[local * proof_width_]);
    return true;
  }

  // Leaves out the cubes_ proven outside the workspace and splits those that may hold its
  // boundary down to kSmallestOutsideProof cells a side; those proven assembled get a
  // certificate of their own (kSmallestCertifiedSide cells a side or more: below, one
  // costs more than sampling them, and they keep the modes their BoundaryCube proves) and
  // go on as an assembled leaf; the others are sampled.
  void provenOutside() {
    boundary_cubes_.clear();
    assembled_cubes_.clear();
    assembled_proofs_.clear();
    while (!cubes_.empty()) {
      next_cubes_.clear();
      for (LeafCube& cube : cubes_) {
        std::uint32_t chains = cube.chains;
        BoxAssembly assembly = assemblyOf(cube.first, cube.last, &chains);
        // One cell the natural form leaves undecided: the mean-value form too.
        bool near_boundary = false;
        if (assembly == BoxAssembly::Undecided && cube.side == 1) {
          ++proofs_;
          assembly = certificate_.assemblyOfCell(boxOf(cube.first, cube.last), chains, &chains);
          near_boundary = assembly == BoxAssembly::Inside;
        }
        if (assembly == BoxAssembly::Outside) {
          fill(cube.first, cube.last, kCodeOutside);
        } else if (assembly == BoxAssembly::Inside && cube.side < kSmallestCertifiedSide) {
          const CellProof proof{true, modesWhereAssembled(cube.boundary_cube), near_boundary};
          if (cube.side > 1 && proof.modes != proofs_map_.allModes() && certifiedAssembled(cube, proof.modes)) continue;
          keepAssembled(cube.first, cube.last, proof, cube.boundary_cube);
        } else if (assembly == BoxAssembly::Inside && decidedAssembled(cube)) {
          continue;
        } else if (cube.side > kSmallestOutsideProof) {
          // The boundary may cross it, or a chain nears its reach in it (decidedAssembled).
          const std::size_t from = next_cubes_.size();
          split(cube.first, cube.last, cube.side, next_cubes_, chains);
          if (cube.side == kSmallestCertifiedSide && cube.boundary_cube == kNoBoundaryCube) {
            cube.boundary_cube = boundary_cubes_.size();
            boundary_cubes_.emplace_back(cube.first, cube.last, dims_);
          }
          for (std::size_t i = from; i < next_cubes_.size(); ++i) next_cubes_[i].boundary_cube = cube.boundary_cube;
        } else {
          sample(cube.first, cube.last);
        }
      }
      flush();
      cubes_.swap(next_cubes_);
    }
    for (std::size_t i = 0; i < assembled_cubes_.size(); ++i) {
      cubes_.push_back(assembled_cubes_[i]);
      provenByVariation(assembled_proofs_[i]);
    }
  }

  void sample(const int* first, const int* last) {
    forRows(dims_, stride_.data(), first, last, [](const int*) { return true; },
            [this](std::size_t local, const int* x) { enqueue(local, x); });
  }

  // Samples a box whose certificate `proof` (assembled) bounds no variation: once the batch
  // is classified, each cell keeps what the certificate proves over the whole box, and the
  // modes `known` proven over it before.
  void sampleProven(const int* first, const int* last, const BoxCertificate& proof, std::uint64_t known = 0) {
    sample(first, last);
    SampledBox box{{}, {}, proof.limits_kept, proof.limits_broken, known | modesProven(proof)};
    std::copy(first, first + dims_, box.first);
    std::copy(last, last + dims_, box.last);
    sampled_boxes_.push_back(box);
  }

  // After a batch: the proofs of the cells of the boxes sampleProven queued.
  void keepSampledProofs() {
    for (const SampledBox& box : sampled_boxes_) {
      forRows(dims_, stride_.data(), box.first, box.last, [](const int*) { return true; }, [&](std::size_t local, const int*) {
        const CellProof proof{membershipProven(box.limits_kept, box.limits_broken, codes_[local]), box.modes};
        proofs_map_.pack(proof, &proven_[local * proof_width_]);
      });
    }
    sampled_boxes_.clear();
  }

  // A box proven assembled inside a BoundaryCube: keeps that proof (with the working modes
  // proven over it) where no limit can bind (with limits, membership needs a certificate).
  // Where every working mode is proven, the floors' signs give the code; else the cells
  // are sampled.
  void keepAssembled(const int* first, const int* last, const CellProof& proof, std::size_t boundary_cube) {
    const bool coded = proof.modes == proofs_map_.allModes();
    const CellCode code = coded ? boundary_cubes_[boundary_cube].code : kCodeUnevaluated;
    if (!coded) sample(first, last);
    if (certificate_.hasLimits()) return;
    forRows(dims_, stride_.data(), first, last, [](const int*) { return true; }, [&](std::size_t local, const int*) {
      if (coded) codes_[local] = code;
      proofs_map_.pack(proof, &proven_[local * proof_width_]);
    });
  }

  // The working modes whose sign, beyond the margin, is proven over the assembled part of
  // a cube that may cross the workspace boundary (none for a robot with limits): its cells
  // proven assembled keep them, and where every mode is proven, take their code from the
  // floors' signs. Near the boundary the rods' rates are unbounded, so no slope proves
  // them; the cube's own enclosure of the determinant can.
  // Computed on the first of its cells proven assembled (many such cubes have none).
  std::uint64_t modesWhereAssembled(std::size_t boundary_cube) {
    if (certificate_.hasLimits() || boundary_cube == kNoBoundaryCube) return 0;
    BoundaryCube& cube = boundary_cubes_[boundary_cube];
    if (cube.modes) return *cube.modes;
    ++proofs_;
    const std::vector<double> floors = certificate_.floorsWhereAssembled(boxOf(cube.first, cube.last));
    cube.modes = 0;
    for (std::size_t m = 0; m < floors.size(); ++m) {
      if (signProven(std::abs(floors[m]))) *cube.modes |= std::uint64_t{1} << m;
    }
    if (*cube.modes == proofs_map_.allModes()) cube.code = encoder_.encode(floors.data());
    return *cube.modes;
  }

  // Whether an assembled box [first, last] whose certificate bounds no variation lies where
  // a chain nears its reach (a rod's rate unbounded on the factorised path, else
  // MeasureCertificate::chainsNearReach) and no limit binds: such a
  // box is split as one the boundary may cross, whose cubes' natural enclosures
  // (decidedAssembled, BoundaryCube) prove more of its cells than its certificate does,
  // since near the reach a rod's rate grows without bound. On the delta-like robot at 2 mm,
  // once the sliders' discriminants were enclosed tightly enough to prove these boxes
  // assembled, sampling them whole took 5 M more poses (27.4 M against 26.3 M before the
  // tighter enclosure, 24.7 M with the split).
  bool nearReach(const int* first, const int* last, const BoxCertificate& proof) {
    if (proof.boundsVariation() || certificate_.hasLimits()) return false;
    const PoseBox box = boxOf(first, last);
    // On the factorised path only a rod whose rate may be unbounded denies the bound.
    if (certificate_.factorisesOver(box)) return true;
    ++proofs_;
    return certificate_.chainsNearReach(box, kSplitNearReachSpreads) != 0;
  }

  // A cube of kSmallestCertifiedSide cells a side that the workspace's boundary may cross.
  struct BoundaryCube {
    BoundaryCube(const int* from, const int* to, int dims) {
      std::copy(from, from + dims, first);
      std::copy(to, to + dims, last);
    }
    int first[kMaxGridDims], last[kMaxGridDims];
    std::optional<std::uint64_t> modes;  // modesWhereAssembled's, once computed
    CellCode code = kCodeUnevaluated;    // its assembled cells', where every mode is proven
  };
  static constexpr std::size_t kNoBoundaryCube = ~std::size_t{0};

  struct LeafCube {
    int first[kMaxGridDims], last[kMaxGridDims], middle[kMaxGridDims];
    int side = 1;
    std::ptrdiff_t slot = -1;  // the middle cell's place in the last batch; -1: sampled before
    std::uint32_t chains = ~0u;  // those that may fail to assemble somewhere in it (refine's)
    std::size_t boundary_cube = kNoBoundaryCube;  // the BoundaryCube it lies in, if any
    // Whether it was split in provenByVariation from a cube whose middle's sample (at
    // parent_middle) did not prove it.
    bool has_parent = false;
    int parent_middle[kMaxGridDims];
    int proof = kLeafProof;  // provenByVariation's certificate for its cells (proofOf)
    std::uint64_t known = 0;  // working modes proven over it before its certificate (a leaf's)
  };
  static constexpr int kLeafProof = 0;
  struct CubeProof {
    LeafCube cube;
    BoxCertificate proof;
    std::uint64_t known;  // the modes the leaf's certificate proves over the cube: not in `proof`
  };

  // Gives a cube of provenByVariation its own certificate (cube.proof), and fills it where
  // that proves it whole (its code, or from its middle's sample `measures`); true then.
  // The certificate is made for the modes the leaf's does not prove over the cube (`known`):
  // near one mode's singular surface most of the others are, and the rows and floors of
  // the modes left out are not computed.
  bool certifiedCube(LeafCube& cube, const double* measures, std::uint64_t known) {
    ++proofs_;
    BoxCertificate proof = certificate_.certify(boxOf(cube.first, cube.last), proofs_map_.allModes() & ~known);
    CellCode code = kCodeOutside;
    if (provenCode(proof, &code, known)) {
      fill(cube.first, cube.last, code);
      return true;
    }
    if (!proof.boundsVariation()) return false;
    cube_proofs_.push_back(CubeProof{wholeCube(cube.first, cube.last, cube.side), std::move(proof), known});
    cube.proof = static_cast<int>(cube_proofs_.size());
    return filledFrom(cube, cube.middle, measures);
  }

  // provenByVariation's certificates: the leaf's (kLeafProof), then its cubes' (cube_proofs_,
  // from 1), each over the cells of its cube.
  const BoxCertificate& proofOf(int index) const { return index == kLeafProof ? *leaf_proof_ : cube_proofs_[index - 1].proof; }
  // The certificate to prove a cell of a cube whose own is `index` from a sample at
  // `reference`: that one where it covers the reference too, else the leaf's.
  int proofFrom(int index, const int* reference) const {
    if (index == kLeafProof) return index;
    const LeafCube& cube = cube_proofs_[index - 1].cube;
    for (int d = 0; d < dims_; ++d) {
      if (reference[d] < cube.first[d] || reference[d] > cube.last[d]) return kLeafProof;
    }
    return index;
  }

  // Decides an assembled cube of kSmallestCertifiedSide cells a side or more in a leaf the
  // boundary may cross: by the natural enclosures of the determinants over it where they
  // prove every working mode (near the boundary a rod's rate grows without bound and the
  // certificate's slopes prove less), else by its certificate (a code, a variation bound,
  // or what it proves over cells all sampled). False, to be split like a cube the boundary
  // may cross, where the certificate fails for a chain nearing its reach (nearReach).
  bool decidedAssembled(LeafCube& cube) {
    std::uint64_t known = 0;  // the modes its natural floors prove: the certificate is for the others
    if (cube.side == kSmallestCertifiedSide && !certificate_.hasLimits()) {
      cube.boundary_cube = boundary_cubes_.size();
      boundary_cubes_.emplace_back(cube.first, cube.last, dims_);
      known = modesWhereAssembled(cube.boundary_cube);
      if (known == proofs_map_.allModes()) {
        fill(cube.first, cube.last, boundary_cubes_[cube.boundary_cube].code);
        return true;
      }
    }
    BoxCertificate proof = certificate_.certify(boxOf(cube.first, cube.last), proofs_map_.allModes() & ~known);
    CellCode code = kCodeOutside;
    if (provenCode(proof, &code, known)) {
      fill(cube.first, cube.last, code);
    } else if (proof.boundsVariation()) {
      assembled_cubes_.push_back(cube);
      assembled_proofs_.push_back(std::move(proof));
    } else if (nearReach(cube.first, cube.last, proof)) {
      return false;
    } else {
      sampleProven(cube.first, cube.last, proof, known);
    }
    return true;
  }

  // An assembled cube below kSmallestCertifiedSide in a BoundaryCube whose floors prove
  // the working modes `known`, not all: where its own certificate (for the other modes)
  // bounds their variation, it goes on as an assembled leaf (provenByVariation, which
  // keeps `known` from the BoundaryCube) instead of having every cell sampled. On the
  // delta-like robot at 2 mm: 11.2 M poses -> 9.5 M for 445 k more boxes (29 % of which
  // bound no variation: a chain reaches its limit in them), and tighter certified bands.
  // Only on the factorised path: the perturbation bound gives no slopes.
  bool certifiedAssembled(LeafCube& cube, std::uint64_t known) {
    const PoseBox box = boxOf(cube.first, cube.last);
    if (certificate_.hasLimits() || !certificate_.factorisesOver(box)) return false;
    ++proofs_;
    BoxCertificate proof = certificate_.certify(box, proofs_map_.allModes() & ~known, true);
    if (!proof.boundsVariation()) return false;
    assembled_cubes_.push_back(cube);
    assembled_proofs_.push_back(std::move(proof));
    return true;
  }

  static constexpr std::ptrdiff_t kFilledFromParent = -2;

  LeafCube singleCell(const int* x) const {
    LeafCube cell;
    std::copy(x, x + dims_, cell.first);
    std::copy(x, x + dims_, cell.last);
    return cell;
  }

  LeafCube wholeCube(const int* first, const int* last, int side) const {
    LeafCube cube;
    cube.side = side;
    std::copy(first, first + dims_, cube.first);
    std::copy(last, last + dims_, cube.last);
    return cube;
  }

  // The 2^dims half-size cubes of the cube [first, last] of `side` cells (cut by the box).
  void split(const int* first, const int* last, int side, std::vector<LeafCube>& out, std::uint32_t chains = ~0u) const {
    const int half = side / 2;
    for (int child = 0; child < (1 << dims_); ++child) {
      LeafCube cube;
      cube.side = half;
      cube.chains = chains;
      bool empty = false;
      for (int d = 0; d < dims_; ++d) {
        // Cubes start on multiples of `half` from the leaf's aligned corner.
        const int origin = first[d] - first[d] % side + (child >> (dims_ - 1 - d) & 1) * half;
        cube.first[d] = std::max(origin, first[d]);
        cube.last[d] = std::min(origin + half - 1, last[d]);
        empty = empty || cube.first[d] > cube.last[d];
      }
      if (!empty) out.push_back(cube);
    }
  }

  // Fills a cube of an assembled leaf whose certificate is `proof` with the code sampled at
  // the cell `reference` (its middle, or a cell near it; `measures` its sample) where the
  // leaf's variation bound proves it: over the cube's whole box (every cell then keeps every
  // working mode's proof), or at its cells' centres alone, which fixes their codes (a code
  // is its centre's) but not their boxes: each cell then keeps the modes proven over its
  // own box. Near a singular surface most cells are proven so, sparing their samples.
  // `over_cube_out`, when given, gets the modes proven over the cube's whole box.
  bool filledFrom(const LeafCube& cube, const int* reference, const double* measures,
                  std::uint64_t* over_cube_out = nullptr) {
    const CellCode code = codes_[localOffset(reference)];
    const std::uint64_t all = proofs_map_.allModes();
    const int proof = cube.proof;
    const std::uint64_t over_cube = provenModes(cube, reference, proof, measures, false);
    if (over_cube_out != nullptr) *over_cube_out = over_cube;
    if (over_cube == all) {
      fill(cube.first, cube.last, code);
      return true;
    }
    if ((over_cube | provenModes(cube, reference, proof, measures, true, 0.0, all & ~over_cube)) != all) return false;
    const bool member = membershipProven(proofOf(proof), code);
    forRows(dims_, stride_.data(), cube.first, cube.last, [](const int*) { return true; }, [&](std::size_t local, const int* x) {
      const LeafCube cell = singleCell(x);
      codes_[local] = code;
      const std::uint64_t over_cell = over_cube | provenModes(cell, reference, proof, measures, false, 0.5, all & ~over_cube);
      proofs_map_.pack(CellProof{member, over_cell}, &proven_[local * proof_width_]);
    });
    return true;
  }

  // The working modes (bit m) that keep, over the cube, their part of the code sampled at
  // the cell `reference` (modeProven): the cube's middle, or a cell near it. Over its
  // cells' whole boxes, or with `pad` 0 at their centres alone.
  // With `all_or_none`, 0 unless every one is (a cube is filled only then).
  std::uint64_t provenModes(const LeafCube& cube, const int* reference, int proof, const double* measures,
                            bool all_or_none, double pad = 0.5, std::uint64_t wanted = ~std::uint64_t{0}) {
    const std::size_t modes = classifier_.modes().size();
    const bool cell = sameCell(cube.first, cube.last, dims_);
    double* kept = cell ? cellThresholds(cube.first, reference, pad, proof) : nullptr;
    Eigen::Vector3d low, high;  // the box's offsets, once a threshold is not kept
    bool box_known = false;
    // Modes proven over a box holding this one before its certificate was made.
    const std::uint64_t known = known_modes_ | (proof == kLeafProof ? 0 : cube_proofs_[proof - 1].known);
    std::uint64_t proven = known & wanted;
    for (std::size_t m = 0; m < modes; ++m) {
      if ((wanted >> m & 1) == 0 || (known >> m & 1) != 0) continue;
      const bool positive = measures[m] > 0.0;
      double threshold = kept != nullptr ? kept[(positive ? 0 : modes) + m] : kNotComputed;
      if (std::isnan(threshold)) {
        if (!box_known) offsetBox(cube, reference, pad, &low, &high), box_known = true;
        threshold = leastProving(proofOf(proof), m, positive, low, high);
        if (kept != nullptr) kept[(positive ? 0 : modes) + m] = threshold;
      }
      // A negative threshold: proven whatever the sample, NaN where the mode breaks a limit.
      if (threshold < 0.0 || std::abs(measures[m]) > threshold) {
        proven |= std::uint64_t{1} << m;
      } else if (all_or_none) {
        return 0;
      }
    }
    return proven;
  }

  // The box of `cube`, cells padded by `pad` each side, as offsets along x y z from the
  // centre of the cell `reference`.
  void offsetBox(const LeafCube& cube, const int* reference, double pad, Eigen::Vector3d* low,
                 Eigen::Vector3d* high) const {
    low->setZero(), high->setZero();
    for (int d = 0; d < dims_; ++d) {
      const int axis = static_cast<int>(grid_.variable(d));
      (*low)[axis] = (cube.first[d] - reference[d] - pad) * grid_.step(d);
      (*high)[axis] = (cube.last[d] - reference[d] + pad) * grid_.step(d);
    }
  }

  // The least |sample| of working mode m, of the given sign, at a reference that proves the
  // mode (modeProven) over the box of offsets [low, high] from it.
  double leastProving(const BoxCertificate& proof, std::size_t m, bool positive, const Eigen::Vector3d& low,
                      const Eigen::Vector3d& high) const {
    const std::uint64_t bit = std::uint64_t{1} << m;
    if ((proof.limits_broken & bit) != 0) return -1.0;  // proven whatever the sample
    if ((proof.limits_kept & bit) == 0) return std::numeric_limits<double>::infinity();
    // The sample's own sign must be proven too: a reference beside the box may lie in the
    // margin's band where the box does not (its floor grows away from it).
    const double floor = band_ + kSignSlack;
    return std::max(floor, proof.provingMagnitude(m, positive, low, high, floor));
  }

  // Per sign (positive first) and working mode, leastProving for a single cell of the leaf
  // provenByVariation works on, kept per certificate, offset from the reference and pad
  // (kNotComputed until provenModes needs it): most cells of a leaf are tried from the same
  // few offsets (the parent's middle, the face neighbours).
  double* cellThresholds(const int* cell, const int* reference, double pad, int proof) {
    const int span = 2 * leaf_.side - 1;
    std::size_t key = pad > 0.0 ? 1 : 0;
    for (int d = 0; d < dims_; ++d) key = key * span + (cell[d] - reference[d] + leaf_.side - 1);
    key += static_cast<std::size_t>(proof) * offsets_per_proof_;
    if (cell_threshold_leaf_[key] != leaf_number_) {
      cell_threshold_leaf_[key] = leaf_number_;
      cell_threshold_at_[key] = cell_thresholds_.size();
      cell_thresholds_.resize(cell_thresholds_.size() + 2 * classifier_.modes().size(), kNotComputed);
    }
    return &cell_thresholds_[cell_threshold_at_[key]];
  }
  static constexpr double kNotComputed = std::numeric_limits<double>::quiet_NaN();

  // Queues a cell for classification unless it has its code already; its place in the
  // batch, or -1.
  std::ptrdiff_t enqueue(std::size_t local, const int* x) {
    if (codes_[local] != kCodeUnevaluated) return -1;
    codes_[local] = kCodeQueued;
    slots_.push_back(local);
    double values[kMaxGridDims];
    for (int d = 0; d < dims_; ++d) values[d] = grid_.centre(d, origin_[d] + x[d]);
    poses_.push_back(grid_.poseAt(values));
    return static_cast<std::ptrdiff_t>(slots_.size()) - 1;
  }

  // Classifies the queued cells, in batches: of TCP positions when the orientation is
  // fixed, else of whole poses.
  void flush() {
    if (slots_.empty()) {
      keepSampledProofs();
      return;
    }
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
    keepSampledProofs();
  }

  const Grid& grid_;
  const BlockLayout& layout_;
  const PoseClassifier& classifier_;
  const MeasureCertificate& certificate_;
  PatternEncoder encoder_;
  const double band_;  // bandedSign's
  const int dims_;
  const int side_;
  std::array<std::size_t, kMaxGridDims> stride_{};
  std::vector<CellCode> codes_;
  const ProofMap proofs_map_;  // how the proofs are packed: proof_width_ bytes a cell
  const int proof_width_;
  std::vector<std::uint8_t> proven_;
  std::vector<std::size_t> block_cell_offset_;
  GridCell origin_{};
  int low_[kMaxGridDims] = {}, high_[kMaxGridDims] = {};
  std::uint64_t evaluated_ = 0, proofs_ = 0;
  std::vector<std::size_t> slots_;
  std::vector<Pose> poses_;
  std::vector<double> px_, py_, pz_;
  std::vector<std::uint8_t> inside_;
  std::vector<double> measures_;  // the last batch's, kept until the next
  // provenByVariation's leaf and its samples (leafSample).
  LeafCube leaf_;
  const BoxCertificate* leaf_proof_ = nullptr;
  std::vector<CubeProof> cube_proofs_;
  static constexpr std::int32_t kNoSample = -1;
  std::vector<std::int32_t> leaf_sample_;
  std::vector<double> leaf_measures_;
  std::vector<double> cell_measures_;  // cellFromSamples's, per working mode
  // cellThresholds's, per offset key: the leaf they were computed for (leaf_number_
  // counts provenByVariation's leaves) and where they start in cell_thresholds_.
  std::uint64_t leaf_number_ = 0;
  std::size_t offsets_per_proof_ = 0;
  std::vector<std::uint64_t> cell_threshold_leaf_;
  std::vector<std::size_t> cell_threshold_at_;
  std::vector<double> cell_thresholds_;
  // Per block of the top cube (its block coordinates, the last fastest): the code of a
  // block a proof filled whole, else kNotWhole.
  static constexpr CellCode kNotWhole = kCodeUnevaluated;  // a marker no proof fills a block with
  std::vector<CellCode> whole_blocks_;
  std::vector<LeafCube> cubes_, next_cubes_, assembled_cubes_;
  std::vector<BoundaryCube> boundary_cubes_;  // provenOutside's, cleared with each call
  // Boxes sampleProven sampled, and what their certificates prove.
  struct SampledBox {
    int first[kMaxGridDims], last[kMaxGridDims];
    std::uint64_t limits_kept, limits_broken, modes;
  };
  std::vector<SampledBox> sampled_boxes_;
  std::vector<BoxCertificate> assembled_proofs_;
  std::uint64_t known_modes_ = 0;  // of the leaf provenByVariation works on: proven before it
};

// The stage's share of sampling the cells; the rest is the check of thin layers (the
// delta-like robot: 72 % of the stage at 2 mm, 70 % at 3 mm).
constexpr double kSamplingShare = 0.7;

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

// A step coprime to `count` near its golden section: t -> t * step mod count visits every
// index once, and any run of visits is spread evenly over [0, count).
std::uint64_t spreadingStride(std::uint64_t count) {
  if (count < 3) return 1;
  std::uint64_t step = static_cast<std::uint64_t>(0.6180339887 * static_cast<double>(count));
  while (std::gcd(step, count) != 1) ++step;
  return step;
}

// Moves the blocks of a classified top cube into the code map (one code for a block
// whose cells all share it, else a page) and the proof map.
void storeBlocks(const TopNodeClassifier& top, const GridCell& first_block, int top_blocks, const BlockLayout& layout,
                 CodeMap* codes, ProofMap* proofs, std::mutex* pages_mutex) {
  const int dims = layout.dims(), cells = layout.cellsPerBlock(), width = proofs->width();
  std::vector<std::uint8_t> all_proven(width);  // the bytes of a cell proven whole
  proofs->pack(CellProof{true, proofs->allModes()}, all_proven.data());
  std::vector<std::uint8_t> packed(static_cast<std::size_t>(cells) * width);  // a block's, in cell order
  std::vector<CellCode> block_codes(cells);
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
    CellCode whole_code = 0;
    if (in_lattice && top.wholeBlock(offset, &whole_code)) {
      const std::uint64_t index = layout.blockIndex(block);
      codes->setUniform(index, whole_code);
      proofs->setAll(index);
    } else if (in_lattice) {
      const std::size_t base = top.localOffset(local);
      for (int c = 0; c < cells; ++c) block_codes[c] = top.code(base, c);
      const std::uint64_t index = layout.blockIndex(block);
      if (std::all_of(block_codes.begin(), block_codes.end(), [&](CellCode code) { return code == block_codes[0]; })) {
        codes->setUniform(index, block_codes[0]);
      } else {
        const std::lock_guard<std::mutex> lock(*pages_mutex);
        codes->addPage(index, block_codes.data());
      }
      int proven = 0, unproven = 0;
      for (int c = 0; c < cells; ++c) {
        const std::uint8_t* proof = top.proof(base, c);
        bool all = true, none = true;
        for (int i = 0; i < width; ++i) all = all && proof[i] == all_proven[i], none = none && proof[i] == 0;
        proven += all;
        unproven += none;
      }
      if (proven == cells) {
        proofs->setAll(index);
      } else if (unproven < cells) {
        for (int c = 0; c < cells; ++c) std::copy(top.proof(base, c), top.proof(base, c) + width, packed.data() + c * width);
        const std::lock_guard<std::mutex> lock(*pages_mutex);
        proofs->addPage(index, packed.data());
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
  CodeTable<std::uint8_t> inside_key(cells.patterns.patterns.size(), 0);
  for (CellCode code = 0; code < cells.patterns.patterns.size(); ++code) inside_key[code] = 1;
  LabelLayer connected;
  const std::vector<Component> components = labelComponents(cells.layout, cells.codes, inside_key, cells.cuts, -1, &connected);
  const std::int32_t start_component = connected.label(cells.start_block, cells.start_cell);
  if (start_component == kNoLabel) {
    // The start cell's centre is assembled (startCell): only a cut on every face isolates it.
    throw std::runtime_error("the start cell is cut off from every neighbour by layers thinner than the step; use a smaller step");
  }
  cells.inside_cells = components[start_component].cells;
  for (std::uint64_t b = 0; b < cells.layout.blockCount(); ++b) {
    if (cells.codes.uniform(b)) {
      const std::int32_t label = connected.label(b, 0);
      if (label != kNoLabel && label != start_component) cells.codes.setUniform(b, kCodeDetached);
      continue;
    }
    for (int c = 0; c < cells.layout.cellsPerBlock(); ++c) {
      const std::int32_t label = connected.label(b, c);
      if (label != kNoLabel && label != start_component) cells.codes.setMarker(b, c, kCodeDetached);
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
    where += std::string(d ? " " : "") + grid.variableName(d) + "=" + numberText(grid.coordinate(start_centre, d));
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

WorkspaceCells classifyWorkspace(const Grid& grid, const PoseClassifier& classifier,
                                 const MeasureCertificate& certificate, const ClassificationOptions& options) {
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
  // Progress counts cubes, and cheap ones lie together (those beyond the reach): taken in
  // an order spread over the box, the count keeps pace with the time (taken row by row, a
  // 3 mm analysis had done 40 % of its cubes at 70 % of the time).
  const std::uint64_t stride = spreadingStride(top_count);
  PatternInterner interner;
  cells.proven = ProofMap(layout.blockCount(), layout.cellsPerBlock(), modes);
  std::atomic<std::uint64_t> next{0}, done{0}, evaluated{0}, proofs{0};
  std::mutex pages_mutex;
  ThrottledProgress progress(options.progress);
  const int workers = resolveThreadCount(options.threads);
  parallelFor(workers, workers, [&](std::size_t, std::size_t) {
    TopNodeClassifier top(grid, layout, classifier, certificate, interner, options.margin, top_side);
    for (std::uint64_t t = next++; t < top_count; t = next++) {
      throwIfCancelled(options.cancelled);
      GridCell first{};
      std::uint64_t rest = (t * stride) % top_count;
      for (int d = grid.dims() - 1; d >= 0; --d) {
        first[d] = static_cast<std::int64_t>(rest % tops[d]) * top_blocks;
        rest /= tops[d];
      }
      const ClassificationWork work = top.run(first);
      evaluated += work.evaluated, proofs += work.proofs;
      storeBlocks(top, first, top_blocks, layout, &cells.codes, &cells.proven, &pages_mutex);
      progress.update(kSamplingShare * static_cast<double>(++done) / top_count, evaluated);
    }
  }, 1);
  cells.evaluated = evaluated;
  cells.proofs = proofs;
  cells.patterns = SignPatterns{modes, interner.take()};
  const std::uint64_t sampled = evaluated;
  cells.cuts = findThinLayers(grid, cells, certificate, classifier, options.threads, options.cancelled,
                              [&](double fraction) {
                                progress.update(kSamplingShare + (1.0 - kSamplingShare) * fraction, sampled);
                              });
  // The labelling reads a cut's blocks cell by cell.
  for (std::uint64_t b : cells.cuts.blocks) {
    if (!cells.codes.uniform(b)) continue;
    const std::vector<CellCode> block_codes(layout.cellsPerBlock(), cells.codes.uniformCode(b));
    cells.codes.addPage(b, block_codes.data());
  }
  keepConnected(cells);
  return cells;
}

}  // namespace maximal_workspace
