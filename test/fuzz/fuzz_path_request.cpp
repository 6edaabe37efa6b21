// libFuzzer target: the /plan_path request validator (resolvePathRequest, which
// path_planner calls on every request) on the delta-like robot and its 8 working modes.
// Any field values must resolve or give an InputError, never a crash or a sanitizer report.
// Values mix plausible ones (so the later checks are reached: start inputs, working modes)
// with arbitrary doubles.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>

#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/planner/path_request.h"

namespace {

using namespace maximal_workspace;

double number(FuzzedDataProvider& input, double low, double high) {
  return input.ConsumeBool() ? input.ConsumeFloatingPointInRange<double>(low, high) : input.ConsumeFloatingPoint<double>();
}

RequestPose pose(FuzzedDataProvider& input) {
  RequestPose pose;
  for (double& value : pose.position) value = number(input, -1.0, 1.5);
  if (input.ConsumeBool()) {  // else the identity, the reference orientation
    for (double& value : pose.orientation) value = number(input, -1.0, 1.0);
  }
  return pose;
}

std::string modeName(FuzzedDataProvider& input, const std::vector<WorkingMode>& modes) {
  if (input.ConsumeBool()) return "";
  if (input.ConsumeBool()) return modes[input.ConsumeIntegralInRange<std::size_t>(0, modes.size() - 1)].name;
  return input.ConsumeRandomLengthString(6);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const RobotModel model = loadRobotFile(MOW_SOURCE_DIR "/config/delta_like.yaml");
  static const std::vector<WorkingMode> modes = coupledWorkingModes(model);
  FuzzedDataProvider input(data, size);
  PathRequest request;
  request.start = pose(input);
  request.goal = pose(input);
  request.start_inputs.resize(input.ConsumeIntegralInRange<std::size_t>(0, 4));
  for (double& value : request.start_inputs) value = number(input, -3.0, 3.0);
  request.start_working_mode = modeName(input, modes);
  request.goal_working_mode = modeName(input, modes);
  request.clearance = number(input, -0.5, 1.5);
  request.assembly_mode = input.ConsumeIntegral<std::int8_t>();
  request.single_working_mode = input.ConsumeBool();
  // An orientation set: start and goal may then take any orientation.
  if (input.ConsumeBool()) request.tilt_max = number(input, 0.0, 1.0);
  try {
    resolvePathRequest(model, modes, request);
  } catch (const InputError&) {
  }
  return 0;
}
