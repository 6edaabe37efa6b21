#include "maximal_workspace/kinematics/working_mode.h"

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

// One letter per group of chains that share a branch, first group slowest.
std::vector<WorkingMode> enumerate(const std::vector<std::vector<int>>& groups) {
  const int letters = static_cast<int>(groups.size());
  std::vector<WorkingMode> modes;
  for (std::uint32_t code = 0; code < (1u << letters); ++code) {
    WorkingMode mode;
    for (int g = 0; g < letters; ++g) {
      const bool negative = (code >> (letters - 1 - g)) & 1u;
      mode.name += branchLetter(negative ? Branch::Negative : Branch::Positive);
      if (negative) {
        for (int chain : groups[g]) mode.negative_chains |= 1u << chain;
      }
    }
    modes.push_back(std::move(mode));
  }
  return modes;
}

}  // namespace

std::vector<WorkingMode> coupledWorkingModes(const RobotModel& model) {
  std::vector<std::vector<int>> groups;
  for (const Input& input : model.inputs) groups.push_back(input.chains);
  return enumerate(groups);
}

std::vector<WorkingMode> uncoupledWorkingModes(const RobotModel& model) {
  std::vector<std::vector<int>> groups;
  for (int c = 0; c < model.chainCount(); ++c) groups.push_back({c});
  return enumerate(groups);
}

const WorkingMode* findWorkingMode(const std::vector<WorkingMode>& modes, const std::string& name) {
  for (const WorkingMode& mode : modes) {
    if (mode.name == name) return &mode;
  }
  return nullptr;
}

std::string workingModeNames(const std::vector<WorkingMode>& modes) {
  std::string names;
  for (const WorkingMode& mode : modes) names += (names.empty() ? "" : " ") + mode.name;
  return names;
}

int workingModeIndex(const std::vector<WorkingMode>& modes, const std::string& name, const std::string& what) {
  const WorkingMode* mode = findWorkingMode(modes, name);
  if (mode == nullptr) throw InputError(what + ": unknown working mode '" + clippedText(name) + "' (known: " + workingModeNames(modes) + ")");
  return static_cast<int>(mode - modes.data());
}

}  // namespace maximal_workspace
