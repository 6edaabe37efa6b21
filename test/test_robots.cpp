// The shipped robots against data that does not come from our code: the geometry table
// of docs/delta_like_geometry.md, hand computations for the planar 5R, and the 6-RSS
// hexapod's stated design.

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/model/pss_chain.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/rss_chain.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

// docs/delta_like_geometry.md, "Nodes in the reference configuration" (chains 1..6).
struct TableRow {
  Eigen::Vector3d f, a, p;
};
const TableRow kTable[6] = {
    {{0.1, -0.1, 0.9}, {-0.1647, -0.3647, 0.3}, {0.2, 0.0, 0.7}},
    {{-0.1, 0.1, 0.9}, {-0.3647, -0.1647, 0.3}, {0.0, 0.2, 0.7}},
    {{0.2, 0.0, 0.0}, {0.2, 0.6231, 0.0}, {0.2, 0.3, 0.8}},
    {{0.0, 0.0, 0.0}, {0.0, 0.6231, 0.0}, {0.0, 0.3, 0.8}},
    {{1.0, 0.0, 0.0}, {1.0, 0.0, 0.4}, {0.3, 0.0, 0.8}},
    {{1.0, 0.2, 0.0}, {1.0, 0.2, 0.4}, {0.3, 0.2, 0.8}},
};
const Eigen::Vector3d kTableTcp(0.15, 0.15, 0.75);

TEST(DeltaLike, RobotFileMatchesTheGeometryTableAtFullPrecision) {
  const RobotModel& model = test::deltaLike();
  ASSERT_EQ(model.chainCount(), 6);
  ASSERT_EQ(model.dof(), 6);
  for (int c = 0; c < 6; ++c) {
    const Chain& chain = *model.chains[c];
    EXPECT_NEAR(chain.rodLength(), (kTable[c].p - kTable[c].a).norm(), 1e-15) << chain.name();
    EXPECT_LT((model.reference.pose.position + chain.platformNode() - kTable[c].p).norm(), 1e-15) << chain.name();
    if (const auto* rss = dynamic_cast<const RssChain*>(&chain)) {
      EXPECT_NEAR(rss->crankLength(), (kTable[c].a - kTable[c].f).norm(), 1e-15);
      EXPECT_LT((rss->crankCentre() - kTable[c].f).norm(), 1e-15);
      EXPECT_LT((rss->axis() - Eigen::Vector3d(1, -1, 0).normalized()).norm(), 1e-15);
    } else {
      const auto* pss = dynamic_cast<const PssChain*>(&chain);
      ASSERT_NE(pss, nullptr);
      EXPECT_LT((pss->fixedNode() - kTable[c].f).norm(), 1e-15);
      EXPECT_LT((pss->direction() - (c < 4 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ())).norm(), 1e-15);
    }
  }
  EXPECT_LT((model.reference.pose.position - kTableTcp).norm(), 1e-15);
}

TEST(DeltaLike, ReferenceWorkingModeReproducesTheTableIntermediateNodes) {
  const RobotModel& model = test::deltaLike();
  const IkpResult ikp = solveIkp(model, model.reference.pose);
  ASSERT_TRUE(ikp.assembled);
  const WorkingModeIdentification found = identifyWorkingMode(model, ikp, model.reference.inputs);
  ASSERT_TRUE(found.found) << found.reason;
  ASSERT_TRUE(found.coupled);
  const Configuration configuration = configurationOf(model.reference.pose, ikp, found.working_mode);
  for (int c = 0; c < 6; ++c) EXPECT_LT((configuration.a[c] - kTable[c].a).norm(), 1e-9) << model.chains[c]->name();
  // The table's slider travels.
  EXPECT_NEAR(configuration.q[2], 0.6231, 1e-12);
  EXPECT_NEAR(configuration.q[4], 0.4, 1e-12);
}

