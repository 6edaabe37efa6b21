// Per assembly mode figures: region and transition counts, the traditional region, and
// the maximal and reachable volumes tallied over the blocks.

#include <algorithm>
#include <cmath>
#include <map>

#include "regions/analysis_data.h"
#include "workspace/parallel.h"

namespace maximal_workspace {

namespace {

// The sets a workspace cell can belong to, as bits of a mask: the certified volumes are
// kept per set.
enum CellSet : std::uint8_t { kWorkspaceSet = 0, kMaximalSet = 1, kTraditionalSet = 3, kReachableSet = 5, kSetCount = 7 };
constexpr std::uint8_t setBit(int set, int a = 0) { return static_cast<std::uint8_t>(1u << (set + a)); }
constexpr std::uint8_t kEverySet = (1u << kSetCount) - 1;

struct Membership {
  std::uint8_t in = 0, proven_in = 0, proven_out = 0;  // masks of CellSet bits
  // A cell not proven assembled or out as a whole: shares of it may be (AssemblyShares).
  bool shares = false;
  bool operator==(const Membership& other) const {
    return in == other.in && proven_in == other.proven_in && proven_out == other.proven_out && shares == other.shares;
  }
};

// Per set, in cells (shares of one where a surface crosses a cell): its proven part, its
// part not proven, and the part not proven out of it beside it.
struct SetCounts {
  std::array<double, kSetCount> proven{}, unproven{}, beside{};
  void merge(const SetCounts& other) {
    for (int k = 0; k < kSetCount; ++k) {
      proven[k] += other.proven[k], unproven[k] += other.unproven[k], beside[k] += other.beside[k];
    }
  }
};

// Per set, the share of one cell proven in it where its membership proves less.
using SetShares = std::array<double, kSetCount>;

// The counts and the traditional region at construction, volumes from add() over every
// workspace cell.
class AssemblyModeTally {
 public:
  // start_labels[m]: the region of working mode m at the start (or -1).
  // `assembled_shares`: a cell's share proven assembled is in the workspace (not with
  // limits, which membership also needs).
  AssemblyModeTally(const std::vector<Region>& regions, const TransitionGraph& graph, const std::int32_t* start_labels,
                    int start_mode, int mode_count, bool assembled_shares)
      : regions_(regions), graph_(graph), mode_count_(mode_count), assembled_shares_(assembled_shares),
        all_modes_(mode_count >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << mode_count) - 1) {
    for (int a = 0; a < 2; ++a) {
      summaries_[a].sign = a == 0 ? 1 : -1;
      countRegions(summaries_[a]);
      summaries_[a].traditional_region = traditionalRegion(summaries_[a].sign, start_labels, start_mode);
      if (summaries_[a].traditional_region >= 0) {
        summaries_[a].traditional_volume = regions[summaries_[a].traditional_region].volume;
      }
      reachable_component_[a] =
          summaries_[a].traditional_region >= 0 ? graph.component[summaries_[a].traditional_region] : -1;
    }
    region_sets_.assign(regions.size(), 0);
    for (const Region& region : regions) {
      if (region.debris) continue;
      for (int a = 0; a < 2; ++a) {
        std::uint8_t& sets = region_sets_[region.id];
        if (region.sign == summaries_[a].sign) sets |= setBit(kMaximalSet, a);
        if (graph.component[region.id] == reachable_component_[a]) sets |= setBit(kReachableSet, a);
        if (region.id == summaries_[a].traditional_region) sets |= setBit(kTraditionalSet, a);
      }
    }
  }

