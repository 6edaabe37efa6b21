#pragma once
// Kinetostatic conditioning of a working mode at a pose (docs/kinematics.md,
// "Conditioning index"): how evenly the inputs drive the platform, from the input-output
// Jacobian J = J_IKP^-1 J_DKP (twist form; qdot = -J twist) made dimensionless.

#include "maximal_workspace/kinematics/jacobian.h"

namespace maximal_workspace {

// J with each input's row multiplied by its intermediate node's speed per unit input (1
// for a slider, the crank length for a crank), so that every input is a length travelled,
// and each rotational column divided by the robot's characteristic length, so that every
// platform rate is one too. Its entries are not finite on an IKP singularity of a chain.
DkpJacobian scaledInputOutputJacobian(const RobotModel& model, const Configuration& configuration);

// The inverse condition number sigma_min / sigma_max of that matrix (Eigen's JacobiSVD):
// in [0, 1], 0 on a DKP or an IKP singularity, 1 where the inputs drive every platform
// direction alike. Unchanged by the units and by scaling the whole robot.
double conditioningIndex(const RobotModel& model, const Configuration& configuration);

}  // namespace maximal_workspace
