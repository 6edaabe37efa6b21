// libFuzzer target: the check robot_pose_publisher makes of a plan from /path_planner/plan
// before playing it (issue 18: unknown working-mode names and short arrays crashed it).
// Any plan must give a problem or be playable: then every index the playback uses is
// valid, which is asserted here, so a check that lets a bad plan through is a crash.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include <fuzzer/FuzzedDataProvider.h>

#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/planner/plan_playback.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace maximal_workspace;
  static const RobotModel model = loadRobotFile(MOW_SOURCE_DIR "/config/delta_like.yaml");
  static const std::vector<WorkingMode> modes = coupledWorkingModes(model);
  FuzzedDataProvider input(data, size);
  PlanToPlay plan;
  // Three lengths of their own, as a message's arrays are.
  plan.positions.resize(input.ConsumeIntegralInRange<std::size_t>(0, 16));
  plan.working_modes.resize(input.ConsumeIntegralInRange<std::size_t>(0, 16));
  plan.times.resize(input.ConsumeIntegralInRange<std::size_t>(0, 16));
  for (auto& position : plan.positions) {
    for (double& value : position) value = input.ConsumeFloatingPoint<double>();
  }
  for (std::string& name : plan.working_modes) {
    // Mostly real names, so that the later checks are reached.
    name = input.ConsumeBool() ? modes[input.ConsumeIntegralInRange<std::size_t>(0, modes.size() - 1)].name
                               : input.ConsumeRandomLengthString(8);
  }
  for (double& time : plan.times) time = input.ConsumeFloatingPoint<double>();
  if (!planToPlayProblem(plan, modes).empty()) return 0;
  const std::size_t poses = plan.positions.size();
  if (poses < 2 || plan.working_modes.size() != poses || plan.times.size() != poses) std::abort();
  for (std::size_t k = 0; k < poses; ++k) {
    if (findWorkingMode(modes, plan.working_modes[k]) == nullptr || !std::isfinite(plan.times[k])) std::abort();
    if (k > 0 && plan.times[k] < plan.times[k - 1]) std::abort();
  }
  return 0;
}