  // The sets a cell is in by its centre (`inside`: its code is; labels[m] in each
  // working mode), and those the proofs show it wholly in or wholly out of: in a set
  // through a working mode whose sign is proven over the cell; out of every set when
  // proven outside; out of those it is not in when every working mode the set depends on
  // is proven.
  Membership membership(bool inside, bool proven_outside, const std::int32_t* labels, const CellProof& proof) const {
    Membership result;
    if (!inside) {
      if (proven_outside) result.proven_out = kEverySet;
      return result;
    }
    result.in = setBit(kWorkspaceSet);
    if (proof.assembly) result.proven_in = setBit(kWorkspaceSet);
    result.shares = !proof.assembly;
    for (int m = 0; m < mode_count_; ++m) {
      if (labels[m] < 0) continue;
      const std::uint8_t sets = region_sets_[labels[m]];
      result.in |= sets;
      if (proof.assembly && (proof.modes >> m & 1u)) result.proven_in |= sets;
    }
    if (proof.assembly && proof.modes == all_modes_) result.proven_out = kEverySet & ~result.in;
    for (int a = 0; a < 2; ++a) {
      const std::int32_t traditional = summaries_[a].traditional_region;
      if (traditional >= 0 && proof.assembly && (proof.modes >> regions_[traditional].mode & 1u)) {
        result.proven_out |= setBit(kTraditionalSet, a) & ~result.in;
      }
    }
    return result;
  }

  // `voxels` cells of one membership, of which each has `shares` proven assembled and not
  // (membership.shares; zeros otherwise). The part proven unassembled is out of every set,
  // the part proven assembled in the workspace (a region's set also needs a working mode's
  // sign proven there, which no proof of a cell not assembled whole gives). `set_shares`:
  // of a cell proven assembled, the shares proven in sets through a mode's sign (setShares).
  void add(const Membership& membership, std::uint64_t voxels, const AssemblyShares& shares = {},
           const SetShares& set_shares = {}) {
    for (int a = 0; a < 2; ++a) {
      summaries_[a].maximal_voxels += membership.in & setBit(kMaximalSet, a) ? voxels : 0;
      summaries_[a].reachable_voxels += membership.in & setBit(kReachableSet, a) ? voxels : 0;
    }
    const double cells = static_cast<double>(voxels);
    for (int k = 0; k < kSetCount; ++k) {
      if (!(membership.in >> k & 1u)) continue;
      if (membership.proven_in >> k & 1u) {
        counts_.proven[k] += cells;
        continue;
      }
      const double proven = std::max(set_shares[k], k == kWorkspaceSet && assembled_shares_ ? shares.assembled : 0.0);
      counts_.proven[k] += proven * cells;
      counts_.unproven[k] += std::max(0.0, 1.0 - proven - shares.unassembled) * cells;
    }
  }
  // The working modes of a cell proven assembled whose sign, proven over a share of it,
  // would prove that share in a maximal set the cell is in but not proven in. The other
  // sets take what these shares prove of them (setShares); asked for themselves too, they
  // would double the cells a certificate is made for (8.2 M against 4.5 M at 2 mm).
  std::uint64_t modesToShare(const Membership& membership, const std::int32_t* labels, const CellProof& proof) const {
    const std::uint8_t unproven = membership.in & ~membership.proven_in & (setBit(kMaximalSet) | setBit(kMaximalSet, 1));
    std::uint64_t modes = 0;
    if (!proof.assembly || unproven == 0) return modes;
    for (int m = 0; m < mode_count_; ++m) {
      if (labels[m] >= 0 && !(proof.modes >> m & 1u) && (region_sets_[labels[m]] & unproven) != 0) {
        modes |= std::uint64_t{1} << m;
      }
    }
    return modes;
  }
  // Per set, the largest share of a cell proven in it through one working mode (the
  // shares of two modes may overlap, so they do not add): mode_shares[m] of the cell where
  // mode m keeps the sign of its region labels[m].
  SetShares setShares(const std::int32_t* labels, const double* mode_shares) const {
    SetShares result{};
    for (int m = 0; m < mode_count_; ++m) {
      if (labels[m] < 0 || !(mode_shares[m] > 0.0)) continue;
      for (int k = 0; k < kSetCount; ++k) {
        if (region_sets_[labels[m]] >> k & 1u) result[k] = std::max(result[k], mode_shares[m]);
      }
    }
    return result;
  }
  // A cell beside the sets `beside`, `open` of it not proven out of them.
  void addBeside(std::uint8_t beside, double open) {
    for (int k = 0; k < kSetCount; ++k) counts_.beside[k] += beside >> k & 1u ? open : 0.0;
  }
  // Adds the cells another tally (a copy of this one, before any add) counted.
  void merge(const AssemblyModeTally& other) {
    for (int a = 0; a < 2; ++a) {
      summaries_[a].maximal_voxels += other.summaries_[a].maximal_voxels;
      summaries_[a].reachable_voxels += other.summaries_[a].reachable_voxels;
    }
    counts_.merge(other.counts_);
  }
  std::array<AssemblyModeSummary, 2> finish(double cell_volume, VolumeBounds* workspace) const {
    std::array<AssemblyModeSummary, 2> result = summaries_;
    for (int a = 0; a < 2; ++a) {
      AssemblyModeSummary& summary = result[a];
      summary.maximal_volume = static_cast<double>(summary.maximal_voxels) * cell_volume;
      summary.reachable_volume = static_cast<double>(summary.reachable_voxels) * cell_volume;
      summary.maximal_bounds = bounds(kMaximalSet + a, cell_volume);
      summary.traditional_bounds = bounds(kTraditionalSet + a, cell_volume);
      summary.reachable_bounds = bounds(kReachableSet + a, cell_volume);
    }
    *workspace = bounds(kWorkspaceSet, cell_volume);
    return result;
  }

