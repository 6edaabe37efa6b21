#pragma once
// The determinants of all working modes' matrices at once, for a block of poses. Row c of
// a working mode's n x n matrix is chain c's row in that mode's branch, so the 2^n matrices
// of a pose (fewer when only some modes are wanted) share their leading rows. The
// determinant is expanded along its rows in chain order: the minors of rows 0..k-1 on
// every set of k columns depend only on the branches of chains 0..k-1, and each minor of
// rows 0..k is a signed sum of row k's entries times minors of rows 0..k-1. A depth-first
// walk of the branch tree keeps one set of minors per depth and visits only the prefixes
// of wanted modes.
//
// Why expansion and not a shared elimination: pivoting is what keeps an LU stable, and a
// pivot chosen in one branch combination would have to serve its whole subtree, or be
// chosen per pose (data-dependent, which does not vectorise). Expansion needs neither
// pivots nor divisions. Given rows of unit norm (as the singularity measure's are), every
// minor is at most 1 in magnitude (Hadamard), and a minor of k rows carries the error of
// the minors it sums times at most sqrt(k) (the row's entries) plus k roundings: for
// n = 6 under 1e-13 at worst, and within 2e-14 of a full-pivot LU in the tests and the
// benchmark. That is an absolute error on a measure in [-1, 1], which is what the
// singular band thresholds; and the loops are branch-free, so the compiler vectorises them.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

// Poses per block of the generic path: rows, minors and the classifier's other scratch
// (174 arrays of a block, 44 KB) are about the size of L1. Blocks of 16 and 64 were slower.
constexpr std::size_t kModeBlock = 32;

// rows[c][b][j][i]: column j of chain c's row in branch b (0: p, 1: n) at pose i.
using BranchRows = double[kMaxChains][2][kMaxChains][kModeBlock];

// One term of a minor of rows 0..k: row k's entry in `column` times the minor of rows
// 0..k-1 on the other columns (index `minor` within its depth). Terms come in increasing
// column order, so their signs alternate and the last is +.
struct MinorTerm {
  int column = 0;
  int minor = 0;
};

class ModeDeterminants {
 public:
  // `size`: the order n of the matrices (chains = columns). `negative_chains`: per wanted
  // mode, bit c set when chain c takes branch n.
  ModeDeterminants(int size, const std::vector<std::uint32_t>& negative_chains);

  // out[i * stride + m]: the determinant of mode m's matrix at pose i, for i < count.
  void determinants(std::size_t count, const BranchRows& rows, double* out, std::size_t stride) const;

 private:
  // Appending chain `chain`'s row in `branch` to the minors at its depth; at the last
  // depth, the modes whose determinant that is.
  struct Step {
    int chain = 0;
    int branch = 0;
    std::vector<int> modes;
  };

  void addSteps(std::uint32_t prefix, int depth, const std::vector<std::uint32_t>& negative_chains);

  int size_ = 0;
  // Per depth k: where its minors start in the scratch, and the terms of each of its
  // C(n, k) minors (k terms each).
  std::vector<int> level_offset_;
  std::vector<std::vector<MinorTerm>> level_terms_;
  std::vector<Step> steps_;  // depth-first order
};

}  // namespace maximal_workspace
