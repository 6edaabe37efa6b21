#pragma once
// Helpers shared by the unit tests.

#include <stdlib.h>

#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Core>

#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/model/pss_chain.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/rss_chain.h"

namespace maximal_workspace::test {

inline std::string sourcePath(const std::string& relative) { return std::string(MOW_SOURCE_DIR) + "/" + relative; }

// The shipped robots, loaded once per test binary.
inline const RobotModel& deltaLike() {
  static const RobotModel model = loadRobotFile(sourcePath("config/delta_like.yaml"));
  return model;
}

inline const RobotModel& fiveBar() {
  static const RobotModel model = loadRobotFile(sourcePath("config/five_bar.yaml"));
  return model;
}

inline const RobotModel& hexapod() {
  static const RobotModel model = loadRobotFile(sourcePath("config/hexapod_6rss.yaml"));
  return model;
}

// The same robot with every length multiplied by `scale` (metres to millimetres, say).
inline RobotModel scaled(const RobotModel& model, double scale) {
  RobotModel result = model;
  for (ChainPtr& chain : result.chains) {
    ChainCommon common = chain->common();
    common.platform_node *= scale;
    common.rod_length *= scale;
    if (const auto* pss = dynamic_cast<const PssChain*>(chain.get())) {
      chain = std::make_shared<PssChain>(common, scale * pss->fixedNode(), pss->direction());
    } else if (const auto* rss = dynamic_cast<const RssChain*>(chain.get())) {
      chain = std::make_shared<RssChain>(common, scale * rss->crankCentre(), rss->axis(), scale * rss->crankLength(),
                                         rss->crankZero());
    }
  }
  result.characteristic_length *= scale;
  result.reference.pose.position *= scale;
  return result;
}

// The default grid of a robot: its translational variables at one step, from the reference
// pose.
inline GridSpec referenceGrid(const RobotModel& model, double step) {
  GridSpec spec;
  spec.variables = translationalVariables(model);
  spec.steps = {step};
  spec.start = model.reference.pose;
  return spec;
}

// Fixed seed: a failure reproduces.
inline std::mt19937& rng() {
  static std::mt19937 generator(20261122);
  return generator;
}

inline double uniform(double low, double high) { return std::uniform_real_distribution<double>(low, high)(rng()); }

inline Eigen::Vector3d uniformVector(double low, double high) {
  return Eigen::Vector3d(uniform(low, high), uniform(low, high), uniform(low, high));
}

inline Eigen::Vector3d randomUnitVector() {
  Eigen::Vector3d v;
  do {
    v = uniformVector(-1.0, 1.0);
  } while (v.norm() < 0.1 || v.norm() > 1.0);
  return v.normalized();
}

// A new directory under /tmp, removed with everything in it when the test ends.
class TemporaryDirectory {
 public:
  explicit TemporaryDirectory(const std::string& prefix) {
    std::string pattern = "/tmp/" + prefix + "_XXXXXX";
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TemporaryDirectory() { std::filesystem::remove_all(path_); }
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;

  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

}  // namespace maximal_workspace::test