 private:
  VolumeBounds bounds(int set, double cell_volume) const {
    VolumeBounds result;
    const double inner = counts_.proven[set], outer = inner + counts_.unproven[set] + counts_.beside[set];
    result.inner = inner * cell_volume;
    result.boundary = (outer - inner) * cell_volume;
    // In whole cells, rounded outward.
    result.inner_voxels = static_cast<std::uint64_t>(std::floor(inner));
    result.boundary_voxels = static_cast<std::uint64_t>(std::ceil(outer)) - result.inner_voxels;
    return result;
  }
  void countRegions(AssemblyModeSummary& summary) const {
    std::vector<bool> component_seen;
    for (const Region& region : regions_) {
      if (region.sign != summary.sign) continue;
      (region.debris ? summary.debris_regions : summary.regions)++;
      const std::int32_t component = graph_.component[region.id];
      if (component >= static_cast<std::int32_t>(component_seen.size())) component_seen.resize(component + 1, false);
      if (!region.debris && !component_seen[component]) {
        component_seen[component] = true;
        summary.components++;
      }
    }
    for (const Transition& transition : graph_.transitions) {
      summary.transitions += transition.sign == summary.sign && !regions_[transition.from_region].debris &&
                             !regions_[transition.to_region].debris;
    }
  }
  std::int32_t traditionalRegion(std::int8_t sign, const std::int32_t* start_labels, int start_mode) const {
    const std::int32_t own = start_labels[start_mode];
    if (own >= 0 && regions_[own].sign == sign) return own;
    std::int32_t best = -1;
    for (int m = 0; m < mode_count_; ++m) {
      const std::int32_t label = start_labels[m];
      if (label >= 0 && regions_[label].sign == sign && (best < 0 || regions_[label].voxels > regions_[best].voxels)) {
        best = label;
      }
    }
    return best;
  }

  const std::vector<Region>& regions_;
  const TransitionGraph& graph_;
  int mode_count_;
  bool assembled_shares_;
  std::uint64_t all_modes_;
  std::array<AssemblyModeSummary, 2> summaries_;
  std::array<std::int32_t, 2> reachable_component_{};
  std::vector<std::uint8_t> region_sets_;  // per region: the sets a cell of it is in
  SetCounts counts_;
};

// Each working mode's label of the cells of one block at a time.
class BlockLabels {
 public:
  BlockLabels(const AnalysisData& data) : data_(data), modes_(static_cast<int>(data.modes.size())), pages_(modes_),
                                          local_labels_(modes_), labels_(modes_) {}
  // Reads block b; true when every layer is uniform over it (labels() holds them).
  bool load(std::uint64_t b) {
    bool uniform = true;
    for (int m = 0; m < modes_; ++m) {
      const LabelLayer& layer = data_.regions.layers[m];
      local_labels_[m] = layer.uniform(b) ? nullptr : layer.localLabels(b);
      if (local_labels_[m] != nullptr) pages_[m] = layer.localPage(b);
      labels_[m] = layer.label(b, 0);
      uniform = uniform && local_labels_[m] == nullptr;
    }
    return uniform;
  }
  // The labels at cell c of the block loaded.
  const std::int32_t* at(int c) {
    for (int m = 0; m < modes_; ++m) {
      if (local_labels_[m] == nullptr) continue;
      const std::uint16_t local = pages_[m][c];
      labels_[m] = local == LabelLayer::kNoLocal ? kNoLabel : local_labels_[m][local];
    }
    return labels_.data();
  }
  const std::vector<std::int32_t>& labels() const { return labels_; }

