#pragma once
// Forward kinematics over a parsed URDF tree (urdfdom), independent of the kinematics
// core: what robot_state_publisher would compute from a set of joint positions.

#include <map>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <urdf_model/model.h>

#include "maximal_workspace/description/robot_description.h"

namespace maximal_workspace::test {

// World frames of every link for the given joint positions, by walking the URDF tree;
// mimic joints follow their leader, as robot_state_publisher makes them.
inline std::map<std::string, Eigen::Isometry3d> linkFrames(const urdf::ModelInterface& urdf, const JointPositions& joints) {
  std::map<std::string, double> value;
  for (std::size_t j = 0; j < joints.names.size(); ++j) value[joints.names[j]] = joints.positions[j];
  std::map<std::string, Eigen::Isometry3d> frames = {{urdf.getRoot()->name, Eigen::Isometry3d::Identity()}};
  std::vector<std::string> pending = {urdf.getRoot()->name};
  while (!pending.empty()) {
    const std::string parent = pending.back();
    pending.pop_back();
    for (const auto& joint : urdf.getLink(parent)->child_joints) {
      const urdf::Pose& o = joint->parent_to_joint_origin_transform;
      Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
      origin.translation() = Eigen::Vector3d(o.position.x, o.position.y, o.position.z);
      double qx, qy, qz, qw;
      o.rotation.getQuaternion(qx, qy, qz, qw);
      origin.linear() = Eigen::Quaterniond(qw, qx, qy, qz).toRotationMatrix();
      double q = 0.0;
      if (joint->type != urdf::Joint::FIXED) {
        EXPECT_TRUE(value.count(joint->name)) << "no position for joint " << joint->name;
        q = joint->mimic ? joint->mimic->multiplier * value[joint->mimic->joint_name] + joint->mimic->offset : value[joint->name];
      }
      const Eigen::Vector3d axis(joint->axis.x, joint->axis.y, joint->axis.z);
      Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
      if (joint->type == urdf::Joint::PRISMATIC) motion.translation() = q * axis;
      if (joint->type == urdf::Joint::REVOLUTE || joint->type == urdf::Joint::CONTINUOUS) {
        motion.linear() = Eigen::AngleAxisd(q, axis).toRotationMatrix();
      }
      frames[joint->child_link_name] = frames[parent] * origin * motion;
      pending.push_back(joint->child_link_name);
    }
  }
  return frames;
}

}  // namespace maximal_workspace::test
