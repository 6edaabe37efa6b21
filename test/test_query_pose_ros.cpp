// /query_pose through ROS against the mow binary: 100 poses (fixed seed) over and around
// the delta-like robot's workspace, the service's answers compared with `mow eval --step`'s
// CSV (inside, det J_DKP and its sign per working mode, the cell, the regions, and per
// assembly mode the maximal workspace, reachability and distance); bad requests. Started by
// test/query_pose.test, whose server has default_step 0.02.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <sstream>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include "cli_support.h"
#include "maximal_workspace/QueryPose.h"
#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/workspace/grid.h"
#include "ros_test_support.h"

namespace maximal_workspace {
namespace {

std::string g_cache_directory;
std::string g_robot_file;
constexpr double kStep = 0.02;

struct QueryCase {
  geometry_msgs::Pose message;
  Eigen::Vector3d position;
  Eigen::Vector3d zyz;  // the angles mow eval gets
};

// The reference pose; one far above the robot; 88 positions uniform over the analysis's
// box widened by a tenth on every side, half with the identity quaternion and half with
// a zero one (the reference orientation, left out); 10 near the reference with the
// platform turned (off the x y z grid, whose orientation is the reference's).
std::vector<QueryCase> queryCases(const RobotModel& model) {
  GridSpec spec;
  spec.variables = translationalVariables(model);
  spec.steps = {kStep};
  spec.start = model.reference.pose;
  const Grid grid(model, spec);
  std::mt19937 random(20260517);
  const auto uniform = [&](double low, double high) { return std::uniform_real_distribution<double>(low, high)(random); };
  const auto make = [](const Eigen::Vector3d& position, const Eigen::Vector3d& zyz, bool left_out) {
    QueryCase c{test::pose(position.x(), position.y(), position.z()), position, zyz};
    const Eigen::Quaterniond q(Eigen::AngleAxisd(zyz[0], Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(zyz[1], Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(zyz[2], Eigen::Vector3d::UnitZ()));
    c.message.orientation.w = left_out ? 0.0 : q.w();
    c.message.orientation.x = q.x();
    c.message.orientation.y = q.y();
    c.message.orientation.z = q.z();
    return c;
  };
  const Eigen::Vector3d reference = model.reference.pose.position;
  std::vector<QueryCase> cases = {make(reference, Eigen::Vector3d::Zero(), false),
                                  make(reference + Eigen::Vector3d(0, 0, 3), Eigen::Vector3d::Zero(), true)};
  for (int k = 0; k < 88; ++k) {
    Eigen::Vector3d position;
    for (int d = 0; d < 3; ++d) {
      const double low = grid.centre(d, 0), high = grid.centre(d, grid.size(d) - 1);
      position[d] = uniform(low - 0.1 * (high - low), high + 0.1 * (high - low));
    }
    cases.push_back(make(position, Eigen::Vector3d::Zero(), k % 2 == 1));
  }
  for (int k = 0; k < 10; ++k) {
    const Eigen::Vector3d position = reference + Eigen::Vector3d(uniform(-0.2, 0.2), uniform(-0.2, 0.2), uniform(-0.2, 0.2));
    cases.push_back(make(position, Eigen::Vector3d(uniform(-M_PI, M_PI), uniform(0.01, 0.3), uniform(-M_PI, M_PI)), false));
  }
  return cases;
}

// mow eval's table: one map from column name to cell per pose.
std::vector<std::map<std::string, std::string>> evalRows(const std::string& csv) {
  std::istringstream in(csv);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::istringstream cells_in(line);
    for (std::string cell; std::getline(cells_in, cell, ',');) cells.push_back(cell);
    if (header.empty()) {
      header = cells;
      continue;
    }
    EXPECT_EQ(cells.size(), header.size());
    std::map<std::string, std::string> row;
    for (std::size_t c = 0; c < std::min(cells.size(), header.size()); ++c) row[header[c]] = cells[c];
    rows.push_back(row);
  }
  return rows;
}

double number(const std::map<std::string, std::string>& row, const std::string& column) {
  const auto found = row.find(column);
  EXPECT_NE(found, row.end()) << "no column " << column;
  return found == row.end() ? NAN : std::strtod(found->second.c_str(), nullptr);
}

QueryPose::Response query(const geometry_msgs::Pose& pose, const std::string& service = "query_pose") {
  QueryPose srv;
  srv.request.pose = pose;
  EXPECT_TRUE(ros::service::call(service, srv)) << "the service call itself failed";
  return srv.response;
}

TEST(QueryPose, AnswersAgreeWithMowEvalOnAHundredPoses) {
  const RobotModel model = loadRobotFile(g_robot_file);
  const std::vector<QueryCase> cases = queryCases(model);
  ASSERT_EQ(cases.size(), 100u);

  const test::TempDir dir;
  std::ostringstream poses;
  poses << "x,y,z,phi,theta,psi\n";
  for (const QueryCase& c : cases) {
    poses << exactText(c.position.x()) << ',' << exactText(c.position.y()) << ',' << exactText(c.position.z()) << ','
          << exactText(c.zyz[0]) << ',' << exactText(c.zyz[1]) << ',' << exactText(c.zyz[2]) << '\n';
  }
  test::writeFile(dir.file("poses.csv"), poses.str());
  const test::RunResult eval = test::runMow({"eval", "--robot", g_robot_file, "--poses", dir.file("poses.csv"), "--out",
                                             dir.file("eval.csv"), "--step", "0.02", "--no-cache", "--quiet"},
                                            dir);
  ASSERT_EQ(eval.exit_code, 0) << eval.err;
  const auto rows = evalRows(test::readFile(dir.file("eval.csv")));
  ASSERT_EQ(rows.size(), cases.size());

  int inside = 0, on_grid = 0, in_maximal = 0, nearest_given = 0, signs_compared = 0;
  std::vector<double> milliseconds;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    SCOPED_TRACE(testing::Message() << "pose " << k << " at " << cases[k].position.transpose() << ", zyz "
                                    << cases[k].zyz.transpose());
    const auto started = std::chrono::steady_clock::now();
    const QueryPose::Response answer = query(cases[k].message);
    milliseconds.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count());
    ASSERT_TRUE(answer.success) << answer.message;
    const auto& row = rows[k];
    EXPECT_EQ(answer.inside, number(row, "inside") == 1.0);
    EXPECT_EQ(answer.step, kStep);
    inside += answer.inside;
    ASSERT_EQ(answer.working_modes.size(), 8u);
    for (const PoseWorkingMode& mode : answer.working_modes) {
      const double det = number(row, "det_" + mode.working_mode);
      const double measure = number(row, "measure_" + mode.working_mode);
      if (!answer.inside) {
        EXPECT_TRUE(std::isnan(det) && std::isnan(mode.det)) << mode.working_mode;
        EXPECT_TRUE(std::isnan(mode.conditioning)) << mode.working_mode;
        EXPECT_EQ(mode.sign, 0);
        continue;
      }
      // The same kinematics; a turned pose reaches the server as a quaternion, mow as angles.
      EXPECT_NEAR(mode.det, det, 1e-9 * std::abs(det)) << mode.working_mode;
      const double conditioning = number(row, "conditioning_" + mode.working_mode);
      EXPECT_NEAR(mode.conditioning, conditioning, 1e-9 + 1e-6 * conditioning) << mode.working_mode;
      EXPECT_EQ(mode.sign, std::abs(measure) < kMeasureTolerance ? 0 : (measure > 0 ? 1 : -1)) << mode.working_mode;
      EXPECT_EQ(mode.region, number(row, "region_" + mode.working_mode)) << mode.working_mode;
      ++signs_compared;
    }
    EXPECT_EQ(answer.on_grid ? double(answer.cell) : -1.0, number(row, "cell"));
    EXPECT_EQ(answer.in_workspace, number(row, "in_workspace") == 1.0);
    on_grid += answer.on_grid;
    ASSERT_EQ(answer.assembly_modes.size(), 2u);
    for (const PoseAssemblyMode& am : answer.assembly_modes) {
      const std::string suffix = am.sign > 0 ? "_positive" : "_negative";
      EXPECT_EQ(am.in_maximal, number(row, "maximal" + suffix) == 1.0);
      EXPECT_EQ(am.reachable, number(row, "reachable" + suffix) == 1.0);
      EXPECT_EQ(am.distance, number(row, "distance" + suffix));
      EXPECT_TRUE(am.has_nearest);
      EXPECT_EQ(am.working_modes.size(), am.regions.size());
      in_maximal += am.in_maximal;
      nearest_given += !am.in_maximal;
      if (!am.in_maximal) continue;
      // In the maximal workspace: the pose itself, and the regions of that sign at its cell.
      EXPECT_EQ(am.distance, 0.0);
      EXPECT_EQ(am.nearest.position.x, cases[k].position.x());
      for (std::size_t r = 0; r < am.regions.size(); ++r) {
        EXPECT_EQ(am.regions[r], number(row, "region_" + am.working_modes[r]));
      }
    }
  }
  // The first call computes the workspace; the others read it from the server's memory.
  const double first = milliseconds.front();
  std::sort(milliseconds.begin() + 1, milliseconds.end());
  std::printf("query_pose: %d of 100 poses inside, %d on the grid, %d (pose, assembly mode) pairs in a maximal workspace "
              "and %d with a nearest point; %d det signs compared; call times: first %.1f ms, then median %.2f ms, "
              "max %.2f ms\n",
              inside, on_grid, in_maximal, nearest_given, signs_compared, first, milliseconds[50], milliseconds.back());
  // Spread over and around the workspace: both answers occur often.
  EXPECT_GE(inside, 20);
  EXPECT_LE(inside, 80);
  EXPECT_GE(nearest_given, 40);
}

TEST(QueryPose, BadRequestsAreRefusedWithTheReason) {
  geometry_msgs::Pose not_finite = test::pose(std::nan(""), 0.1, 0.7);
  const QueryPose::Response nan_answer = query(not_finite);
  EXPECT_FALSE(nan_answer.success);
  EXPECT_NE(nan_answer.message.find("pose: position must be finite"), std::string::npos) << nan_answer.message;

  geometry_msgs::Pose not_unit = test::pose(0.15, 0.15, 0.75);
  not_unit.orientation.w = 0.5;
  const QueryPose::Response unit_answer = query(not_unit);
  EXPECT_FALSE(unit_answer.success);
  EXPECT_NE(unit_answer.message.find("pose: orientation must be a unit quaternion"), std::string::npos)
      << unit_answer.message;

  QueryPose negative_step;
  negative_step.request.pose = test::pose(0.15, 0.15, 0.75);
  negative_step.request.step = -0.01;
  ASSERT_TRUE(ros::service::call("query_pose", negative_step));
  EXPECT_FALSE(negative_step.response.success);
  EXPECT_NE(negative_step.response.message.find("step"), std::string::npos) << negative_step.response.message;

  ASSERT_TRUE(ros::service::waitForService("broken/query_pose", ros::Duration(30)));
  const QueryPose::Response broken = query(test::pose(0.15, 0.15, 0.75), "broken/query_pose");
  EXPECT_FALSE(broken.success);
  EXPECT_NE(broken.message.find("/nonexistent/robot.yaml: cannot read robot file"), std::string::npos) << broken.message;

  // Still up, and answering.
  const QueryPose::Response after = query(test::pose(0.15, 0.15, 0.75));
  EXPECT_TRUE(after.success) << after.message;
  EXPECT_EQ(after.message, "workspace from the cache");
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  using namespace maximal_workspace;
  return test::runServerTests(argc, argv, "query_pose_test", "query_pose", g_cache_directory, g_robot_file);
}
