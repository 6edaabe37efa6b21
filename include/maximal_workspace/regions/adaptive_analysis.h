#pragma once
// The method end to end on the adaptive workspace (issue 7): the figures of
// workspace_analysis.h at steps where a per-voxel array would not fit, for grids of x y z
// at a fixed orientation.

#include <array>
#include <vector>

#include "maximal_workspace/regions/adaptive_regions.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

struct AdaptiveAnalysis {
  explicit AdaptiveAnalysis(Grid grid_) : grid(std::move(grid_)) {}

  Grid grid;
  std::vector<WorkingMode> modes;
  int start_mode = 0;
  AdaptiveWorkspace workspace;
  AdaptiveRegionMap regions;
  AdaptiveTransitions transitions;
  std::array<AssemblyModeSummary, 2> assembly_modes;  // sign +1, then -1
  StageSeconds seconds;  // wave_front: the adaptive classification; singularities: unused

  double workspaceVolume() const { return static_cast<double>(workspace.inside_cells) * grid.cellVolume(); }
};

// As analyseWorkspace; the grid's voxel budget still bounds the box, but nothing is
// allocated per box cell. Throws InputError as analyseWorkspace does, and for a grid that
// is not x y z or more than kMaxAdaptiveModes working modes.
AdaptiveAnalysis analyseWorkspaceAdaptive(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options);

}  // namespace maximal_workspace
