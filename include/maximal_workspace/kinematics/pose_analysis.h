#pragma once
// Everything `mow eval` reports for one pose: the IKP of every chain and, per working
// mode, the inputs and the DKP singularity figures.

#include <vector>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/kinematics/working_mode.h"

namespace maximal_workspace {

struct WorkingModeAnalysis {
  std::array<double, kMaxChains> q{};
  DkpSingularity singularity;
};

struct PoseAnalysis {
  IkpResult ikp;
  std::vector<WorkingModeAnalysis> modes;  // empty when the pose is not assembled
};

PoseAnalysis analysePose(const RobotModel& model, const Pose& pose,
                         const std::vector<WorkingMode>& modes);

}  // namespace maximal_workspace
