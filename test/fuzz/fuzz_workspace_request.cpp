// libFuzzer target: the /compute_workspace request validator (resolveWorkspaceRequest,
// which workspace_server calls on every request) on the delta-like robot. Any field values
// must resolve or give an InputError, never a crash or a sanitizer report. Values are drawn
// from a mix of plausible ones (so the checks past the first ones are reached) and
// arbitrary doubles (NaN, infinities, denormals).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>

#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"

namespace {

using namespace maximal_workspace;

double number(FuzzedDataProvider& input) {
  switch (input.ConsumeIntegralInRange<int>(0, 3)) {
    case 0: return input.ConsumeFloatingPointInRange<double>(-2.0, 2.0);
    case 1: return input.ConsumeFloatingPointInRange<double>(0.0, 0.1);
    case 2: return input.ConsumeIntegralInRange<int>(-3, 3) * 0.25;
    default: return input.ConsumeFloatingPoint<double>();
  }
}

std::vector<double> numbers(FuzzedDataProvider& input) {
  std::vector<double> values(input.ConsumeIntegralInRange<std::size_t>(0, 8));
  for (double& value : values) value = number(input);
  return values;
}

std::string name(FuzzedDataProvider& input, const std::vector<std::string>& known) {
  if (input.ConsumeBool()) return known[input.ConsumeIntegralInRange<std::size_t>(0, known.size() - 1)];
  return input.ConsumeRandomLengthString(8);
}

std::vector<std::string> names(FuzzedDataProvider& input, const std::vector<std::string>& known) {
  std::vector<std::string> values(input.ConsumeIntegralInRange<std::size_t>(0, 4));
  for (std::string& value : values) value = name(input, known);
  return values;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string robot_text = readTextFile(MOW_SOURCE_DIR "/config/delta_like.yaml", "robot file");
  static const RobotModel model = parseRobotFile(robot_text, "delta_like.yaml");
  static const std::vector<std::string> variables = {"x", "y", "z", "phi", "theta", "psi"};
  static const std::vector<std::string> modes = {"ppp", "ppn", "pnp", "pnn", "npp", "npn", "nnp", "nnn"};
  FuzzedDataProvider input(data, size);
  WorkspaceRequest request;
  request.step = number(input);
  request.start = numbers(input);
  request.start_working_mode = input.ConsumeBool() ? "" : name(input, modes);
  request.variables = names(input, variables);
  request.bounds = numbers(input);
  request.working_modes = names(input, modes);
  request.assembly_mode = input.ConsumeIntegral<std::int8_t>();
  request.conditioning = input.ConsumeBool();
  request.conditioning_threshold = number(input);
  try {
    resolveWorkspaceRequest(model, robot_text, request, WorkspaceRequestDefaults{});
  } catch (const InputError&) {
  }
  return 0;
}
