#pragma once
// Everything `mow eval` reports for one pose: the IKP of every chain and, per working
// mode, the inputs, the DKP singularity figures, the conditioning index and how far it is
// from the robot's limits.

#include <vector>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/kinematics/working_mode.h"

namespace maximal_workspace {

struct WorkingModeAnalysis {
  std::array<double, kMaxChains> q{};
  DkpSingularity singularity;
  double conditioning = 0.0;  // conditioningIndex (kinematics/conditioning.h)
  ConstraintMargins limits;
};

struct PoseAnalysis {
  IkpResult ikp;
  std::vector<WorkingModeAnalysis> modes;  // empty when the pose is not assembled
};

PoseAnalysis analysePose(const RobotModel& model, const Pose& pose,
                         const std::vector<WorkingMode>& modes);

}  // namespace maximal_workspace
