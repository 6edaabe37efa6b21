#pragma once
// The uncoupled IKP of a pose (every chain alone, both branches), and the configuration
// of one working mode built from it.

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

struct IkpResult {
  std::array<Eigen::Vector3d, kMaxChains> platform_nodes;  // base frame
  std::array<ChainSolution, kMaxChains> chains;
  int chain_count = 0;
  bool assembled = false;  // every chain can be assembled: the pose is in the workspace
};

IkpResult solveIkp(const RobotModel& model, const Pose& pose);

// The assembled robot in one working mode (only meaningful when the IKP is assembled).
struct Configuration {
  Pose pose;
  std::array<Eigen::Vector3d, kMaxChains> p;  // platform nodes
  std::array<Eigen::Vector3d, kMaxChains> a;  // intermediate nodes
  std::array<double, kMaxChains> q{};         // inputs
  int chain_count = 0;
};

Configuration configurationOf(const Pose& pose, const IkpResult& ikp, const WorkingMode& mode);

// Which branch each chain takes when the inputs have the given values at the pose.
struct WorkingModeIdentification {
  bool found = false;
  WorkingMode uncoupled;      // a letter per chain
  bool coupled = false;       // every couple's chains share their branch
  WorkingMode working_mode;   // a letter per input, when coupled
  std::string reason;         // why not found
};

// `input_values` has one value per input. A chain matches a branch when its input is
// within `tolerance` (m or rad) of that branch's root; at an IKP singularity both match
// and the p branch is reported.
WorkingModeIdentification identifyWorkingMode(const RobotModel& model, const IkpResult& ikp,
                                              const std::vector<double>& input_values,
                                              double tolerance = 1e-6);

}  // namespace maximal_workspace
