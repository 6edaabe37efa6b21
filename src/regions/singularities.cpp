#include "regions/singularities.h"

#include <atomic>
#include <algorithm>
#include <bitset>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "workspace/parallel.h"

namespace maximal_workspace {

DkpScan::DkpScan(const WorkspaceCells& cells)
    : cells_(cells),
      positive_(cells.patterns.patterns.size()),
      negative_(cells.patterns.patterns.size()),
      blocked_(cells.patterns.patterns.size()) {
  const SignPatterns& patterns = cells.patterns;
  for (CellCode code = 0; code < patterns.patterns.size(); ++code) {
    for (int m = 0; m < patterns.modes; ++m) {
      const int sign = patterns.sign(code, m);
      if (sign > 0) positive_[code] |= std::uint64_t{1} << m;
      if (sign < 0) negative_[code] |= std::uint64_t{1} << m;
      if (patterns.blocked(code, m)) blocked_[code] |= std::uint64_t{1} << m;
    }
  }
  all_ = patterns.modes >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << patterns.modes) - 1;
}

// The singular modes of one workspace cell: its band, and sign changes across its faces.
// Neighbours within the block are read from its page (or are the block's own code); only
// those across a block face are looked up.
std::uint64_t DkpScan::singularModes(std::uint64_t block, int cell, CellCode code, const CodeMap::Page& page) const {
  const BlockLayout& layout = cells_.layout;
  const int mask = layout.side() - 1;
  std::uint64_t modes = band(code);
  for (int d = 0; d < layout.dims(); ++d) {
    const int shift = (layout.dims() - 1 - d) * layout.sideBits();
    const int at = cell >> shift & mask;
    for (int direction : {-1, 1}) {
      CellCode other = code;
      if (at + direction >= 0 && at + direction <= mask && !layout.periodic(d)) {
        if (!page.empty()) other = page[cell + direction * (1 << shift)];
      } else {
        std::uint64_t other_block = 0;
        int other_cell = 0;
        if (!layout.neighbour(block, cell, d, direction, &other_block, &other_cell)) continue;
        other = cells_.codes.code(other_block, other_cell);
      }
      if (other != code && codeInside(other)) modes |= opposite(code, other);
    }
  }
  return modes;
}

void DkpScan::scan(std::uint64_t first_block, std::uint64_t end_block,
                   const std::function<void(std::uint64_t, int, std::uint64_t)>& found) const {
  const BlockLayout& layout = cells_.layout;
  for (std::uint64_t block = first_block; block < end_block; ++block) {
    const bool uniform = cells_.codes.uniform(block);
    if (uniform && !codeInside(cells_.codes.uniformCode(block))) continue;
    // Inside a uniform block every cell has the block's band and no sign change: only its
    // side cells can meet another code, on the faces where a neighbour may hold one.
    const bool interior_plain = uniform && band(cells_.codes.uniformCode(block)) == 0;
    unsigned faces = 0;
    if (interior_plain) {
      const CellCode code = cells_.codes.uniformCode(block);
      faces = facesMeetingCodes(layout, cells_.codes, block,
                                [&](CellCode other) { return codeInside(other) && opposite(code, other) != 0; });
      if (faces == 0) continue;
    }
    const CodeMap::Page page = uniform ? CodeMap::Page() : cells_.codes.page(block);
    for (int c = 0; c < layout.cellsPerBlock(); ++c) {
      if (interior_plain && !onFaces(layout, c, faces)) continue;
      const CellCode code = !page.empty() ? page[c] : cells_.codes.uniformCode(block);
      if (!codeInside(code)) continue;
      const std::uint64_t modes = singularModes(block, c, code, page);
      if (modes != 0) found(block, c, modes);
    }
  }
}

std::uint64_t countDkpEntries(const WorkspaceCells& cells, int threads, const CancelCheck& cancelled) {
  const DkpScan dkp(cells);
  const std::uint64_t blocks = cells.layout.blockCount();
  const std::size_t chunks = static_cast<std::size_t>(std::min<std::uint64_t>(blocks, 256));
  std::atomic<std::uint64_t> total{0};
  parallelForEach(chunks, threads, [&](std::size_t begin, std::size_t end) {
    std::uint64_t count = 0;
    for (std::size_t chunk = begin; chunk < end; ++chunk) {
      throwIfCancelled(cancelled);
      dkp.scan(blocks * chunk / chunks, blocks * (chunk + 1) / chunks,
               [&](std::uint64_t, int, std::uint64_t modes) { count += std::bitset<64>(modes).count(); });
    }
    total += count;
  });
  return total;
}

