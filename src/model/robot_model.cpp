#include "maximal_workspace/model/robot_model.h"

#include <algorithm>

namespace maximal_workspace {

bool RobotModel::hasOutputVariable(OutputVariable variable) const {
  return std::find(output_variables.begin(), output_variables.end(), variable) != output_variables.end();
}

int RobotModel::chainIndex(const std::string& chain_name) const {
  for (int c = 0; c < chainCount(); ++c) {
    if (chains[c]->name() == chain_name) return c;
  }
  return -1;
}

int RobotModel::inputIndex(const std::string& input_name) const {
  for (int i = 0; i < inputCount(); ++i) {
    if (inputs[i].name == input_name) return i;
  }
  return -1;
}

}  // namespace maximal_workspace