 private:
  const AnalysisData& data_;
  const int modes_;
  std::vector<LabelLayer::LocalPage> pages_;  // local components where a layer is not uniform
  std::vector<const std::int32_t*> local_labels_;
  std::vector<std::int32_t> labels_;
};

// Adds the cells of blocks to a tally: each workspace cell to the sets it is in, proven
// or not, and each cell not proven out of a set it is not in but faces (the exact set may
// reach into it). Where a cell is not proven assembled or out as a whole, `certificate`
// (when given) proves shares of it (AssemblyShares).
class BlockTally {
 public:
  BlockTally(const AnalysisData& data, const MeasureCertificate* certificate, AssemblyModeTally& tally)
      : data_(data), cells_(data.cells), layout_(data.cells.layout), certificate_(certificate), tally_(tally),
        block_labels_(data), neighbour_labels_(data), members_(layout_.cellsPerBlock()), labels_(data.modes.size()),
        shares_(layout_.cellsPerBlock()), mode_shares_(data.modes.size()), share_modes_(layout_.cellsPerBlock()),
        last_labels_(data.modes.size()) {
    for (int c = 0; c < layout_.cellsPerBlock(); ++c) {
      if (onFaces(layout_, c, ~0u)) face_cells_.push_back(c);
    }
    // Signs' shares come from the factorised path's certificates, over translations only
    // (its limits, where a robot has some, are not proven over shares).
    sign_shares_ = certificate_ != nullptr && !certificate_->hasLimits() && certificate_->factorises() &&
                   layout_.side() % kShareCubeSide == 0;
    int share_cubes = 1;
    const GridCell origin = layout_.cellCoords(0, 0);
    for (int d = 0; d < layout_.dims(); ++d) {
      share_cubes *= layout_.side() / kShareCubeSide + 1;
      share_phase_[d] = static_cast<int>((origin[d] % kShareCubeSide + kShareCubeSide) % kShareCubeSide);
    }
    cube_modes_.assign(share_cubes, 0);
    for (int d = 0; d < data_.grid.dims(); ++d) {
      sign_shares_ = sign_shares_ && static_cast<int>(data_.grid.variable(d)) < 3;
    }
  }

  void add(std::uint64_t first, std::uint64_t end) {
    for (std::uint64_t b = first; b < end; ++b) {
      if (uniformBlock(b, block_labels_)) {
        const Membership member = membership(b, 0, block_labels_.labels().data());
        if (!needsShare(member)) {
          addUniform(b, member);
          continue;
        }
      }
      addCells(b);
      for (int c = 0; c < layout_.cellsPerBlock(); ++c) addBeside(b, c, false);
    }
  }

 private:
  // A block of one code, one label per mode and one proof: its cells share their
  // membership, so only neighbours in other blocks can add any.
  bool uniformBlock(std::uint64_t b, BlockLabels& labels_of) {
    return labels_of.load(b) && cells_.codes.uniform(b) && (cells_.proven.allProven(b) || cells_.proven.noneProven(b));
  }

  // The membership of a cell of block b, whose labels are `at`.
  Membership membership(std::uint64_t b, int c, const std::int32_t* at) const {
    const CellCode code = cells_.codes.code(b, c);
    const CellProof proof = cells_.proven.proof(b, c);
    return tally_.membership(codeInside(code), provenOutside(code, proof), at, proof);
  }
  // Outside or blocked (every working mode breaking a limit) over the whole cell.
  static bool provenOutside(CellCode code, const CellProof& proof) {
    return (code == kCodeOutside || code == kCodeBlocked) && proof.assembly;
  }

  // The sets of a cell of another block.
  std::uint8_t setsOf(std::uint64_t b, int c) {
    if (!codeInside(cells_.codes.code(b, c))) return 0;
    for (std::size_t m = 0; m < labels_.size(); ++m) labels_[m] = data_.regions.label(b, c, static_cast<int>(m));
    return membership(b, c, labels_.data()).in;
  }

