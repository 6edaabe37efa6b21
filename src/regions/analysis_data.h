#pragma once
// What a WorkspaceAnalysis holds. Internal to the engine: the state file (io/
// workspace_state.cpp) stores and restores it; every other consumer uses the queries of
// maximal_workspace/regions/workspace_analysis.h.

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "maximal_workspace/kinematics/measure_certificate.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "regions/region_labels.h"
#include "workspace/block_storage.h"

namespace maximal_workspace {

struct AnalysisData {
  explicit AnalysisData(Grid grid_) : grid(std::move(grid_)) {}

  Grid grid;
  std::vector<WorkingMode> modes;
  int start_mode = 0;
  bool factorised = false;
  AnalysisSettings settings;
  WorkspaceCells cells;
  RegionLabels regions;
  TransitionGraph transitions;
  SingularityCounts singularities;
  std::array<AssemblyModeSummary, 2> assembly_modes;  // sign +1, then -1
  std::optional<ConditioningSummary> conditioning;
  VolumeBounds workspace_bounds;
  StageSeconds seconds;
};

struct AnalysisAccess {
  static WorkspaceAnalysis make(std::shared_ptr<const AnalysisData> data) { return WorkspaceAnalysis(std::move(data)); }
  static const AnalysisData& data(const WorkspaceAnalysis& analysis) { return *analysis.data_; }
};

// Per assembly mode, the figures of regions, transitions and cells: counts, the
// traditional region, the maximal and reachable volumes, and what the proofs certify of
// them and (`workspace_bounds`) of the workspace; `certificate` (optional) proves shares of
// the cells the workspace's boundary crosses. progress(fraction) is called from the worker
// threads, serialised.
std::array<AssemblyModeSummary, 2> summariseAssemblyModes(const AnalysisData& data, const MeasureCertificate* certificate,
                                                          int threads, VolumeBounds* workspace_bounds,
                                                          const std::function<void(double)>& progress = {});

// The stages whose results decide the memory an analysis takes (cells, regions,
// transitions), without its singularity counts, summary and admission: the memory
// estimate's coarse pass (regions/memory_estimate.cpp).
std::shared_ptr<const AnalysisData> analyseFootprint(const RobotModel& model, const GridSpec& spec,
                                                     const AnalysisOptions& options);

}  // namespace maximal_workspace
