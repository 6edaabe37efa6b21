#include "label_layout.h"

#include <algorithm>
#include <cmath>

namespace maximal_workspace {

namespace {

// Space kept between a label and what it must not touch, in text heights.
constexpr double kGapHeights = 1.0;

ScreenBox pointBox(const ScreenAxes& axes, const Eigen::Vector3d& point, double height) {
  const Eigen::Vector2d at = axes.project(point);
  const Eigen::Vector2d half = Eigen::Vector2d::Constant(0.5 * height);
  return ScreenBox(at - half, at + half);
}

bool clear(const ScreenBox& box, const std::vector<ScreenBox>& taken, double margin) {
  const ScreenBox kept(box.min() - Eigen::Vector2d::Constant(margin), box.max() + Eigen::Vector2d::Constant(margin));
  return std::none_of(taken.begin(), taken.end(), [&](const ScreenBox& other) { return kept.intersects(other); });
}

// The box moved up or down, the least that leaves it clear of `taken` (it stays beside
// what it names).
ScreenBox slidClear(const ScreenBox& box, const std::vector<ScreenBox>& taken, double height) {
  constexpr int kTries = 400;
  for (int k = 0; k < kTries; ++k) {
    const double shift = (k % 2 == 0 ? -1.0 : 1.0) * ((k + 1) / 2) * 0.5 * height;
    const ScreenBox moved(box.min() + Eigen::Vector2d(0.0, shift), box.max() + Eigen::Vector2d(0.0, shift));
    if (clear(moved, taken, 0.25 * height)) return moved;
  }
  return box;  // unreachable for the few labels of a plan; left where it was asked
}

// Callouts in groups whose points are within kMergeHeights text heights of another member's
// on the screen (single linkage), in the callouts' order.
std::vector<std::vector<std::size_t>> closeGroups(const ScreenAxes& axes, const std::vector<Callout>& callouts,
                                                  double height) {
  std::vector<std::size_t> group(callouts.size());
  for (std::size_t i = 0; i < callouts.size(); ++i) group[i] = i;
  for (std::size_t i = 0; i < callouts.size(); ++i) {
    for (std::size_t j = i + 1; j < callouts.size(); ++j) {
      const double apart = (axes.project(callouts[i].point) - axes.project(callouts[j].point)).norm();
      if (apart >= kMergeHeights * height || group[i] == group[j]) continue;
      const std::size_t from = group[j], to = group[i];
      std::replace(group.begin(), group.end(), from, to);
    }
  }
  std::vector<std::vector<std::size_t>> groups;
  std::vector<std::size_t> ids;  // of groups[k]
  for (std::size_t i = 0; i < callouts.size(); ++i) {
    const auto known = std::find(ids.begin(), ids.end(), group[i]);
    if (known != ids.end()) {
      groups[static_cast<std::size_t>(known - ids.begin())].push_back(i);
      continue;
    }
    ids.push_back(group[i]);
    groups.push_back({i});
  }
  return groups;
}

}  // namespace

ScreenAxes ScreenAxes::defaultView() {
  constexpr double kYaw = 4.3, kPitch = 0.3;
  // The camera looks along -towards; right is horizontal, up completes the screen.
  const Eigen::Vector3d towards(std::cos(kYaw) * std::cos(kPitch), std::sin(kYaw) * std::cos(kPitch), std::sin(kPitch));
  const Eigen::Vector3d right(-std::sin(kYaw), std::cos(kYaw), 0.0);
  ScreenAxes axes;
  axes.view << right, towards.cross(right), towards;
  return axes;
}

Eigen::Vector2d textSize(const std::string& text, double height) {
  std::size_t lines = 1, longest = 0, line = 0;
  for (const char c : text) {
    if (c == '\n') {
      ++lines;
      line = 0;
      continue;
    }
    longest = std::max(longest, ++line);
  }
  return {kCharWidth * height * static_cast<double>(longest), height * (1.0 + kLineAdvance * static_cast<double>(lines - 1))};
}

ScreenBox textBox(const ScreenAxes& axes, const Eigen::Vector3d& centre, const Eigen::Vector2d& size) {
  const Eigen::Vector2d at = axes.project(centre);
  return ScreenBox(at - 0.5 * size, at + 0.5 * size);
}

FramePlacement placeFrame(const ScreenAxes& axes, const Eigen::AlignedBox3d& extent, const Eigen::Vector2d& title_size,
                          const Eigen::Vector2d& legend_size, double gap) {
  const Eigen::Vector3d low = extent.min(), high = extent.max();
  const Eigen::Vector2d title(0.5 * (low.x() + high.x()), high.y() + gap + 0.5 * title_size.y());
  const Eigen::Vector2d legend(high.x() + gap + 0.5 * legend_size.x(), high.y() - 0.5 * legend_size.y());
  return {axes.at(title, high.z()), axes.at(legend, high.z())};
}

std::vector<Eigen::Vector3d> blockLines(const ScreenAxes& axes, const Eigen::Vector3d& centre, std::size_t count,
                                        double height) {
  std::vector<Eigen::Vector3d> lines;
  for (std::size_t k = 0; k < count; ++k) {
    const double above = (0.5 * static_cast<double>(count - 1) - static_cast<double>(k)) * kLineAdvance * height;
    lines.push_back(axes.moved(centre, Eigen::Vector2d(0.0, above)));
  }
  return lines;
}

std::vector<PlacedCallout> placeCallouts(const ScreenAxes& axes, const std::vector<Callout>& callouts,
                                         const Eigen::AlignedBox3d& extent, double height) {
  std::vector<ScreenBox> taken;
  for (const Callout& callout : callouts) taken.push_back(pointBox(axes, callout.point, height));
  std::vector<PlacedCallout> placed;
  for (const std::vector<std::size_t>& members : closeGroups(axes, callouts, height)) {
    PlacedCallout label;
    ScreenBox spread;
    for (std::size_t m : members) {
      label.text += (label.text.empty() ? "" : "\n") + callouts[m].text;
      label.points.push_back(callouts[m].point);
      spread.extend(axes.project(callouts[m].point));
    }
    const Eigen::Vector2d size = textSize(label.text, height);
    const double side = spread.center().x() >= extent.center().x() ? 1.0 : -1.0;
    const double gap = kGapHeights * height;
    const double x = side > 0.0 ? spread.max().x() + gap + 0.5 * size.x() : spread.min().x() - gap - 0.5 * size.x();
    const Eigen::Vector2d at(x, spread.center().y());
    const ScreenBox box = slidClear(ScreenBox(at - 0.5 * size, at + 0.5 * size), taken, height);
    taken.push_back(box);
    label.position = axes.at(box.center(), extent.max().z());
    const Eigen::Vector2d start(box.center().x() - side * (0.5 * size.x() + 0.25 * height), box.center().y());
    label.leader_start = axes.at(start, extent.max().z());
    placed.push_back(label);
  }
  return placed;
}

Eigen::Vector3d placeNote(const ScreenAxes& axes, const Eigen::Vector3d& point, const Eigen::Vector2d& size,
                          const std::vector<ScreenBox>& taken, double height, double depth) {
  const Eigen::Vector2d at = axes.project(point) - Eigen::Vector2d(kGapHeights * height + 0.5 * size.x(), 0.0);
  const ScreenBox box = slidClear(ScreenBox(at - 0.5 * size, at + 0.5 * size), taken, height);
  return axes.at(box.center(), std::max(depth, axes.toView(point).z()));
}

std::vector<ScreenBox> calloutBoxes(const ScreenAxes& axes, const std::vector<PlacedCallout>& callouts, double height) {
  std::vector<ScreenBox> boxes;
  for (const PlacedCallout& callout : callouts) {
    boxes.push_back(textBox(axes, callout.position, textSize(callout.text, height)));
    for (const Eigen::Vector3d& point : callout.points) boxes.push_back(pointBox(axes, point, height));
  }
  return boxes;
}

}  // namespace maximal_workspace
