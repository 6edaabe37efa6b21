#pragma once
// Where a dexterity margin changes the topology (docs/results.md, "Sensitivity to the
// margin"). A margin removes the cells where |measure| is under it; the regions left can
// fall into groups that transitions no longer join, groups that were one. Between two
// such groups the widest route of the exact analysis (cells of one working mode joined by
// faces, and transitions between working modes; the route whose smallest |measure| is
// largest) has a narrowest place: the neck. Its |measure| is the largest margin at which
// the two groups stay joined, so the necks are the topology changes, margin by margin.

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "maximal_workspace/model/pose.h"
#include "maximal_workspace/model/robot_model.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

struct NeckSample {
  Pose pose;       // a cell centre
  int mode = 0;    // working-mode index
  double measure;  // |measure| of that working mode there
};

// Where a neck's passage meets the region (with the margin) of one side.
struct NeckEnd {
  Pose pose;     // a cell centre
  int mode = 0;  // working-mode index
};

struct Neck {
  enum class Kind : std::uint8_t { Region, Transition };
  Kind kind = Kind::Region;  // a place in one working mode's region, or a transition point
  std::int8_t sign = 0;      // the assembly mode
  int mode = 0;              // working-mode index (Transition: the one it leaves)
  int to_mode = -1;          // Transition: the working mode it enters
  // The groups (TransitionGraph::component of the analysis with the margin) the neck
  // joins: on each side the smallest id of the groups that side already joins.
  std::array<std::int32_t, 2> groups{};
  double measure = 0.0;  // the largest margin at which the two sides stay joined
  Pose pose;             // the neck cell's centre, or the transition point
  // A shortest route from the side of groups[0] to that of groups[1] through the neck,
  // over the cells under the margin, none under `measure`: the measure along the neck.
  std::vector<NeckSample> passage;
  std::array<NeckEnd, 2> ends;  // where the passage meets the sides of groups[0] and groups[1]
  // The neck's width, where |measure| is at least half the neck's. Region necks: the
  // smallest cross-section, among the grid's axis planes through the neck (lines on a 2-D
  // grid), of the cells of its working mode under the margin joined to it in that plane;
  // extent per grid variable, 0 along the normal. Transition necks (normal -1): the points
  // of its transition joined to the neck's through neighbouring cells, their count and
  // the extent of their box.
  int cross_section_normal = -1;
  std::uint64_t cross_section_cells = 0;
  std::vector<double> cross_section_extent;
  bool cross_section_bounded = true;  // false: the flood stopped at kMaxCrossSectionCells
};

constexpr std::uint64_t kMaxCrossSectionCells = 1u << 20;

// The necks between the groups of `with_margin`, found in `exact`: both analyses of one
// robot and grid, `exact` at the smaller margin (0 for the exact one). Per assembly mode,
// groups - 1 necks at most (none where the groups were not joined in `exact` either),
// sorted by sign, then decreasing measure. Throws InputError when the analyses differ in
// grid or working modes, or the margins are not in that order.
std::vector<Neck> findNecks(const RobotModel& model, const WorkspaceAnalysis& exact, const WorkspaceAnalysis& with_margin);

// The narrowest place of the widest route of `exact` in assembly mode `sign` from cell
// `from` in working mode `from_mode` to cell `to` in any of `to_modes`: its |measure| is the
// largest margin at which the analysis joins the two (the ends' own |measure| included).
// Only measure, kind, pose, mode, to_mode and sign are set. Nothing when `exact` does not
// join them at all. Throws InputError as findNecks does.
std::optional<Neck> widestRouteNeck(const RobotModel& model, const WorkspaceAnalysis& exact,
                                    const WorkspaceAnalysis& with_margin, std::int8_t sign, std::uint64_t from, int from_mode,
                                    std::uint64_t to, const std::vector<int>& to_modes);

}  // namespace maximal_workspace
