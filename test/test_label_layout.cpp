// Where the rviz labels go (src/ros/label_layout.h), on the default view's screen with each
// text's extent estimated from its characters: titles and legends outside the whole drawn
// robot, callouts apart from each other and from the points they name.

#include <algorithm>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "label_layout.h"
#include "maximal_workspace/description/robot_description.h"
#include "maximal_workspace/model/robot_file.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> result;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) result.push_back(line);
  return result;
}

TEST(LabelLayout, TitleAndLegendStayOutsideTheWholeDrawnRobot) {
  const double height = 0.05;
  const Eigen::Vector2d title = textSize(std::string(80, 'x') + "\n" + std::string(80, 'x'), height);
  const Eigen::Vector2d legend = textSize("working mode ppp\nworking mode ppn\nworking mode pnp\nworking mode pnn\n"
                                          "working mode npp\nworking mode npn\nworking mode nnp\nworking mode nnn\n"
                                          "white ball: a transition",
                                          height);
  const ScreenAxes axes = ScreenAxes::defaultView();
  for (const char* robot : {"config/delta_like.yaml", "config/linear_delta.yaml", "config/rotary_delta.yaml",
                            "config/hexapod_6rss_long.yaml"}) {
    const RobotModel model = loadRobotFile(test::sourcePath(robot));
    const Eigen::Vector3d tcp = axes.toView(model.reference.pose.position);
    const Eigen::AlignedBox3d workspace(tcp - Eigen::Vector3d::Constant(0.1), tcp + Eigen::Vector3d::Constant(0.1));
    const Eigen::AlignedBox3d extent = drawnRobotBox(model, workspace, axes.view);
    const FramePlacement place = placeFrame(axes, extent, title, legend, 2.0 * height);
    const ScreenBox robot_box(extent.min().head<2>(), extent.max().head<2>());  // its silhouette
    const ScreenBox title_box = textBox(axes, place.title, title), legend_box = textBox(axes, place.legend, legend);
    EXPECT_GE(axes.toView(place.title).z(), extent.max().z() - 1e-9) << robot << ": the title behind the robot's front";
    EXPECT_GE(axes.toView(place.legend).z(), extent.max().z() - 1e-9) << robot << ": the legend behind the robot's front";
    EXPECT_FALSE(title_box.intersects(robot_box)) << robot << ": the title over the robot";
    EXPECT_FALSE(legend_box.intersects(robot_box)) << robot << ": the legend over the robot";
    EXPECT_FALSE(title_box.intersects(legend_box)) << robot << ": the title over the legend";
    EXPECT_GT(title_box.min().y(), robot_box.max().y()) << robot << ": the title above the robot";
    EXPECT_GT(legend_box.min().x(), robot_box.max().x()) << robot << ": the legend right of the robot";
    // Its lines within the block, one under the other.
    const std::vector<Eigen::Vector3d> at = blockLines(axes, place.legend, 9, height);
    for (std::size_t k = 0; k < at.size(); ++k) {
      EXPECT_TRUE(legend_box.contains(axes.project(at[k]))) << robot << " line " << k;
      if (k > 0) EXPECT_NEAR(axes.project(at[k - 1]).y() - axes.project(at[k]).y(), kLineAdvance * height, 1e-12);
    }
  }
}

// The demo's two transitions, a few cm apart: one label of two lines, beside both spheres,
// on the side away from the robot's centre, its leader starting just off its near edge.
TEST(LabelLayout, CloseTransitionsShareOneLabelBesideThem) {
  const double height = 0.07;
  const ScreenAxes axes = ScreenAxes::defaultView();
  const std::vector<Callout> callouts = {{"KC1 n->p", Eigen::Vector3d(0.78, 0.45, 0.09)},
                                         {"KC2 p->n", Eigen::Vector3d(0.76, 0.43, 0.10)}};
  const auto around = [&](const Eigen::Vector3d& centre) {
    const Eigen::Vector3d at = axes.toView(centre);
    return Eigen::AlignedBox3d(at - Eigen::Vector3d::Constant(0.5), at + Eigen::Vector3d::Constant(0.5));
  };
  const Eigen::AlignedBox3d extent = around(Eigen::Vector3d(0.3, 0.2, 0.5));  // its centre left of them on the screen
  const std::vector<PlacedCallout> placed = placeCallouts(axes, callouts, extent, height);
  ASSERT_EQ(placed.size(), 1u);
  EXPECT_EQ(lines(placed[0].text), (std::vector<std::string>{"KC1 n->p", "KC2 p->n"}));
  const ScreenBox box = textBox(axes, placed[0].position, textSize(placed[0].text, height));
  for (const Callout& callout : callouts) {
    EXPECT_GT(box.min().x(), axes.project(callout.point).x()) << "the label right of " << callout.text;
  }
  const Eigen::Vector2d start = axes.project(placed[0].leader_start);
  EXPECT_FALSE(box.contains(start));
  EXPECT_LT(box.min().x() - start.x(), 0.5 * height);
  EXPECT_NEAR(axes.toView(placed[0].position).z(), extent.max().z(), 1e-9) << "at the robot's front";
  // Mirrored: the robot's centre right of them puts the label on their left.
  const std::vector<PlacedCallout> left = placeCallouts(axes, callouts, around(Eigen::Vector3d(1.5, 0.0, 0.1)), height);
  ASSERT_EQ(left.size(), 1u);
  const ScreenBox left_box = textBox(axes, left[0].position, textSize(left[0].text, height));
  for (const Callout& callout : callouts) EXPECT_LT(left_box.max().x(), axes.project(callout.point).x());
}

