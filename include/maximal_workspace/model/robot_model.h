#pragma once
// What the robot is: chains, inputs, output variables, reference configuration.
// Immutable once loaded; results of computations live in separate structures.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "maximal_workspace/model/chain.h"
#include "maximal_workspace/model/pose.h"

namespace maximal_workspace {

// Fully parallel: one chain per degree of freedom, and at most six of them.
constexpr int kMaxChains = 6;

struct Input {
  std::string name;
  InputKind kind = InputKind::Prismatic;
  // Chains driven by this input; more than one makes a couple (a parallelogram leg split
  // into chains that share the input value and the branch).
  std::vector<int> chains;
  std::optional<std::array<double, 2>> limits;  // [min, max] in m or rad
};

struct ReferenceConfiguration {
  Pose pose;  // the default wave-front start
  // One value per input when the file gives them; they tell which working mode the
  // robot is assembled in at the reference pose.
  std::vector<double> inputs;
};

struct RobotModel {
  std::string name;
  std::string source;  // where it was read from, for messages
  std::vector<ChainPtr> chains;
  std::vector<Input> inputs;
  std::vector<int> chain_input;  // input index of each chain
  std::vector<OutputVariable> output_variables;  // the mechanism's DOF, in file order
  ReferenceConfiguration reference;
  // RMS distance of the platform nodes from the TCP (m): turns rotational Jacobian
  // columns into lengths for the scale-free singularity measure. 0 without rotational DOF.
  double characteristic_length = 0.0;
  // Distance rods keep beyond the sum of their radii (m): the file's `clearance`.
  double rod_clearance = 0.0;

  int chainCount() const { return static_cast<int>(chains.size()); }
  int inputCount() const { return static_cast<int>(inputs.size()); }
  int dof() const { return static_cast<int>(output_variables.size()); }
  bool hasOutputVariable(OutputVariable variable) const;
  int chainIndex(const std::string& chain_name) const;  // -1 when absent
  int inputIndex(const std::string& input_name) const;  // -1 when absent
};

}  // namespace maximal_workspace
