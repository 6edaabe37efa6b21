#include "maximal_workspace/model/chain.h"

namespace maximal_workspace {

char branchLetter(Branch branch) { return branch == Branch::Positive ? 'p' : 'n'; }

ChainSolution Chain::solve(const Eigen::Vector3d& p) const {
  const ChainNodes nodes = intermediateNodes(p);
  ChainSolution solution;
  solution.discriminant = nodes.discriminant;
  solution.assembled = nodes.assembled;
  if (nodes.assembled) {
    for (int b = 0; b < 2; ++b) solution.branches[b] = ChainBranch{inputOf(nodes.a[b]), nodes.a[b]};
  }
  return solution;
}

const char* inputUnit(InputKind kind) { return kind == InputKind::Prismatic ? "m" : "rad"; }

}  // namespace maximal_workspace
