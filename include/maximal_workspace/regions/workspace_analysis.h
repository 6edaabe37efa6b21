#pragma once
// The method end to end for one robot and one grid: wave front, singularity map, regions
// per working mode, transitions, and per assembly mode the maximal operational workspace
// against the traditional one.

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "maximal_workspace/regions/regions.h"
#include "maximal_workspace/regions/transitions.h"
#include "maximal_workspace/workspace/singularity_map.h"
#include "maximal_workspace/workspace/workspace_map.h"

namespace maximal_workspace {

struct AnalysisOptions {
  double singular_threshold = 1e-3;     // |measure| below: singular band
  DebrisThreshold debris;
  bool uncoupled = false;                // the auxiliary's working modes
  // Only these working modes (names); empty: all. The maximal workspace is then the
  // union over these alone, and transitions join these alone.
  std::vector<std::string> working_modes;
  // Working mode at the start; empty: the one the robot file's reference inputs give
  // (only when the start is the reference pose).
  std::string start_mode;
  double transition_tolerance = 1e-9;
  int threads = 0;
  std::function<void(const WaveFrontProgress&)> progress;
};

// One assembly mode: one sign of det J_DKP.
struct AssemblyModeSummary {
  std::int8_t sign = 0;
  int regions = 0;          // non-debris regions of this sign, all working modes
  int debris_regions = 0;
  int transitions = 0;      // between non-debris regions
  int components = 0;       // groups of regions joined by transitions
  // Union over working modes of this sign's (non-debris) regions.
  std::uint64_t maximal_voxels = 0;
  double maximal_volume = 0.0;
  // The region holding the start in the start working mode when it has this sign, else
  // the largest region of this sign holding the start in another working mode; -1: none.
  std::int32_t traditional_region = -1;
  double traditional_volume = 0.0;
  // Union of the regions joined to the traditional one by transitions: what the robot
  // reaches from the start without crossing a DKP singularity.
  std::uint64_t reachable_voxels = 0;
  double reachable_volume = 0.0;
};

// The per assembly mode figures from regions, transitions and the voxels' labels: counts
// and the traditional region at construction, volumes from add() over every voxel.
class AssemblyModeTally {
 public:
  // start_labels[m]: the region of working mode m at the start (or -1).
  AssemblyModeTally(const std::vector<Region>& regions, const TransitionGraph& graph, const std::int32_t* start_labels,
                    int start_mode, int mode_count);
  // `voxels` voxels that all have labels[m] in working mode m.
  void add(const std::int32_t* labels, std::uint64_t voxels);
  // Adds the voxels another tally (a copy of this one, before any add) counted.
  void merge(const AssemblyModeTally& other);
  std::array<AssemblyModeSummary, 2> finish(double cell_volume) const;

 private:
  const std::vector<Region>& regions_;
  const TransitionGraph& graph_;
  int mode_count_;
  std::array<AssemblyModeSummary, 2> summaries_;
  std::array<std::int32_t, 2> reachable_component_{};
};

struct StageSeconds {
  double wave_front = 0, singularities = 0, regions = 0, transitions = 0, summary = 0, total = 0;
};

// The transition options an analysis's options imply.
TransitionOptions transitionOptions(const AnalysisOptions& options);

// Runs stage() and returns its wall time in seconds.
template <typename Stage>
double stageSeconds(const Stage& stage) {
  const auto started = std::chrono::steady_clock::now();
  stage();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

struct WorkspaceAnalysis {
  explicit WorkspaceAnalysis(Grid grid_) : grid(std::move(grid_)) {}

  Grid grid;
  std::vector<WorkingMode> modes;
  int start_mode = 0;
  bool factorised = false;  // the per-pose classifier used the couple factorisation
  WorkspaceMap map;
  SingularityMap singularities;
  RegionMap regions;
  TransitionGraph transitions;
  std::array<AssemblyModeSummary, 2> assembly_modes;  // sign +1, then -1
  StageSeconds seconds;

  double workspaceVolume() const { return static_cast<double>(map.voxelCount()) * grid.cellVolume(); }
};

// The voxel belongs to the maximal operational workspace of the assembly mode `sign`:
// some working mode has a non-debris region of that sign there.
bool inMaximalWorkspace(const WorkspaceAnalysis& analysis, std::uint32_t voxel, std::int8_t sign);
// The same for any structure: label_of(m) is the voxel's region in working mode m, or -1.
template <class LabelOf>
bool inMaximalWorkspace(const std::vector<Region>& regions, int mode_count, std::int8_t sign, const LabelOf& label_of) {
  for (int m = 0; m < mode_count; ++m) {
    const std::int32_t label = label_of(m);
    if (label >= 0 && regions[label].sign == sign && !regions[label].debris) return true;
  }
  return false;
}

// Throws InputError for a bad grid, an unknown start mode, or a start outside the workspace.
WorkspaceAnalysis analyseWorkspace(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options);

// The working modes an analysis with these options covers, in canonical order. Throws
// InputError for an unknown name.
std::vector<WorkingMode> analysedWorkingModes(const RobotModel& model, const AnalysisOptions& options);

// The working mode at the start: `name` when given, else the reference inputs' one.
int resolveStartMode(const RobotModel& model, const std::vector<WorkingMode>& modes, const Pose& start,
                     const std::string& name);

}  // namespace maximal_workspace
