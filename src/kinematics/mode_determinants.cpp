#include "kinematics/mode_determinants.h"

#include <algorithm>
#include <bitset>

#include "model/vector_kernel.h"

namespace maximal_workspace {

namespace {

using BlockArray = double[kModeBlock];

// The minors of rows 0..Order-1 from row Order-1 and the minors of the rows above it, over
// a block. Order is a template argument so that each minor's terms stay in registers and
// their alternating signs are known; inlined into the vectorised kernel below.
template <int Order>
[[gnu::always_inline]] inline void expandMinorsOf(std::size_t count, const MinorTerm* __restrict terms, int minors,
                                                  const BlockArray* __restrict row, const BlockArray* __restrict above,
                                                  BlockArray* __restrict out) {
  for (int o = 0; o < minors; ++o, terms += Order) {
    int column[Order], minor[Order];
    for (int t = 0; t < Order; ++t) {
      column[t] = terms[t].column;
      minor[t] = terms[t].minor;
    }
    for (std::size_t i = 0; i < count; ++i) {
      double sum = 0.0;
      for (int t = 0; t < Order; ++t) {
        const double product = row[column[t]][i] * above[minor[t]][i];
        sum = (Order - 1 - t) % 2 == 0 ? sum + product : sum - product;
      }
      out[o][i] = sum;
    }
  }
}

MOW_VECTOR_KERNEL void expandMinors(std::size_t count, int order, const MinorTerm* terms, int minors,
                                    const BlockArray* row, const BlockArray* above, BlockArray* out) {
  switch (order) {
    case 1: return expandMinorsOf<1>(count, terms, minors, row, above, out);
    case 2: return expandMinorsOf<2>(count, terms, minors, row, above, out);
    case 3: return expandMinorsOf<3>(count, terms, minors, row, above, out);
    case 4: return expandMinorsOf<4>(count, terms, minors, row, above, out);
    case 5: return expandMinorsOf<5>(count, terms, minors, row, above, out);
    default: return expandMinorsOf<6>(count, terms, minors, row, above, out);
  }
}

int bitCount(std::uint32_t bits) { return static_cast<int>(std::bitset<32>(bits).count()); }

}  // namespace

ModeDeterminants::ModeDeterminants(int size, const std::vector<std::uint32_t>& negative_chains) : size_(size) {
  // Column sets as bit masks; a minor's index within its depth is its mask's rank among
  // the masks with as many bits.
  const std::uint32_t sets = 1u << size;
  std::vector<int> rank(sets);
  std::vector<int> per_depth(size + 1, 0);
  for (std::uint32_t mask = 0; mask < sets; ++mask) rank[mask] = per_depth[bitCount(mask)]++;
  level_offset_.assign(size + 2, 0);
  for (int k = 0; k <= size; ++k) level_offset_[k + 1] = level_offset_[k] + per_depth[k];
  level_terms_.resize(size + 1);
  for (std::uint32_t mask = 0; mask < sets; ++mask) {
    for (int column = 0; column < size; ++column) {
      const std::uint32_t bit = 1u << column;
      if (mask & bit) level_terms_[bitCount(mask)].push_back(MinorTerm{column, rank[mask ^ bit]});
    }
  }
  addSteps(0, 0, negative_chains);
}

void ModeDeterminants::addSteps(std::uint32_t prefix, int depth, const std::vector<std::uint32_t>& negative_chains) {
  const std::uint32_t depth_mask = (2u << depth) - 1;  // chains 0..depth
  for (int branch = 0; branch < 2; ++branch) {
    const std::uint32_t extended = prefix | (static_cast<std::uint32_t>(branch) << depth);
    Step step{depth, branch, {}};
    bool wanted = false;
    for (std::size_t m = 0; m < negative_chains.size(); ++m) {
      if ((negative_chains[m] & depth_mask) != extended) continue;
      wanted = true;
      if (depth + 1 == size_) step.modes.push_back(static_cast<int>(m));
    }
    if (!wanted) continue;
    steps_.push_back(std::move(step));
    if (depth + 1 < size_) addSteps(extended, depth + 1, negative_chains);
  }
}

void ModeDeterminants::determinants(std::size_t count, const BranchRows& rows, double* out, std::size_t stride) const {
  // Minors of every depth, one set per depth: the walk overwrites a depth's set when it
  // moves to a sibling branch.
  BlockArray minors[1u << kMaxChains];
  std::fill(minors[0], minors[0] + count, 1.0);  // the empty minor
  for (const Step& step : steps_) {
    const int depth = step.chain + 1;
    expandMinors(count, depth, level_terms_[depth].data(), level_offset_[depth + 1] - level_offset_[depth],
                 rows[step.chain][step.branch], minors + level_offset_[step.chain], minors + level_offset_[depth]);
    const double* determinant = minors[level_offset_[size_]];
    for (const int m : step.modes) {
      for (std::size_t i = 0; i < count; ++i) out[i * stride + m] = determinant[i];
    }
  }
}

}  // namespace maximal_workspace
