#pragma once
// Where the workspace meets singularities, voxel by voxel.
// - DKP: per working mode, voxels in the singular band or next to a voxel of the other
//   sign of det J_DKP (a DKP surface passes between them).
// - IKP: faces between an inside voxel and a tested outside neighbour, tagged with the
//   input (couple) and chain whose discriminant is negative across the face: the workspace
//   boundary, where working modes meet.

#include <cstdint>
#include <vector>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/workspace/workspace_map.h"

namespace maximal_workspace {

struct DkpSingularVoxel {
  std::uint32_t voxel = 0;
  std::uint8_t mode = 0;
  float measure = 0.0f;  // normalised singularity measure at the voxel centre
};

struct IkpBoundaryFace {
  std::uint32_t voxel = 0;      // the inside voxel
  std::uint8_t dim = 0;         // grid dimension crossed
  std::int8_t direction = 0;    // +1 or -1 along it
  std::uint8_t input = 0;       // the couple limiting the workspace across the face
  std::uint8_t chain = 0;       // a chain of that couple with a negative discriminant there
};

struct SingularityMap {
  std::vector<DkpSingularVoxel> dkp;
  std::vector<IkpBoundaryFace> ikp;
};

SingularityMap findSingularities(const RobotModel& model, const Grid& grid, const PoseClassifier& classifier,
                                 const WorkspaceMap& map, int threads);

}  // namespace maximal_workspace