WallScan::WallScan(const WorkspaceCells& cells)
    : cells_(cells), admissible_(cells.patterns.patterns.size()), blocked_(cells.patterns.patterns.size()) {
  const SignPatterns& patterns = cells.patterns;
  all_ = patterns.modes >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << patterns.modes) - 1;
  for (CellCode code = 0; code < patterns.patterns.size(); ++code) {
    for (int m = 0; m < patterns.modes; ++m) {
      if (patterns.blocked(code, m)) blocked_[code] |= std::uint64_t{1} << m;
    }
    admissible_[code] = all_ & ~blocked_[code];
    any_ = any_ || blocked_[code] != 0;
  }
  const CodeMap& codes = cells.codes;
  for (std::uint64_t b = 0; b < codes.blockCount() && !any_; ++b) {
    any_ = codes.holds(b, kCodeBlocked);
  }
}

std::uint64_t WallScan::walled(CellCode from, CellCode to) const {
  if (to == kCodeBlocked) return admissible_[from];
  return codeInside(to) ? admissible_[from] & blocked_[to] : 0;
}

void WallScan::scan(std::uint64_t first_block, std::uint64_t end_block,
                    const std::function<void(std::uint64_t, int, int, int, std::uint64_t)>& found) const {
  if (!any_) return;
  const BlockLayout& layout = cells_.layout;
  for (std::uint64_t block = first_block; block < end_block; ++block) {
    const bool uniform = cells_.codes.uniform(block);
    if (uniform && !codeInside(cells_.codes.uniformCode(block))) continue;
    // Inside a uniform block neighbours share the code: only its side cells can meet a
    // wall, on the faces where a neighbour may hold one.
    unsigned faces = 0;
    if (uniform) {
      const CellCode code = cells_.codes.uniformCode(block);
      faces = facesMeetingCodes(layout, cells_.codes, block, [&](CellCode other) { return walled(code, other) != 0; });
      if (faces == 0) continue;
    }
    for (int c = 0; c < layout.cellsPerBlock(); ++c) {
      if (uniform && !onFaces(layout, c, faces)) continue;
      const CellCode code = cells_.codes.code(block, c);
      if (!codeInside(code)) continue;
      for (int d = 0; d < layout.dims(); ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t other_block = 0;
          int other_cell = 0;
          if (!layout.neighbour(block, c, d, direction, &other_block, &other_cell)) continue;
          const std::uint64_t modes = walled(code, cells_.codes.code(other_block, other_cell));
          if (modes != 0) found(block, c, d, direction, modes);
        }
      }
    }
  }
}

void countWallEntries(const RobotModel& model, const Grid& grid, const std::vector<WorkingMode>& modes,
                      const WorkspaceCells& cells, int threads, SingularityCounts* counts, const CancelCheck& cancelled) {
  const RobotConstraints constraints(model);
  if (!constraints.active()) return;  // no limit, no wall: not even a scan
  const WallScan walls(cells);
  if (!walls.any()) return;
  const BlockLayout& layout = cells.layout;
  const std::uint64_t blocks = layout.blockCount();
  const std::size_t chunks = static_cast<std::size_t>(std::min<std::uint64_t>(blocks, 256));
  std::atomic<std::uint64_t> by_kind[3] = {{0}, {0}, {0}};
  parallelForEach(chunks, threads, [&](std::size_t begin, std::size_t end) {
    std::uint64_t found[3] = {0, 0, 0};
    std::vector<WallLimit> wall_limits(modes.size());
    const auto count = [&](std::uint64_t block, int cell, int d, int direction, std::uint64_t walled) {
      // The limit broken at the centre of the cell across the face.
      Pose across = grid.pose(layout.gridIndex(block, cell));
      grid.move(&across, d, direction * grid.step(d));
      const IkpResult ikp = solveIkp(model, across);
      if (ikp.assembled) constraints.walls(across, ikp, modes, walled, wall_limits.data());
      for (std::size_t m = 0; m < modes.size(); ++m) {
        if (!(walled >> m & 1)) continue;
        const ConstraintKind kind = ikp.assembled ? wall_limits[m].kind : ConstraintKind::InputRange;
        ++found[kind == ConstraintKind::JointCone ? 1 : kind == ConstraintKind::Interference ? 2 : 0];
      }
    };
    for (std::size_t chunk = begin; chunk < end; ++chunk) {
      throwIfCancelled(cancelled);
      walls.scan(blocks * chunk / chunks, blocks * (chunk + 1) / chunks, count);
    }
    for (int k = 0; k < 3; ++k) by_kind[k] += found[k];
  });
  counts->limit_entries = by_kind[0];
  counts->cone_entries = by_kind[1];
  counts->interference_entries = by_kind[2];
}

}  // namespace maximal_workspace
