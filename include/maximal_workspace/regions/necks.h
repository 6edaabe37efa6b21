#pragma once
// Where a dexterity margin changes the topology (docs/results.md, "Sensitivity to the
// margin"). A margin removes the cells where |measure| is under it; an exact region can
// then fall apart into regions that transitions no longer join: groups that were one. The
// neck between two such parts is the cell of the exact region where the widest path from
// one part to the other (the path whose smallest |measure| is largest) is narrowest: its
// |measure| is the largest margin at which the parts stay joined in that region.

#include <array>
#include <cstdint>
#include <vector>

#include "maximal_workspace/model/pose.h"
#include "maximal_workspace/model/robot_model.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

struct NeckSample {
  Pose pose;       // a cell centre
  double measure;  // |measure| of the neck's working mode there
};

struct Neck {
  std::int8_t sign = 0;            // the assembly mode
  int mode = 0;                    // working-mode index
  std::uint32_t exact_region = 0;  // the region of the exact analysis holding the neck
  // The groups (TransitionGraph::component of the analysis with the margin) the neck
  // joins: on each side the smallest id of the groups that side already joins.
  std::array<std::int32_t, 2> groups{};
  double measure = 0.0;  // |measure| at the neck: the largest margin keeping the sides joined here
  Pose pose;             // the neck cell's centre
  // The cells under the margin on a shortest path from one side to the other through the
  // neck, none under `measure`: the measure along the neck.
  std::vector<NeckSample> passage;
  // The smallest cross-section, among the grid's axis planes through the neck (lines on a
  // 2-D grid), of the cells of the exact region under the margin joined to the neck in
  // that plane: the neck's width. Its extent is per grid variable, 0 along the normal.
  int cross_section_normal = -1;  // -1 on a 1-D grid
  std::uint64_t cross_section_cells = 0;
  std::vector<double> cross_section_extent;
  bool cross_section_bounded = true;  // false: the flood stopped at kMaxCrossSectionCells
};

constexpr std::uint64_t kMaxCrossSectionCells = 1u << 20;

// The necks that `with_margin` cuts in the regions of `exact`: both analyses of one robot
// and grid, `exact` at the smaller margin (0 for the exact one). One neck per pair of
// groups of `with_margin` first joined inside an exact region, sorted by sign, then
// decreasing measure. Throws InputError when the analyses differ in grid or working modes,
// or the margins are not in that order.
std::vector<Neck> findNecks(const RobotModel& model, const WorkspaceAnalysis& exact, const WorkspaceAnalysis& with_margin);

}  // namespace maximal_workspace
