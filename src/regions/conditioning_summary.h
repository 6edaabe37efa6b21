#pragma once
// The conditioning figures of an analysis's maximal workspaces (docs/kinematics.md,
// "Conditioning index"): computed in the summary stage when the options ask for them.

#include <array>
#include <functional>
#include <vector>

#include "regions/analysis_data.h"

namespace maximal_workspace {

// Per assembly mode (0: +, 1: -), the best conditioning index at `pose` of the working
// modes to which region_sign(m) gives the sign of a non-debris region holding the pose's
// cell (0: none): the robot may be in any of them there. -1 where no working mode has one.
std::array<double, 2> bestConditioning(const RobotModel& model, const Pose& pose, const std::vector<WorkingMode>& modes,
                                       const std::function<int(int)>& region_sign);

// The sampling stride: the smallest k for which `cells` cells, taken every k-th along
// each of `dims` grid variables, in `modes` working modes each, are at most `evaluations`.
int conditioningStride(std::uint64_t cells, int dims, int modes, std::uint64_t evaluations);

// From the regions and the assembly modes' maximal volumes already in `data`.
// progress(fraction) is called from the worker threads, serialised; what it throws
// (Cancelled) reaches the caller.
ConditioningSummary summariseConditioning(const RobotModel& model, const AnalysisData& data,
                                          const ConditioningRequest& request, int threads,
                                          const std::function<void(double)>& progress = {});

}  // namespace maximal_workspace
