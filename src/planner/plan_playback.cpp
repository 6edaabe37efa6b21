#include "maximal_workspace/planner/plan_playback.h"

#include <cmath>

#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

std::string planToPlayProblem(const PlanToPlay& plan, const std::vector<WorkingMode>& modes) {
  const std::size_t poses = plan.positions.size();
  if (poses < 2) return "fewer than 2 poses";
  if (plan.working_modes.size() != poses || plan.times.size() != poses) {
    return std::to_string(poses) + " poses but " + std::to_string(plan.working_modes.size()) + " working modes and " +
           std::to_string(plan.times.size()) + " trajectory points";
  }
  double last_time = -INFINITY;
  for (std::size_t k = 0; k < poses; ++k) {
    if (findWorkingMode(modes, plan.working_modes[k]) == nullptr) {
      return "pose " + std::to_string(k) + ": working mode '" + clippedText(plan.working_modes[k]) +
             "' is not one of this display's (" + workingModeNames(modes) + ")";
    }
    const std::array<double, 3>& p = plan.positions[k];
    const double time = plan.times[k];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]) || !std::isfinite(time)) {
      return "pose " + std::to_string(k) + ": not finite";
    }
    if (time < last_time) return "pose " + std::to_string(k) + ": its time goes back";
    last_time = time;
  }
  return "";
}

}  // namespace maximal_workspace