  // Whether a cell of this membership is in a set it is not proven in, but shares of it
  // may be proven.
  bool needsShare(const Membership& member) const {
    return certificate_ != nullptr && member.shares && (member.in & ~member.proven_in) != 0;
  }

  // The shares of cell c of block b proven assembled and not: computed once a cell.
  // Only the chains that may fail to assemble somewhere in the block are enclosed over its
  // cells (most cells near the workspace's boundary are near one chain's reach only).
  const AssemblyShares& sharesOf(std::uint64_t b, int c) {
    if (shares_block_ != b) {
      shares_block_ = b;
      for (CellShares& cell : shares_) cell.known = false;
      GridCell first = layout_.cellCoords(b, 0), last = layout_.cellCoords(b, layout_.cellsPerBlock() - 1);
      for (int d = 0; d < layout_.dims(); ++d) {
        first[d] = std::max<std::int64_t>(first[d], 0);
        last[d] = std::min<std::int64_t>(last[d], data_.grid.size(d) - 1);
      }
      // Proven outside over the block (no cell then asks): every chain stays.
      block_chains_ = ~0u;
      certificate_->assemblyOf(data_.grid.cellsBox(first, last), ~0u, &block_chains_);
    }
    CellShares& cell = shares_[c];
    if (!cell.known) {
      const GridCell coords = layout_.cellCoords(b, c);
      cell.shares = certificate_->assemblyShares(data_.grid.cellsBox(coords, coords), block_chains_);
      cell.known = true;
    }
    return cell.shares;
  }

  // Per working mode of `modes`, the share of cell c of block b where the mode keeps the
  // sign of the cell's centre (0 for the others), from the certificate of its aligned cube
  // of kShareCubeSide cells a side, made once for the cells of the cube that need it, for
  // the modes any of them asks (cube_modes_). The enclosures widen fast with the box: at 2
  // mm the maximal + band is 1.15 % with a certificate a cell, 1.68 % a 2-cell cube, 2.63 %
  // a 4-cell cube (docs/benchmarks.md).
  const double* signSharesOf(std::uint64_t b, int c, std::uint64_t modes) {
    if (cubes_block_ != b) {
      cubes_block_ = b;
      cube_certificates_.clear();
    }
    const GridCell coords = layout_.cellCoords(b, c);
    GridCell first = coords, last = coords;
    for (int d = 0; d < layout_.dims(); ++d) {
      first[d] = coords[d] - coords[d] % kShareCubeSide;
      last[d] = std::min<std::int64_t>(first[d] + kShareCubeSide - 1, data_.grid.size(d) - 1);
    }
    auto found = cube_certificates_.find(first);
    if (found == cube_certificates_.end()) {
      const std::uint64_t asked = cube_modes_[shareCube(c)];
      // Only a certificate that bounds the variation gives shares: slopes alone (at 2 mm,
      // 102 k of the 341 k cubes are assembled with some rod's rate unbounded).
      const PoseBox box = data_.grid.cellsBox(first, last);
      found = cube_certificates_.emplace(first, certificate_->certify(box, asked, true)).first;
    }
    const BoxCertificate& cube = found->second;
    std::fill(mode_shares_.begin(), mode_shares_.end(), 0.0);
    if (cube.assembly != BoxAssembly::Inside || !cube.boundsVariation()) return mode_shares_.data();
    const PoseBox cell = data_.grid.cellsBox(coords, coords);
    for (std::size_t m = 0; m < mode_shares_.size(); ++m) {
      if (modes >> m & 1u) mode_shares_[m] = cube.shareKeepingSign(m, cell, data_.settings.margin);
    }
    return mode_shares_.data();
  }
  // The index of cell c's share cube among those that meet its block (up to side /
  // kShareCubeSide + 1 a variable). Blocks start kShareCubeSide-aligned but for the grid's
  // padding, the same for all: share_phase_.
  int shareCube(int c) const {
    int cube = 0;
    for (int d = 0; d < layout_.dims(); ++d) {
      cube = cube * (layout_.side() / kShareCubeSide + 1) + (layout_.cellCoord(c, d) + share_phase_[d]) / kShareCubeSide;
    }
    return cube;
  }