TEST(DeltaLike, ChainsOfACoupleShareInputAndRodDirectionAtConstantOrientation) {
  // A parallelogram leg: with the platform at the reference orientation, a_2 - a_1 =
  // p_2 - p_1 for every input, so both chains of a couple take the same q and rod.
  const RobotModel& model = test::deltaLike();
  const std::vector<WorkingMode> modes = coupledWorkingModes(model);
  int checked = 0;
  for (int k = 0; k < 500; ++k) {
    Pose pose = model.reference.pose;
    pose.position += test::uniformVector(-0.3, 0.3);
    const IkpResult ikp = solveIkp(model, pose);
    if (!ikp.assembled) continue;
    for (const WorkingMode& mode : modes) {
      const Configuration configuration = configurationOf(pose, ikp, mode);
      for (const Input& input : model.inputs) {
        const int first = input.chains[0], second = input.chains[1];
        EXPECT_LT(model.chains[first]->inputDistance(configuration.q[first], configuration.q[second]), 1e-9);
        EXPECT_LT(((configuration.p[first] - configuration.a[first]) - (configuration.p[second] - configuration.a[second])).norm(), 1e-9);
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 1000);
}

TEST(WorkingModes, NamesFollowTheChapter) {
  // Chapter Fig. 4: WM c1c2c3, c_k the branch of KC_k.
  std::vector<std::string> names;
  for (const WorkingMode& mode : coupledWorkingModes(test::deltaLike())) names.push_back(mode.name);
  const std::vector<std::string> expected = {"ppp", "ppn", "pnp", "pnn", "npp", "npn", "nnp", "nnn"};
  EXPECT_EQ(names, expected);
  for (const WorkingMode& mode : coupledWorkingModes(test::deltaLike())) {
    for (int i = 0; i < 3; ++i) {
      for (int c : test::deltaLike().inputs[i].chains) EXPECT_EQ(branchLetter(mode.branch(c)), mode.name[i]);
    }
  }
  const std::vector<WorkingMode> uncoupled = uncoupledWorkingModes(test::deltaLike());
  std::set<std::string> distinct;
  for (const WorkingMode& mode : uncoupled) distinct.insert(mode.name);
  EXPECT_EQ(distinct.size(), 64u);
  // The robot's own modes are the auxiliary's with equal letters in each couple.
  for (const WorkingMode& mode : coupledWorkingModes(test::deltaLike())) {
    const std::string chains = {mode.name[0], mode.name[0], mode.name[1], mode.name[1], mode.name[2], mode.name[2]};
    const WorkingMode* same = findWorkingMode(uncoupled, chains);
    ASSERT_NE(same, nullptr);
    EXPECT_EQ(same->negative_chains, mode.negative_chains);
  }
  std::vector<std::string> five_bar;
  for (const WorkingMode& mode : coupledWorkingModes(test::fiveBar())) five_bar.push_back(mode.name);
  EXPECT_EQ(five_bar, (std::vector<std::string>{"pp", "pn", "np", "nn"}));
}

// Elbow of an RR leg by the two-circle intersection, the textbook way: distance d
// between centres, foot of the chord at a from the base, half-chord h.
std::vector<double> elbowAnglesByHand(const Eigen::Vector2d& base, const Eigen::Vector2d& tcp) {
  const double r_crank = 0.2, r_rod = 0.25;
  const Eigen::Vector2d towards = tcp - base;
  const double d = towards.norm();
  const double a = (r_crank * r_crank - r_rod * r_rod + d * d) / (2 * d);
  const double h = std::sqrt(r_crank * r_crank - a * a);
  const Eigen::Vector2d foot = base + a * towards / d;
  const Eigen::Vector2d normal(-towards.y() / d, towards.x() / d);
  std::vector<double> angles;
  for (double side : {1.0, -1.0}) {
    const Eigen::Vector2d elbow = foot + side * h * normal;
    angles.push_back(std::atan2(elbow.y() - base.y(), elbow.x() - base.x()));
  }
  return angles;  // left of base->tcp first: a positive turn from the direction to the TCP
}

TEST(FiveBar, IkpMatchesTwoCircleIntersection) {
  const RobotModel& model = test::fiveBar();
  const Eigen::Vector2d bases[2] = {{-0.1, 0.0}, {0.1, 0.0}};
  for (const Eigen::Vector2d& tcp : {Eigen::Vector2d(0.0, 0.3), Eigen::Vector2d(0.12, 0.2), Eigen::Vector2d(-0.2, -0.15),
                                    Eigen::Vector2d(0.3, 0.05)}) {
    Pose pose;
    pose.position << tcp.x(), tcp.y(), 0.0;
    const IkpResult ikp = solveIkp(model, pose);
    ASSERT_TRUE(ikp.assembled);
    for (int c = 0; c < 2; ++c) {
      const std::vector<double> hand = elbowAnglesByHand(bases[c], tcp);
      EXPECT_LT(model.chains[c]->inputDistance(ikp.chains[c].branch(Branch::Positive).q, hand[0]), 1e-12);
      EXPECT_LT(model.chains[c]->inputDistance(ikp.chains[c].branch(Branch::Negative).q, hand[1]), 1e-12);
    }
  }
  // The same, worked out once on paper for TCP (0, 0.3): left elbows at 2.16038066957 and
  // 0.337710875223 rad, right elbows at 2.80388177837 and 0.981211984016 rad.
  Pose pose;
  pose.position << 0.0, 0.3, 0.0;
  const IkpResult ikp = solveIkp(model, pose);
  EXPECT_NEAR(ikp.chains[0].branch(Branch::Positive).q, 2.16038066957, 1e-10);
  EXPECT_NEAR(ikp.chains[0].branch(Branch::Negative).q, 0.337710875223, 1e-10);
  EXPECT_NEAR(ikp.chains[1].branch(Branch::Positive).q, 2.80388177837, 1e-10);
  EXPECT_NEAR(ikp.chains[1].branch(Branch::Negative).q, 0.981211984016, 1e-10);
}

TEST(FiveBar, AssembledExactlyInsideBothAnnuli) {
  const RobotModel& model = test::fiveBar();
  int inside = 0;
  for (int k = 0; k < 5000; ++k) {
    Pose pose;
    pose.position << test::uniform(-0.6, 0.6), test::uniform(-0.6, 0.6), 0.0;
    // Each leg reaches the annulus between |0.25 - 0.2| and 0.25 + 0.2 about its base.
    const double left = (pose.position - Eigen::Vector3d(-0.1, 0, 0)).norm();
    const double right = (pose.position - Eigen::Vector3d(0.1, 0, 0)).norm();
    const double margin = std::min({std::abs(left - 0.05), std::abs(left - 0.45), std::abs(right - 0.05), std::abs(right - 0.45)});
    if (margin < 1e-9) continue;
    const bool expected = left > 0.05 && left < 0.45 && right > 0.05 && right < 0.45;
    EXPECT_EQ(solveIkp(model, pose).assembled, expected);
    inside += expected;
  }
  EXPECT_GT(inside, 1000);
}

TEST(FiveBar, ReferenceIsElbowsOut) {
  const RobotModel& model = test::fiveBar();
  const IkpResult ikp = solveIkp(model, model.reference.pose);
  const WorkingModeIdentification found = identifyWorkingMode(model, ikp, model.reference.inputs);
  ASSERT_TRUE(found.found) << found.reason;
  const Configuration configuration = configurationOf(model.reference.pose, ikp, found.working_mode);
  // The hand-computed elbows (-0.2112, 0.1662) and (0.2112, 0.1662).
  EXPECT_NEAR(configuration.a[0].x(), -0.2112031176734915, 1e-12);
  EXPECT_NEAR(configuration.a[0].y(), 0.16623437255783052, 1e-12);
  EXPECT_NEAR(configuration.a[1].x(), 0.2112031176734915, 1e-12);
  EXPECT_NEAR(configuration.a[1].y(), 0.16623437255783052, 1e-12);
}

// config/hexapod_6rss.yaml as its header states the design: crank centres 0.15 m from the
// base centre at these angles, axes horizontal and tangent to the base circle, cranks
// 0.05 m, rods 0.2 m, platform joints 0.1 m from the TCP at these angles.
const double kHexapodBaseDegrees[6] = {-15, 15, 105, 135, 225, 255};
const double kHexapodPlatformDegrees[6] = {-45, 45, 75, 165, 195, 285};

// Where a crank of length `crank` turning about the unit axis `e` through `centre` meets
// the sphere of radius `rod` about `p`: in the crank's plane, at +/- alpha from the
// projection of p - centre, with cos(alpha) from the law of cosines. The + turn (about e)
// first: the p branch (docs/kinematics.md).
std::array<Eigen::Vector3d, 2> crankCircleMeetsSphere(const Eigen::Vector3d& centre, const Eigen::Vector3d& e,
                                                      double crank, const Eigen::Vector3d& p, double rod) {
  const Eigen::Vector3d w = p - centre;
  const Eigen::Vector3d in_plane = w - w.dot(e) * e;
  const double cos_alpha = (crank * crank + w.squaredNorm() - rod * rod) / (2.0 * crank * in_plane.norm());
  const double sin_alpha = std::sqrt(1.0 - cos_alpha * cos_alpha);
  const Eigen::Vector3d x = in_plane.normalized(), y = e.cross(x);
  return {centre + crank * (cos_alpha * x + sin_alpha * y), centre + crank * (cos_alpha * x - sin_alpha * y)};
}

TEST(Hexapod, ReferenceIkpIsTheCrankCircleSphereIntersection) {
  const RobotModel& model = test::hexapod();
  ASSERT_EQ(model.chainCount(), 6);
  ASSERT_EQ(model.inputCount(), 6);
  EXPECT_EQ(coupledWorkingModes(model).size(), 64u);
  // Level platform with every crank horizontal: the height worked out in the file's header.
  const double height = std::sqrt(0.02 * std::sqrt(3.0) - 0.01);
  EXPECT_LT((model.reference.pose.position - Eigen::Vector3d(0.0, 0.0, height)).norm(), 1e-15);
  EXPECT_LT(model.reference.pose.euler_zyz.norm(), 1e-15);
  const IkpResult ikp = solveIkp(model, model.reference.pose);
  ASSERT_TRUE(ikp.assembled);
  for (int i = 0; i < 6; ++i) {
    const double base = kHexapodBaseDegrees[i] * M_PI / 180.0, platform = kHexapodPlatformDegrees[i] * M_PI / 180.0;
    const Eigen::Vector3d centre(0.15 * std::cos(base), 0.15 * std::sin(base), 0.0);
    const Eigen::Vector3d axis(std::sin(base), -std::cos(base), 0.0);  // axis x radial = +z: a + turn lifts the crank
    const Eigen::Vector3d p(0.1 * std::cos(platform), 0.1 * std::sin(platform), height);
    EXPECT_LT((ikp.platform_nodes[i] - p).norm(), 1e-15) << i;
    const std::array<Eigen::Vector3d, 2> expected = crankCircleMeetsSphere(centre, axis, 0.05, p, 0.2);
    for (Branch branch : {Branch::Positive, Branch::Negative}) {
      const Eigen::Vector3d& a = ikp.chains[i].branch(branch).a;
      EXPECT_LT((a - expected[static_cast<int>(branch)]).norm(), 1e-12) << i << branchLetter(branch);
      EXPECT_NEAR((a - p).norm(), 0.2, 1e-12);  // the rod closes the chain
      EXPECT_NEAR((a - centre).norm(), 0.05, 1e-12);
      EXPECT_NEAR((a - centre).dot(axis), 0.0, 1e-12);
    }
    // The reference inputs (all 0) hold the crank horizontal and radially out: the n root.
    EXPECT_LT((expected[1] - centre * (0.2 / 0.15)).norm(), 1e-12) << i;
    EXPECT_NEAR(ikp.chains[i].branch(Branch::Negative).q, 0.0, 1e-12) << i;
  }
  const WorkingModeIdentification found = identifyWorkingMode(model, ikp, model.reference.inputs);
  ASSERT_TRUE(found.found) << found.reason;
  EXPECT_EQ(found.working_mode.name, "nnnnnn");
}

}  // namespace
}  // namespace maximal_workspace
