#include "maximal_workspace/kinematics/inverse_kinematics.h"

#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

IkpResult solveIkp(const RobotModel& model, const Pose& pose) {
  IkpResult result;
  result.chain_count = model.chainCount();
  result.assembled = true;
  const Eigen::Matrix3d rotation = pose.rotation();
  for (int c = 0; c < result.chain_count; ++c) {
    result.platform_nodes[c] = pose.position + rotation * model.chains[c]->platformNode();
    result.chains[c] = model.chains[c]->solve(result.platform_nodes[c]);
    result.assembled = result.assembled && result.chains[c].assembled;
  }
  return result;
}

Configuration configurationOf(const Pose& pose, const IkpResult& ikp, const WorkingMode& mode) {
  Configuration configuration;
  configuration.pose = pose;
  configuration.chain_count = ikp.chain_count;
  for (int c = 0; c < ikp.chain_count; ++c) {
    const ChainBranch& branch = ikp.chains[c].branch(mode.branch(c));
    configuration.p[c] = ikp.platform_nodes[c];
    configuration.a[c] = branch.a;
    configuration.q[c] = branch.q;
  }
  return configuration;
}

WorkingModeIdentification identifyWorkingMode(const RobotModel& model, const IkpResult& ikp,
                                              const std::vector<double>& input_values, double tolerance) {
  WorkingModeIdentification result;
  if (static_cast<int>(input_values.size()) != model.inputCount()) {
    result.reason = "no input values given";
    return result;
  }
  if (!ikp.assembled) {
    result.reason = "the pose is outside the workspace";
    return result;
  }
  for (int c = 0; c < model.chainCount(); ++c) {
    const Chain& chain = *model.chains[c];
    const double q = input_values[model.chain_input[c]];
    const ChainSolution& solution = ikp.chains[c];
    const double to_p = chain.inputDistance(q, solution.branch(Branch::Positive).q);
    const double to_n = chain.inputDistance(q, solution.branch(Branch::Negative).q);
    if (to_p <= tolerance) continue;
    if (to_n <= tolerance) {
      result.uncoupled.negative_chains |= 1u << c;
      continue;
    }
    result.reason = "chain " + chain.name() + ": input " + chain.input() + " = " + numberText(q) +
                    " matches neither branch (p: " + numberText(solution.branch(Branch::Positive).q) +
                    ", n: " + numberText(solution.branch(Branch::Negative).q) + ")";
    return result;
  }
  result.found = true;
  for (int c = 0; c < model.chainCount(); ++c) result.uncoupled.name += branchLetter(result.uncoupled.branch(c));
  result.coupled = true;
  for (const Input& input : model.inputs) {
    const Branch branch = result.uncoupled.branch(input.chains.front());
    for (int c : input.chains) result.coupled = result.coupled && result.uncoupled.branch(c) == branch;
    result.working_mode.name += branchLetter(branch);
  }
  if (result.coupled) {
    result.working_mode.negative_chains = result.uncoupled.negative_chains;
  } else {
    result.working_mode = WorkingMode{};
  }
  return result;
}

}  // namespace maximal_workspace