  // A uniform block of membership `member` (uniformBlock has loaded its labels into
  // block_labels_).
  void addUniform(std::uint64_t b, const Membership& member) {
    tally_.add(member, static_cast<std::uint64_t>(layout_.cellsPerBlock()));
    const std::uint8_t open = kEverySet & ~(member.in | member.proven_out);
    if (open == 0) return;
    // Beside a uniform block whose sets are none of the open ones, no face cell has any.
    const unsigned faces = facesToScan(layout_, b, [&](std::uint64_t other) {
      return !uniformBlock(other, neighbour_labels_) ||
             (membership(other, 0, neighbour_labels_.labels().data()).in & open) != 0;
    });
    if (faces == 0) return;
    std::fill(members_.begin(), members_.end(), member);
    for (int c : face_cells_) {
      if (onFaces(layout_, c, faces)) addBeside(b, c, true);
    }
  }

  // The cells of a block that is not uniform, into members_ and the tally. Neighbouring
  // cells mostly share their membership: added a run at a time, in the one pass that
  // computes them. The cells that ask for shares are added after it, once the modes their
  // share cubes need are all gathered (cube_modes_).
  void addCells(std::uint64_t b) {
    std::fill(cube_modes_.begin(), cube_modes_.end(), 0);
    share_cells_.clear();
    const std::size_t modes = last_labels_.size();
    Membership run;
    std::uint64_t run_cells = 0;
    bool asks = false;  // whether the last membership computed asks for shares
    for (int c = 0; c < layout_.cellsPerBlock(); ++c) {
      const std::int32_t* labels = block_labels_.at(c);
      const CellCode code = cells_.codes.code(b, c);
      const CellProof proof = cells_.proven.proof(b, c);
      // A cell of the previous one's code, proof and labels shares its membership (most
      // cells of a block do; 1.9 s of CPU a cell at a time at 2 mm). A loop: std::equal
      // calls memcmp, for 8 labels at a time.
      bool same = c > 0 && code == last_code_ && proof.assembly == last_proof_.assembly &&
                  proof.modes == last_proof_.modes;
      for (std::size_t m = 0; same && m < modes; ++m) same = labels[m] == last_labels_[m];
      if (same) {
        members_[c] = members_[c - 1];
        share_modes_[c] = share_modes_[c - 1];
      } else {
        last_code_ = code, last_proof_ = proof;
        std::copy(labels, labels + modes, last_labels_.begin());
        members_[c] = tally_.membership(codeInside(code), provenOutside(code, proof), labels, proof);
        const bool whole = needsShare(members_[c]);
        const bool shared = code != kCodeVoid && sign_shares_ && !whole;
        share_modes_[c] = shared ? tally_.modesToShare(members_[c], labels, proof) : 0;
        asks = code != kCodeVoid && (whole || share_modes_[c] != 0);
      }
      if (code == kCodeVoid) continue;
      if (asks) {
        share_cells_.push_back(c);
        if (share_modes_[c] != 0) cube_modes_[shareCube(c)] |= share_modes_[c];
        continue;
      }
      if (run_cells > 0 && !(members_[c] == run)) tally_.add(run, run_cells), run_cells = 0;
      run = members_[c];
      ++run_cells;
    }
    if (run_cells > 0) tally_.add(run, run_cells);
    for (int c : share_cells_) {
      if (needsShare(members_[c])) {
        tally_.add(members_[c], 1, sharesOf(b, c));
        continue;
      }
      const double* mode_shares = signSharesOf(b, c, share_modes_[c]);
      tally_.add(members_[c], 1, {}, tally_.setShares(block_labels_.at(c), mode_shares));
    }
  }

