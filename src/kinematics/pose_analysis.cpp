#include "maximal_workspace/kinematics/pose_analysis.h"

#include "maximal_workspace/kinematics/conditioning.h"

namespace maximal_workspace {

PoseAnalysis analysePose(const RobotModel& model, const Pose& pose, const std::vector<WorkingMode>& modes) {
  PoseAnalysis analysis;
  analysis.ikp = solveIkp(model, pose);
  if (!analysis.ikp.assembled) return analysis;
  analysis.modes.reserve(modes.size());
  const RobotConstraints constraints(model);
  for (const WorkingMode& mode : modes) {
    const Configuration configuration = configurationOf(pose, analysis.ikp, mode);
    WorkingModeAnalysis mode_analysis;
    mode_analysis.q = configuration.q;
    mode_analysis.singularity = dkpSingularity(model, configuration);
    mode_analysis.conditioning = conditioningIndex(model, configuration);
    mode_analysis.limits = constraints.margins(configuration);
    analysis.modes.push_back(mode_analysis);
  }
  return analysis;
}

}  // namespace maximal_workspace
