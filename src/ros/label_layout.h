#pragma once
// Where the text of the rviz markers goes, without ROS, so that a test can check it. rviz
// draws text facing the viewer but with depth test: a label behind a rail or a rod is
// hidden. Labels are therefore laid out on the screen of the configurations' default view
// (rviz/*.rviz), orthographically, and put at the depth of the front of the robot's drawn
// extent, where nothing of it is in front of them: titles and legends clear of that
// extent's silhouette, callouts (the transitions' labels) clear of each other and of the
// points they name, joined to them by leader lines.

#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace maximal_workspace {

using ScreenBox = Eigen::AlignedBox2d;

// The default view's axes in the base frame. View coordinates: x right and y up on the
// screen, z towards the viewer.
struct ScreenAxes {
  Eigen::Matrix3d view;  // columns: right, up, towards the viewer

  // rviz/*.rviz: an orbit view at yaw 4.3 rad and pitch 0.3 rad, seen from -x, -y, above.
  static ScreenAxes defaultView();
  Eigen::Vector3d toView(const Eigen::Vector3d& point) const { return view.transpose() * point; }
  Eigen::Vector2d project(const Eigen::Vector3d& point) const { return toView(point).head<2>(); }
  // The point `offset` away from `from` on the screen, at the same depth.
  Eigen::Vector3d moved(const Eigen::Vector3d& from, const Eigen::Vector2d& offset) const {
    return from + view.leftCols<2>() * offset;
  }
  // The base-frame point at `screen` and `depth` (view coordinates).
  Eigen::Vector3d at(const Eigen::Vector2d& screen, double depth) const {
    return view * Eigen::Vector3d(screen.x(), screen.y(), depth);
  }
};

// A text's extent on the screen as rviz draws it at `height` (the marker's scale.z):
// characters about half as wide as high, lines kLineAdvance heights apart.
constexpr double kCharWidth = 0.5;
constexpr double kLineAdvance = 1.6;
Eigen::Vector2d textSize(const std::string& text, double height);
// rviz centres a text on its position.
ScreenBox textBox(const ScreenAxes& axes, const Eigen::Vector3d& centre, const Eigen::Vector2d& size);

// The centres of two blocks of text around `extent` (the drawn robot's box in view
// coordinates), `gap` clear of its silhouette and in front of it: the title centred above
// it, the legend beside its right edge (where the default view has room), tops level.
struct FramePlacement {
  Eigen::Vector3d title;
  Eigen::Vector3d legend;
};
FramePlacement placeFrame(const ScreenAxes& axes, const Eigen::AlignedBox3d& extent, const Eigen::Vector2d& title_size,
                          const Eigen::Vector2d& legend_size, double gap);
// The centres of `count` lines kLineAdvance * height apart, top first, in a block centred at `centre`.
std::vector<Eigen::Vector3d> blockLines(const ScreenAxes& axes, const Eigen::Vector3d& centre, std::size_t count,
                                        double height);

// A text naming a point (a transition's sphere).
struct Callout {
  std::string text;
  Eigen::Vector3d point;
};
// One label for callouts whose points are close on the screen (their texts one per line),
// beside them and joined to each by a leader from `leader_start`.
struct PlacedCallout {
  std::string text;
  Eigen::Vector3d position;
  Eigen::Vector3d leader_start;
  std::vector<Eigen::Vector3d> points;
};
// Callouts within kMergeHeights text heights of each other on the screen share a label; each
// label goes to the side of its points away from the centre of `extent` (the drawn robot's
// box in view coordinates: not up through the links), clear of its points, of the others'
// points and of the labels placed before it, at the extent's front.
constexpr double kMergeHeights = 4.0;
std::vector<PlacedCallout> placeCallouts(const ScreenAxes& axes, const std::vector<Callout>& callouts,
                                         const Eigen::AlignedBox3d& extent, double height);

// Where a note about `point` goes: to its left (legends are on the right), moved up or down
// until clear of `taken`, at `depth` or in front of the point if it is nearer.
Eigen::Vector3d placeNote(const ScreenAxes& axes, const Eigen::Vector3d& point, const Eigen::Vector2d& size,
                          const std::vector<ScreenBox>& taken, double height, double depth);
// The screen boxes of placed callouts' labels and points, for placeNote.
std::vector<ScreenBox> calloutBoxes(const ScreenAxes& axes, const std::vector<PlacedCallout>& callouts, double height);

}  // namespace maximal_workspace