  // The sets cell c of block b (its membership in members_) is beside but not in.
  void addBeside(std::uint64_t b, int c, bool uniform) {
    const std::uint8_t open = kEverySet & ~(members_[c].in | members_[c].proven_out);
    // Padding beyond the box is no part of any set.
    if (open == 0 || cells_.codes.code(b, c) == kCodeVoid) return;
    const int dims = layout_.dims(), bits = layout_.sideBits(), last = layout_.side() - 1;
    std::uint8_t beside = 0;
    for (int d = 0; d < dims; ++d) {
      const int shift = (dims - 1 - d) * bits, at = c >> shift & last;
      for (int direction : {-1, 1}) {
        // Inside the block: the neighbour is in members_ (of the same membership when uniform).
        if (direction < 0 ? at > 0 : at < last) {
          if (!uniform) beside |= members_[c + direction * (1 << shift)].in & open;
          continue;
        }
        std::uint64_t nb = 0;
        int nc = 0;
        if (!layout_.neighbour(b, c, d, direction, &nb, &nc)) continue;
        beside |= (nb == b ? members_[nc].in : setsOf(nb, nc)) & open;
      }
    }
    if (beside == 0) return;
    const bool whole = certificate_ == nullptr || cells_.proven.proof(b, c).assembly;
    tally_.addBeside(beside, whole ? 1.0 : 1.0 - sharesOf(b, c).unassembled);
  }

  const AnalysisData& data_;
  const WorkspaceCells& cells_;
  const BlockLayout& layout_;
  const MeasureCertificate* certificate_;
  AssemblyModeTally& tally_;
  BlockLabels block_labels_, neighbour_labels_;
  std::vector<Membership> members_;
  std::vector<std::int32_t> labels_;
  std::vector<int> face_cells_;  // the cells on a block's faces
  struct CellShares {
    AssemblyShares shares;
    bool known = false;
  };
  std::vector<CellShares> shares_;  // of the cells of block shares_block_
  std::uint64_t shares_block_ = ~std::uint64_t{0};
  std::uint32_t block_chains_ = ~0u;  // of block shares_block_: those that may not assemble
  static constexpr int kShareCubeSide = 2;
  bool sign_shares_ = false;
  std::map<GridCell, BoxCertificate> cube_certificates_;  // of block cubes_block_, by first cell
  std::uint64_t cubes_block_ = ~std::uint64_t{0};
  std::vector<double> mode_shares_;
  std::vector<std::uint64_t> share_modes_;  // per cell of the block in hand: modes it asks shares of
  std::vector<std::uint64_t> cube_modes_;   // per share cube of that block: their union
  std::vector<int> share_cells_;            // addCells's cells that ask for shares
  // addCells's last cell whose membership it computed.
  CellCode last_code_ = kCodeVoid;
  CellProof last_proof_;
  std::vector<std::int32_t> last_labels_;
  int share_phase_[kMaxGridDims] = {};       // where blocks start in the share cubes (shareCube)
};

}  // namespace

std::array<AssemblyModeSummary, 2> summariseAssemblyModes(const AnalysisData& data, const MeasureCertificate* certificate,
                                                          int threads, VolumeBounds* workspace_bounds,
                                                          const std::function<void(double)>& progress) {
  const WorkspaceCells& cells = data.cells;
  const int modes = static_cast<int>(data.modes.size());
  std::vector<std::int32_t> start_labels(modes);
  for (int m = 0; m < modes; ++m) start_labels[m] = data.regions.label(cells.start_block, cells.start_cell, m);
  const bool assembled_shares = certificate != nullptr && !certificate->hasLimits();
  const AssemblyModeTally total(data.regions.regions, data.transitions, start_labels.data(), data.start_mode, modes,
                                assembled_shares);
  // Fixed chunks of blocks, each with its own copy of the tally, merged in order.
  const std::uint64_t blocks = cells.layout.blockCount();
  const std::size_t chunks = static_cast<std::size_t>(std::min<std::uint64_t>(blocks, 64));
  std::vector<AssemblyModeTally> tallies(chunks, total);
  ItemProgress chunks_done(progress, chunks);
  parallelForEach(chunks, threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t chunk = begin; chunk < end; ++chunk) {
      const std::uint64_t first = blocks * chunk / chunks, last = blocks * (chunk + 1) / chunks;
      BlockTally(data, certificate, tallies[chunk]).add(first, last);
      chunks_done.finished();
    }
  });
  AssemblyModeTally merged = total;
  for (const AssemblyModeTally& tally : tallies) merged.merge(tally);
  return merged.finish(data.grid.cellVolume(), workspace_bounds);
}

}  // namespace maximal_workspace
