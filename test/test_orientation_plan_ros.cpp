// /plan_path over a tilt-and-torsion orientation set, on the hexaglide (10 deg envelope,
// 20 mm, the box and working modes of test_orientation_plan): a goal with the platform
// tilted, reached through a transition, planned in position and orientation, verified,
// and the same plan as `mow plan` makes; a bad orientation set refused naming its field.
// Started by test/orientation_plan.test.

#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <ros/package.h>
#include <ros/ros.h>

#include "maximal_workspace/PlanPath.h"
#include "cli_support.h"
#include "ros_test_support.h"

namespace maximal_workspace {
namespace {

constexpr double kEnvelope = 10.0 * M_PI / 180.0;
const char* const kModes[] = {"ppnnpp", "npnnpp", "pnnnpp", "pppnpp", "ppnppp", "ppnnnp", "ppnnpn"};
// Azimuth, tilt and torsion of the goal (rad): a pose only a transition reaches
// (test_orientation_plan finds such goals; the start's working mode takes slider s1 past
// its stroke there).
constexpr double kGoal[6] = {0.27, -0.09, 0.21, 3.1, 0.05, -0.13};

PlanPath::Request orientationRequest() {
  PlanPath::Request r;
  r.step = 0.02;
  r.tilt_max = kEnvelope;
  r.torsion = {-kEnvelope, kEnvelope};
  r.angle_step = kEnvelope / 2.0;
  r.bounds = {-0.02, 0.4, -0.1, 0.1, 0.2, 0.36};
  r.working_modes.assign(std::begin(kModes), std::end(kModes));
  // The goal's rotation: R = Rz(a) Ry(t) Rz(s - a) (the reference orientation is level).
  const double a = kGoal[3], t = kGoal[4], s = kGoal[5];
  const Eigen::Quaterniond q(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(t, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(s - a, Eigen::Vector3d::UnitZ()));
  r.goal = test::pose(kGoal[0], kGoal[1], kGoal[2]);
  r.goal.orientation.w = q.w();
  r.goal.orientation.x = q.x();
  r.goal.orientation.y = q.y();
  r.goal.orientation.z = q.z();
  return r;
}

// Every digit, so that mow's analysis is the service's.
std::string exact(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

PlanPath::Response call(const PlanPath::Request& r) {
  PlanPath srv;
  srv.request = r;
  EXPECT_TRUE(ros::service::call("plan_path", srv)) << "the service call itself failed";
  return srv.response;
}

Eigen::Quaterniond orientationOf(const geometry_msgs::Pose& pose) {
  return Eigen::Quaterniond(pose.orientation.w, pose.orientation.x, pose.orientation.y, pose.orientation.z);
}

TEST(OrientationPlanRos, ATiltedGoalIsPlannedThroughATransitionAsMowPlansIt) {
  const PlanPath::Request r = orientationRequest();
  const PlanPath::Response planned = call(r);
  ASSERT_TRUE(planned.success) << planned.message;
  EXPECT_TRUE(planned.verified) << planned.verification;
  EXPECT_FALSE(planned.transitions.empty());
  const Eigen::Quaterniond end = orientationOf(planned.path.poses.back().pose);
  EXPECT_LT(end.angularDistance(orientationOf(r.goal)), 1e-6);
  // The same analysis and plan through mow.
  const test::TempDir dir;
  std::string goal;
  for (double value : kGoal) goal += (goal.empty() ? "" : ",") + exact(value);
  const test::RunResult mow = test::runMow(
      {"plan", "--robot", ros::package::getPath("maximal_workspace") + "/config/hexaglide_6pss.yaml", "--step", "0.02",
       "--bounds", "-0.02,0.4,-0.1,0.1,0.2,0.36", "--tilt-max", exact(kEnvelope), "--torsion",
       exact(-kEnvelope) + "," + exact(kEnvelope), "--angle-step", exact(kEnvelope / 2.0),
       "--modes", "ppnnpp,npnnpp,pnnnpp,pppnpp,ppnppp,ppnnnp,ppnnpn", "--goal", goal, "--cache", dir.file("cache"), "--quiet"},
      dir);
  ASSERT_EQ(mow.exit_code, 0) << mow.out << mow.err;
  char length[48];
  std::snprintf(length, sizeof length, "transition%s, length %.4f m", planned.transitions.size() == 1 ? "" : "s",
                planned.length);
  EXPECT_NE(mow.out.find(std::to_string(planned.transitions.size()) + " " + length), std::string::npos)
      << mow.out << " against " << length;
}

TEST(OrientationPlanRos, ABadOrientationSetIsRefusedNamingItsField) {
  PlanPath::Request r = orientationRequest();
  r.torsion = {0.1};
  const PlanPath::Response refused = call(r);
  EXPECT_FALSE(refused.success);
  EXPECT_NE(refused.message.find("torsion"), std::string::npos) << refused.message;
  r = orientationRequest();
  r.tilt_max = -0.1;
  const PlanPath::Response negative = call(r);
  EXPECT_FALSE(negative.success);
  EXPECT_NE(negative.message.find("tilt"), std::string::npos) << negative.message;
}

}  // namespace
}  // namespace maximal_workspace

int main(int argc, char** argv) {
  return maximal_workspace::test::runRosTests(argc, argv, "test_orientation_plan_ros", {"plan_path"});
}
