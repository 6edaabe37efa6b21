#pragma once
// Working modes: one IKP branch per chain. The robot's own working modes give the chains
// of a couple the same branch (2^inputs of them, named by one letter per input, e.g.
// `npn`); the uncoupled auxiliary's give each chain its own (2^chains, a letter per chain).

#include <cstdint>
#include <string>
#include <vector>

#include "maximal_workspace/model/chain.h"
#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

struct WorkingMode {
  std::string name;
  std::uint32_t negative_chains = 0;  // bit c set: chain c takes branch n

  Branch branch(int chain) const {
    return (negative_chains >> chain) & 1u ? Branch::Negative : Branch::Positive;
  }
};

// In name order with p before n, first letter slowest: ppp, ppn, pnp, ..., nnn.
std::vector<WorkingMode> coupledWorkingModes(const RobotModel& model);
std::vector<WorkingMode> uncoupledWorkingModes(const RobotModel& model);
// Null when no working mode has this name.
const WorkingMode* findWorkingMode(const std::vector<WorkingMode>& modes, const std::string& name);
// The names, space-separated, for messages.
std::string workingModeNames(const std::vector<WorkingMode>& modes);
// The index of the working mode with this name; throws InputError "<what>: unknown working
// mode '<name>' (known: ...)".
int workingModeIndex(const std::vector<WorkingMode>& modes, const std::string& name, const std::string& what);

}  // namespace maximal_workspace
