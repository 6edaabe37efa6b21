#pragma once
// URDF of a robot file's mechanism and the joint positions of a configuration, made
// together so that the description and the kinematics cannot drift apart.
//
// Closed loops the usual ROS way: a tree. From base_link, each chain is an actuator joint
// (revolute about the actuator frame's z, or prismatic along its x), its actuator link
// (crank or slider), the first spherical joint as three revolute joints (z, y, x) and the
// rod, a link along its x of the rod's length. The platform hangs from base_link by its
// own joints: prismatic x, y, z for the translational DOF, and for the auxiliary revolute
// phi (z), theta (y), psi (z). The rods' far ends are left free; the joint positions put
// them on their platform nodes.

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

// Robot: the chains of a couple are driven together (the second chain's actuator joint
// mimics the first's), parallelogram bars drawn, the platform translating only.
// Auxiliary: every chain its own actuator, the platform with all the mechanism's DOF.
enum class Mechanism { Robot, Auxiliary };

std::string urdfDescription(const RobotModel& model, Mechanism mechanism);

struct JointPositions {
  std::vector<std::string> names;
  std::vector<double> positions;
};

// Every joint of the description (mimic joints included) for an assembled configuration.
JointPositions jointPositions(const RobotModel& model, Mechanism mechanism, const Configuration& configuration);

// The box of everything the description draws that does not ride on the platform, at any
// input: the base plate, every rail and crank axis, every crank's circle, widened by the
// thickest part's half-width. In coordinates along `axes`' columns (orthonormal; a view's
// right, up and depth give its silhouette), by default the base frame's. Each rod joins a
// point of it to a platform node, so with the platform's box it bounds the whole drawn robot.
Eigen::AlignedBox3d fixedGeometryBox(const RobotModel& model, const Eigen::Matrix3d& axes = Eigen::Matrix3d::Identity());
// The box of the whole drawn robot while its TCP stays within `tcp_box` (the workspace's, in
// the same coordinates): fixedGeometryBox with tcp_box widened by the platform's reach at any
// orientation.
Eigen::AlignedBox3d drawnRobotBox(const RobotModel& model, const Eigen::AlignedBox3d& tcp_box,
                                  const Eigen::Matrix3d& axes = Eigen::Matrix3d::Identity());

std::string actuatorJointName(const Chain& chain);
std::string rodLinkName(const Chain& chain);
constexpr const char* kPlatformLink = "platform";
constexpr const char* kBaseLink = "base_link";

}  // namespace maximal_workspace