// Random transitions: every one named once, no two labels overlapping, no label over a
// sphere, each label beside its own spheres.
TEST(LabelLayout, LabelsNeverOverlapEachOtherOrTheSpheres) {
  std::mt19937 random(31);
  std::uniform_real_distribution<double> coordinate(0.0, 1.0), size(0.02, 0.08);
  std::uniform_int_distribution<int> count(1, 10), width(4, 14);
  const ScreenAxes axes = ScreenAxes::defaultView();
  for (int trial = 0; trial < 200; ++trial) {
    const double height = size(random);
    std::vector<Callout> callouts(static_cast<std::size_t>(count(random)));
    for (std::size_t k = 0; k < callouts.size(); ++k) {
      callouts[k].text = "T" + std::to_string(k) + std::string(static_cast<std::size_t>(width(random)), '-');
      // Clustered often: a fifth of the cube holds them all in some trials.
      const double spread = trial % 2 == 0 ? 1.0 : 0.2;
      callouts[k].point = spread * Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random));
    }
    const Eigen::Vector3d centre = axes.toView(Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random)));
    const Eigen::AlignedBox3d extent(centre - Eigen::Vector3d::Constant(1.0), centre + Eigen::Vector3d::Constant(1.0));
    const std::vector<PlacedCallout> placed = placeCallouts(axes, callouts, extent, height);
    std::vector<std::string> named;
    std::vector<ScreenBox> boxes;
    for (const PlacedCallout& label : placed) {
      for (const std::string& line : lines(label.text)) named.push_back(line);
      boxes.push_back(textBox(axes, label.position, textSize(label.text, height)));
      for (const Eigen::Vector3d& point : label.points) {
        const Eigen::Vector2d at = axes.project(point);
        EXPECT_LT(std::abs(at.y() - boxes.back().center().y()), 20.0 * height) << "trial " << trial << ": far from its sphere";
      }
    }
    std::vector<std::string> expected;
    for (const Callout& callout : callouts) expected.push_back(callout.text);
    std::sort(named.begin(), named.end());
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(named, expected) << "trial " << trial;
    for (std::size_t a = 0; a < boxes.size(); ++a) {
      for (std::size_t b = a + 1; b < boxes.size(); ++b) {
        EXPECT_FALSE(boxes[a].intersects(boxes[b])) << "trial " << trial << ": labels " << a << " and " << b;
      }
      for (const Callout& callout : callouts) {
        EXPECT_FALSE(boxes[a].contains(axes.project(callout.point))) << "trial " << trial << ": over " << callout.text;
      }
    }
  }
}

// A goal's note: to the goal's left, near it, clear of the labels already there.
TEST(LabelLayout, ANoteGoesLeftOfItsGoalClearOfTheLabels) {
  const double height = 0.07;
  const ScreenAxes axes = ScreenAxes::defaultView();
  const Eigen::Vector3d goal(0.5, 0.2, 0.3);
  const Eigen::Vector2d size = textSize("no plan: the goal is outside the workspace of\nassembly mode +", height);
  const Eigen::Vector2d at = axes.project(goal);
  // A label where the note would go first.
  const std::vector<ScreenBox> taken = {ScreenBox(at - Eigen::Vector2d(1.0, 0.1), at + Eigen::Vector2d(-0.05, 0.1))};
  const double front = axes.toView(goal).z() + 0.4;
  const Eigen::Vector3d placed = placeNote(axes, goal, size, taken, height, front);
  EXPECT_NEAR(axes.toView(placed).z(), front, 1e-9);
  const ScreenBox note = textBox(axes, placed, size);
  EXPECT_FALSE(note.intersects(taken[0]));
  EXPECT_LT(note.max().x(), at.x());
  EXPECT_LT(at.x() - note.max().x(), 2.0 * height);
  EXPECT_LT(std::abs(note.center().y() - at.y()), 0.5 * size.y() + 0.2 + 2.0 * height);
}

}  // namespace
}  // namespace maximal_workspace
