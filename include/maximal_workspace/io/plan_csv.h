#pragma once
// Plan files: one row per trajectory sample,
//   t,waypoints,mode,x,y,z,phi,theta,psi,<one column per input, named after it>
// t in s; waypoints: how many plan waypoints fall on the sample (2 at a transition, where
// the mode changes); mode: the working mode's name; x..psi: the planned TCP pose (m, rad);
// then the inputs (m or rad). `mow plan` writes them, `mow verify` reads them.

#include <cstdint>
#include <istream>
#include <string>
#include <vector>

#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/planner/trajectory.h"

namespace maximal_workspace {

// Plans are read whole, so their files are bounded: the delta-like robot's plan of
// test_mow_cli (to 0.775,0.455,0.075), at 5 mm, has 1,337 samples in 196 KB.
constexpr std::uint64_t kMaxPlanFileBytes = std::uint64_t{64} << 20;

std::string planCsv(const InputTrajectory& trajectory, const std::vector<WorkingMode>& modes);

// Throws InputError naming the source, the line and the column. Mode names must be among
// `modes`, input columns must be the robot's inputs in order, times must increase; a line
// over kMaxLineBytes is refused at that line.
InputTrajectory readPlanCsv(std::istream& in, const std::string& source, const RobotModel& model,
                            const std::vector<WorkingMode>& modes);

}  // namespace maximal_workspace
