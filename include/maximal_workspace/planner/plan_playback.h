#pragma once
// A planned path as a display plays it (the PlannedPath message in plain types). It comes
// from any node, so it is checked whole before it replaces the one playing.

#include <array>
#include <string>
#include <vector>

#include "maximal_workspace/kinematics/working_mode.h"

namespace maximal_workspace {

struct PlanToPlay {
  std::vector<std::array<double, 3>> positions;  // TCP (m), one per pose
  std::vector<std::string> working_modes;        // one per pose
  std::vector<double> times;                     // s from the start, one per trajectory point
};

// Why the plan cannot be played in these working modes (names quoted and cut), or empty:
// then it has at least 2 poses, as many working modes and times, every working mode among
// `modes`, finite positions and times that never go back.
std::string planToPlayProblem(const PlanToPlay& plan, const std::vector<WorkingMode>& modes);

}  // namespace maximal_workspace
