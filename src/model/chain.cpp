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

void Chain::intermediateNodes(const PointBatch& points, const NodeBatch& nodes) const {
  for (std::size_t i = 0; i < points.count; ++i) {
    const ChainNodes one = intermediateNodes(Eigen::Vector3d(points.x[i], points.y[i], points.z[i]));
    nodes.discriminant[i] = one.discriminant;
    for (int b = 0; b < 2; ++b) {
      const Eigen::Vector3d a = one.assembled ? one.a[b] : Eigen::Vector3d::Zero();
      nodes.x[b][i] = a.x();
      nodes.y[b][i] = a.y();
      nodes.z[b][i] = a.z();
    }
  }
}

const char* inputUnit(InputKind kind) { return kind == InputKind::Prismatic ? "m" : "rad"; }

}  // namespace maximal_workspace
