#pragma once
// What a real robot allows beyond its legs' reach (issue 16): each input within its
// actuator range, each spherical joint within its cone, and no two rods (capsules)
// closer than their radii plus the robot's clearance. A pose belongs to a working mode
// only where that mode's configuration keeps all three; their boundaries are walls of the
// workspace, never transitions (docs/method.md).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

// Numbered as the singularity map's kinds (0 DKP and 1 IKP singularities come first).
enum class ConstraintKind : std::uint8_t { None = 0, InputRange = 2, JointCone = 3, Interference = 4 };
const char* constraintKindName(ConstraintKind kind);  // "actuator limit", "joint cone", "interference"

// How far one configuration is from each limit: >= 0 where it holds, +infinity where the
// robot file sets none.
struct ConstraintMargins {
  std::array<double, kMaxChains> input;          // m or rad to the nearer end of the input's range
  std::array<double, kMaxChains> fixed_cone;     // rad: half_angle minus the rod's angle at a
  std::array<double, kMaxChains> platform_cone;  // rad: the same at p
  std::array<double, kMaxChains> rod_distance;   // m: to the nearest rod checked against it, beyond radii and clearance
  double min_input = INFINITY, min_cone = INFINITY, min_rod_distance = INFINITY;
  // The first limit broken, in chain order (inputs, then cones, then rods); None: all hold.
  ConstraintKind violated = ConstraintKind::None;
  int chain = -1;        // the chain concerned (the first of a pair of rods)
  int other_chain = -1;  // the second rod of an interfering pair
  double violation = 0.0;  // the broken limit's margin (< 0)
  bool violated_fixed_end = false;  // a broken cone: at a (else at p)
  bool satisfied() const { return violated == ConstraintKind::None; }
};

// The limit a wall is made of: the one broken, else (a pose just on the limit, where
// rounding decides) the one with the smallest margin; and its chain.
struct WallLimit {
  ConstraintKind kind = ConstraintKind::None;
  int chain = -1;
};
WallLimit wallLimit(const ConstraintMargins& margins);

class RobotConstraints {
 public:
  explicit RobotConstraints(const RobotModel& model);

  // Whether the robot file sets any limit: without, every check here passes.
  bool active() const { return active_; }
  // Whether the rods of chains c and d are checked against each other, and the distance
  // their axes must keep (radii plus clearance).
  bool checksPair(int c, int d) const { return pairDistance(c, d) > 0.0; }
  double pairDistance(int c, int d) const;
  ConstraintMargins margins(const Configuration& configuration) const;
  // The same with the platform's rotation given (configuration.pose's is not read).
  ConstraintMargins margins(const Configuration& configuration, const Eigen::Matrix3d& rotation) const;
  // The margins of working mode `mode` at a pose whose IKP `ikp` is assembled (callers
  // checking several modes at one pose solve it once).
  ConstraintMargins margins(const Pose& pose, const IkpResult& ikp, const WorkingMode& mode) const;
  // "chain 'T1a': input T1 = -0.16 m is outside [0, 0.8]", or empty when all hold.
  std::string violationText(const Configuration& configuration, const ConstraintMargins& margins) const;
  // The same for working mode `mode` at a pose whose IKP `ikp` is assembled.
  std::string violationText(const Pose& pose, const IkpResult& ikp, const WorkingMode& mode) const;
  // walls[m] = wallLimit(margins(pose, ikp, modes[m])) for each working mode m with bit m
  // of `wanted`, at a pose whose IKP is assembled. Where no rods are checked against each
  // other each chain's limits are found once a branch, not once a mode.
  void walls(const Pose& pose, const IkpResult& ikp, const std::vector<WorkingMode>& modes, std::uint64_t wanted,
             WallLimit* walls) const;

 private:
  void chainMargins(const Configuration& configuration, const Eigen::Matrix3d& rotation, int c,
                    ConstraintMargins& result) const;
  void settleChains(ConstraintMargins& result) const;

  const RobotModel& model_;
  bool active_ = false;
  bool rods_checked_ = false;
};

}  // namespace maximal_workspace
