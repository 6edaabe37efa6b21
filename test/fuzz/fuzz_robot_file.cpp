// libFuzzer target: robot files (YAML). Any bytes must give a model or an InputError, never
// a crash, a hang or a sanitizer report; a model that loads must also be usable: its
// working modes and the analysis of its reference pose.
#include <cstddef>
#include <cstdint>
#include <string>

#include "maximal_workspace/kinematics/pose_analysis.h"
#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace maximal_workspace;
  try {
    const RobotModel model = parseRobotFile(std::string(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    analysePose(model, model.reference.pose, coupledWorkingModes(model));
  } catch (const InputError&) {
  }
  return 0;
}
