// The URDF descriptions against the kinematics: the committed files are what `mow urdf`
// makes, check_urdf accepts them, forward kinematics over the parsed URDF tree (urdfdom)
// puts every rod's far end on its platform node, and actuator limits are the robot file's.

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <urdf_parser/urdf_parser.h>

#include "maximal_workspace/description/robot_description.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/model/robot_file.h"
#include "test_support.h"
#include "urdf_kinematics.h"

namespace maximal_workspace {
namespace {

struct Committed {
  const char* robot;
  const char* urdf;
  Mechanism mechanism;
};
const Committed kCommitted[] = {{"config/delta_like.yaml", "urdf/delta_like.urdf", Mechanism::Robot},
                                {"config/delta_like.yaml", "urdf/aux_4pss_2rss.urdf", Mechanism::Auxiliary},
                                {"config/five_bar.yaml", "urdf/five_bar.urdf", Mechanism::Robot}};

TEST(Description, CommittedFilesAreWhatMowUrdfMakes) {
  for (const Committed& c : kCommitted) {
    const RobotModel model = loadRobotFile(test::sourcePath(c.robot));
    EXPECT_EQ(urdfDescription(model, c.mechanism), readTextFile(test::sourcePath(c.urdf), "urdf"))
        << c.urdf << " is stale: regenerate it with mow urdf";
  }
}

// TinyXML (urdfdom, check_urdf) forgives what strict parsers such as Python's refuse: XML
// 1.0 forbids "--" inside a comment.
void expectWellFormedComments(const std::string& text, const std::string& what) {
  for (std::size_t open = text.find("<!--"); open != std::string::npos; open = text.find("<!--", open + 4)) {
    const std::size_t close = text.find("-->", open + 4);
    ASSERT_NE(close, std::string::npos) << what << ": comment never closed";
    EXPECT_EQ(text.substr(open + 4, close - open - 4).find("--"), std::string::npos)
        << what << ": '--' inside the comment at offset " << open;
  }
}

TEST(Description, CommentsAreWellFormedXml) {
  for (const Committed& c : kCommitted) expectWellFormedComments(readTextFile(test::sourcePath(c.urdf), "urdf"), c.urdf);
}

// Issue 18: the robot file's name goes into the opening comment; one with "--" or bytes
// beyond ASCII (file names need not be UTF-8) must leave the document well-formed ASCII.
TEST(Description, AnyRobotFileNameKeepsTheDocumentWellFormed) {
  const RobotModel model =
      parseRobotFile(readTextFile(test::sourcePath("config/five_bar.yaml"), "robot"), "/tmp/five--bar-\xff.yaml");
  const std::string urdf = urdfDescription(model, Mechanism::Robot);
  expectWellFormedComments(urdf, "five--bar-\\xff.yaml");
  EXPECT_TRUE(std::all_of(urdf.begin(), urdf.end(), [](char c) { return c == '\n' || (c >= 0x20 && c < 0x7f); }));
  EXPECT_NE(urdf.find("robot file five-_bar-_.yaml;"), std::string::npos) << urdf.substr(0, 200);
}

TEST(Description, CheckUrdfAcceptsTheCommittedFiles) {
  for (const Committed& c : kCommitted) {
    const std::string command = "check_urdf " + test::sourcePath(c.urdf) + " > /dev/null 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << c.urdf;
  }
}

void expectClosure(const Committed& c, int samples) {
  const RobotModel model = loadRobotFile(test::sourcePath(c.robot));
  const urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDF(urdfDescription(model, c.mechanism));
  ASSERT_TRUE(urdf) << c.urdf;
  const std::vector<WorkingMode> modes =
      c.mechanism == Mechanism::Auxiliary ? uncoupledWorkingModes(model) : coupledWorkingModes(model);
  int closed = 0;
  for (int k = 0; k < samples; ++k) {
    Pose pose = model.reference.pose;
    pose.position += Eigen::Vector3d(test::uniform(-0.2, 0.2), test::uniform(-0.2, 0.2),
                                     model.hasOutputVariable(OutputVariable::Z) ? test::uniform(-0.2, 0.2) : 0.0);
    if (c.mechanism == Mechanism::Auxiliary) pose.euler_zyz = test::uniformVector(-0.2, 0.2);
    const IkpResult ikp = solveIkp(model, pose);
    if (!ikp.assembled) continue;
    for (const WorkingMode& mode : modes) {
      const Configuration configuration = configurationOf(pose, ikp, mode);
      const auto frames = test::linkFrames(*urdf, jointPositions(model, c.mechanism, configuration));
      const Eigen::Isometry3d& platform = frames.at(kPlatformLink);
      EXPECT_LT((platform.translation() - pose.position).norm(), 1e-9) << c.urdf;
      for (int i = 0; i < model.chainCount(); ++i) {
        const Chain& chain = *model.chains[i];
        const Eigen::Vector3d rod_end = frames.at(rodLinkName(chain)) * Eigen::Vector3d(chain.rodLength(), 0, 0);
        const Eigen::Vector3d node = platform * chain.platformNode();
        EXPECT_LT((rod_end - node).norm(), 1e-6) << c.urdf << " chain " << chain.name() << " mode " << mode.name;
        EXPECT_LT((frames.at(rodLinkName(chain)).translation() - configuration.a[i]).norm(), 1e-9);
        ++closed;
      }
    }
  }
  EXPECT_GT(closed, samples) << c.urdf;
}

TEST(Description, EveryRodClosesOnItsPlatformNodeInEveryWorkingMode) {
  for (const Committed& c : kCommitted) expectClosure(c, 40);
}

TEST(Description, ActuatorLimitsAreTheRobotFilesLimits) {
  std::string text = readTextFile(test::sourcePath("config/delta_like.yaml"), "robot file");
  const auto add_limits = [&text](const std::string& input, const std::string& range) {
    const std::string line = "  - name: " + input + "\n";
    text.replace(text.find(line), line.size(), line + "    limits: " + range + "\n");
  };
  add_limits("KC1", "[-3.0, 0.5]");
  add_limits("KC2", "[-0.1, 0.9]");
  const RobotModel model = parseRobotFile(text, "limited.yaml");
  const urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDF(urdfDescription(model, Mechanism::Robot));
  ASSERT_TRUE(urdf);
  for (const char* name : {"KC1a_actuator", "KC1b_actuator"}) {
    const auto joint = urdf->getJoint(name);
    ASSERT_TRUE(joint && joint->limits);
    EXPECT_EQ(joint->type, urdf::Joint::REVOLUTE);
    EXPECT_EQ(joint->limits->lower, -3.0);
    EXPECT_EQ(joint->limits->upper, 0.5);
  }
  for (const char* name : {"KC2a_actuator", "KC2b_actuator"}) {
    const auto joint = urdf->getJoint(name);
    ASSERT_TRUE(joint && joint->limits);
    EXPECT_EQ(joint->type, urdf::Joint::PRISMATIC);
    EXPECT_EQ(joint->limits->lower, -0.1);
    EXPECT_EQ(joint->limits->upper, 0.9);
  }
  // Without limits in the file a crank turns freely.
  EXPECT_EQ(urdf->getJoint("KC3a_actuator")->type, urdf::Joint::PRISMATIC);
  const urdf::ModelInterfaceSharedPtr open = urdf::parseURDF(urdfDescription(test::deltaLike(), Mechanism::Robot));
  EXPECT_EQ(open->getJoint("KC1a_actuator")->type, urdf::Joint::CONTINUOUS);
  // The robot drives a couple with one input: the second chain mimics the first.
  ASSERT_TRUE(open->getJoint("KC2b_actuator")->mimic);
  EXPECT_EQ(open->getJoint("KC2b_actuator")->mimic->joint_name, "KC2a_actuator");
  EXPECT_FALSE(urdf::parseURDF(urdfDescription(test::deltaLike(), Mechanism::Auxiliary))->getJoint("KC2b_actuator")->mimic);
}

// A revolute range may cross pi (issue 16): [2.5, 4.2] holds the reference crank angle
// -2.1286 one turn up (4.1546). URDF takes any lower < upper, so the joint's limit is the
// file's as written, and the joint position of that configuration is given in the same
// turn: a joint state of a configuration within the robot's limits is within the URDF's.
TEST(Description, RevoluteRangeAcrossPiIsWrittenAsGivenAndPositionsFollowIt) {
  std::string text = readTextFile(test::sourcePath("config/delta_like.yaml"), "robot file");
  const auto add_limits = [&text](const std::string& input, const std::string& range) {
    const std::string line = "  - name: " + input + "\n";
    text.replace(text.find(line), line.size(), line + "    limits: " + range + "\n");
  };
  add_limits("KC1", "[2.5, 4.2]");
  add_limits("KC3", "[0.0, 0.8]");
  const RobotModel model = parseRobotFile(text, "across_pi.yaml");
  const double reference_crank = model.reference.inputs[0];  // the file's value, in (-pi, pi]
  const Pose& pose = model.reference.pose;
  const IkpResult ikp = solveIkp(model, pose);
  const WorkingModeIdentification found = identifyWorkingMode(model, ikp, model.reference.inputs);
  ASSERT_TRUE(found.found) << found.reason;
  const Configuration configuration = configurationOf(pose, ikp, found.uncoupled);
  ASSERT_NEAR(configuration.q[0], reference_crank, 1e-9);
  ASSERT_LT(configuration.q[0], 2.5);  // below the range as written: one turn up brings it in

  for (Mechanism mechanism : {Mechanism::Robot, Mechanism::Auxiliary}) {
    const urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDF(urdfDescription(model, mechanism));
    ASSERT_TRUE(urdf);
    for (const char* name : {"KC1a_actuator", "KC1b_actuator"}) {
      const auto joint = urdf->getJoint(name);
      ASSERT_TRUE(joint && joint->limits) << name;
      EXPECT_EQ(joint->type, urdf::Joint::REVOLUTE) << name;
      EXPECT_EQ(joint->limits->lower, 2.5) << name;
      EXPECT_EQ(joint->limits->upper, 4.2) << name;
    }
    for (const char* name : {"KC3a_actuator", "KC3b_actuator"}) {
      const auto joint = urdf->getJoint(name);
      ASSERT_TRUE(joint && joint->limits) << name;
      EXPECT_EQ(joint->type, urdf::Joint::PRISMATIC) << name;
      EXPECT_EQ(joint->limits->lower, 0.0) << name;
      EXPECT_EQ(joint->limits->upper, 0.8) << name;
    }
    // A slider without limits: prismatic over the description's open range.
    const auto open_slider = urdf->getJoint("KC2a_actuator");
    ASSERT_TRUE(open_slider && open_slider->limits);
    EXPECT_EQ(open_slider->type, urdf::Joint::PRISMATIC);
    EXPECT_LT(open_slider->limits->lower, -1.0);
    EXPECT_GT(open_slider->limits->upper, 1.0);

    const JointPositions joints = jointPositions(model, mechanism, configuration);
    const auto position = [&joints](const std::string& name) -> double {
      for (std::size_t k = 0; k < joints.names.size(); ++k) {
        if (joints.names[k] == name) return joints.positions[k];
      }
      ADD_FAILURE() << "no joint position for " << name;
      return NAN;
    };
    for (const char* name : {"KC1a_actuator", "KC1b_actuator"}) {
      EXPECT_EQ(position(name), configuration.q[0] + 2.0 * M_PI) << name;
      EXPECT_NEAR(position(name), reference_crank + 2.0 * M_PI, 1e-9) << name;
      EXPECT_GE(position(name), 2.5) << name;
      EXPECT_LE(position(name), 4.2) << name;
    }
    EXPECT_EQ(position("KC3a_actuator"), configuration.q[model.chainIndex("KC3a")]);  // 0.4: a slider as it is
    // The turned crank angle is the same crank: every rod still ends on its platform node.
    const auto frames = test::linkFrames(*urdf, joints);
    const Eigen::Isometry3d& platform = frames.at(kPlatformLink);
    for (int i = 0; i < model.chainCount(); ++i) {
      const Chain& chain = *model.chains[i];
      const Eigen::Vector3d rod_end = frames.at(rodLinkName(chain)) * Eigen::Vector3d(chain.rodLength(), 0, 0);
      EXPECT_LT((rod_end - platform * chain.platformNode()).norm(), 1e-6) << chain.name();
    }
  }

  // A range within (-pi, pi], and no range at all, leave the crank angle as it is.
  std::string inside = readTextFile(test::sourcePath("config/delta_like.yaml"), "robot file");
  inside.replace(inside.find("  - name: KC1\n"), 14, "  - name: KC1\n    limits: [-3.0, 0.5]\n");
  const auto expect_crank_as_is = [&](const RobotModel& other) {
    const JointPositions joints = jointPositions(other, Mechanism::Robot, configuration);
    ASSERT_EQ(joints.names.front(), "KC1a_actuator");
    EXPECT_EQ(joints.positions.front(), configuration.q[0]) << other.source;
  };
  expect_crank_as_is(parseRobotFile(inside, "inside.yaml"));
  expect_crank_as_is(test::deltaLike());
  EXPECT_EQ(urdf::parseURDF(urdfDescription(test::deltaLike(), Mechanism::Robot))->getJoint("KC1b_actuator")->type,
            urdf::Joint::CONTINUOUS);
}

// The box of the fixed geometry from the robot files' own numbers, widened by the slider
// block's half-length (4 cm): the linear delta's rails span their stroke [0, 0.531] up
// from fixed nodes at x = +/-0.15424, y in [-0.10175, 0.1654], over the 2 cm base plate;
// the delta-like robot's rails run 1 m each way (no stroke) and its cranks, of 0.7072 m
// about (+/-0.1, -/+0.1, 0.9) on the axis (1, -1, 0), reach 0.5 along x and y and 0.7072
// along z.
TEST(Description, FixedGeometryBoxHoldsRailsCranksAndBase) {
  struct Expected {
    const char* robot;
    Eigen::Vector3d min, max;
  };
  const double crank = 0.70720024038457463, across = crank * std::sqrt(0.5), pad = 0.04;
  const Expected cases[] = {
      {"config/linear_delta.yaml", Eigen::Vector3d(-0.154240601785946, -0.101752558883258, -0.02),
       Eigen::Vector3d(0.154240601785946, 0.1654, 0.531)},
      {"config/delta_like.yaml", Eigen::Vector3d(-0.1 - across, -1.0, -1.0), Eigen::Vector3d(1.0, 1.0, 0.9 + crank)}};
  for (const Expected& e : cases) {
    const Eigen::AlignedBox3d box = fixedGeometryBox(loadRobotFile(test::sourcePath(e.robot)));
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(box.min()[k], e.min[k] - pad, 1e-9) << e.robot << " axis " << k;
      EXPECT_NEAR(box.max()[k], e.max[k] + pad, 1e-9) << e.robot << " axis " << k;
    }
  }
}

// Along other axes (a quarter turn about z: x' = y, y' = -x), the same geometry's box.
TEST(Description, FixedGeometryBoxAlongTurnedAxes) {
  const RobotModel model = loadRobotFile(test::sourcePath("config/linear_delta.yaml"));
  Eigen::Matrix3d turned;
  turned << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // columns: base y, -x, z
  const Eigen::AlignedBox3d base = fixedGeometryBox(model), along = fixedGeometryBox(model, turned);
  EXPECT_NEAR(along.min().x(), base.min().y(), 1e-12);
  EXPECT_NEAR(along.max().x(), base.max().y(), 1e-12);
  EXPECT_NEAR(along.min().y(), -base.max().x(), 1e-12);
  EXPECT_NEAR(along.max().y(), -base.min().x(), 1e-12);
  EXPECT_NEAR(along.max().z(), base.max().z(), 1e-12);
}

// The whole drawn robot: the fixed geometry with the TCP's box widened by the platform's
// farthest node (the delta-like robot's (0.15, -0.15, 0.05), and so on) and the pad.
TEST(Description, DrawnRobotBoxAddsThePlatformAroundTheTcpBox) {
  const RobotModel model = loadRobotFile(test::sourcePath("config/delta_like.yaml"));
  const double reach = std::sqrt(0.15 * 0.15 * 2 + 0.05 * 0.05) + 0.04;
  const Eigen::AlignedBox3d far(Eigen::Vector3d(2.0, 0.0, 0.5), Eigen::Vector3d(3.0, 0.5, 2.0));
  const Eigen::AlignedBox3d box = drawnRobotBox(model, far);
  EXPECT_NEAR(box.max().x(), 3.0 + reach, 1e-9);
  EXPECT_NEAR(box.max().z(), 2.0 + reach, 1e-9);
  EXPECT_NEAR(box.min().x(), fixedGeometryBox(model).min().x(), 1e-12);  // the cranks still reach further
  EXPECT_TRUE(box.contains(fixedGeometryBox(model)));
}

}  // namespace
}  // namespace maximal_workspace
