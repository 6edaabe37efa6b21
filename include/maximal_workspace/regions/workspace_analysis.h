#pragma once
// The method end to end for one robot and one grid (docs/method.md): the workspace
// connected to the start, every cell's sign of det J_DKP in every working mode, the
// singularity map, singularity-free regions per working mode, transitions, and per
// assembly mode the maximal operational workspace against the traditional one.
//
// An analysis is stored block by block (workspace/block_layout.h): a block whose cells
// agree is one value, so fine steps cost what the surfaces cost, not what the box does.
// It is immutable once made, and cheap to copy (the copies share it). Consumers ask
// through the queries below; the storage itself is the engine's own.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/regions/regions.h"
#include "maximal_workspace/regions/transitions.h"
#include "maximal_workspace/workspace/block_layout.h"
#include "maximal_workspace/workspace/cancellation.h"
#include "maximal_workspace/workspace/grid.h"

namespace maximal_workspace {

// Where a computation stands. Stages run in order: classification, regions,
// singularities, transitions, summary; `fraction` is of the whole analysis, each stage
// weighted by its share of the time measured on the delta-like robot.
struct AnalysisProgress {
  const char* stage = "";
  double fraction = 0.0;
  std::uint64_t evaluated = 0;  // poses classified so far
  std::uint64_t inside = 0;     // workspace cells, once the classification is done
  double elapsed_seconds = 0.0;
};

// What the summary stage is asked of the conditioning index (docs/kinematics.md,
// "Conditioning index"): per assembly mode, the share of the maximal workspace where it is
// at least `threshold` and its mean there.
struct ConditioningRequest {
  double threshold = 0.1;  // in [0, 1]
  // At most about this many indices are computed (cells times working modes, 5 to 7 us
  // each): the centres of every k-th cell along each grid variable, k the smallest stride
  // that keeps the workspace's cells to it.
  std::uint64_t evaluations = 1000000;
};

struct AnalysisOptions {
  // Dexterity margin: cells where |measure| is under it count as singular (0: only
  // where the sign cannot be trusted, kMeasureTolerance). docs/kinematics.md says what a
  // margin means physically.
  double margin = 0.0;
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
  // The conditioning figures, computed in the summary stage only when asked for.
  std::optional<ConditioningRequest> conditioning;
  // Bytes an analysis may take: one whose estimate (estimateAnalysisBytes) is over it is
  // refused before anything is allocated. 0: half the machine's memory.
  std::uint64_t memory_budget = 0;
  // Called from the computing threads, one call at a time, at most a few times a second.
  std::function<void(const AnalysisProgress&)> progress;
  // Asked from the computing threads, several times a second whatever the stage: when it
  // returns true the analysis stops within about a second and throws Cancelled.
  CancelCheck cancelled;
};

// What of the options decides a result, as the analysis was made with.
struct AnalysisSettings {
  double margin = 0.0;
  DebrisThreshold debris;
  bool uncoupled = false;
  double transition_tolerance = 1e-9;
};

// "exact" for margin 0, else "margin 0.001": what every output says of its analysis.
std::string marginText(double margin);

// One assembly mode: one sign of det J_DKP.
// What the interval proofs certify of a volume (docs/kinematics.md, "Certified volumes"):
// `inner`, the set's cells proven over their whole box, and the shares proven of those the
// workspace's boundary crosses; `boundary`, what is not proven of the cells that are in the
// set or face one of its cells. The set's exact volume lies in [inner, inner + boundary].
struct VolumeBounds {
  // In whole cells, rounded outward: inner down, inner + boundary up.
  std::uint64_t inner_voxels = 0, boundary_voxels = 0;
  double inner = 0.0, boundary = 0.0;
};

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
  VolumeBounds maximal_bounds, traditional_bounds, reachable_bounds;
};

// One assembly mode's maximal workspace seen through the conditioning index: at each
// sampled cell the best index of the working modes whose non-debris region of that sign
// holds it (the robot may be in any of them there).
struct ConditioningFigures {
  std::uint64_t samples = 0;           // sampled cells of the maximal workspace
  std::uint64_t well_conditioned = 0;  // of them, those whose index is at least the threshold
  // The maximal volume times well_conditioned / samples: the well-conditioned maximal workspace.
  double well_conditioned_volume = 0.0;
  double global_index = 0.0;  // the mean index over the samples: Gosselin and Angeles' GCI
};

struct ConditioningSummary {
  ConditioningRequest request;
  int stride = 1;  // every stride-th cell along each grid variable was sampled
  std::array<ConditioningFigures, 2> assembly_modes;  // sign +1, then -1
  double seconds = 0.0;  // of the summary stage's time
};

struct StageSeconds {
  double classification = 0, regions = 0, singularities = 0, transitions = 0, summary = 0, total = 0;
};

struct SingularityCounts {
  std::uint64_t dkp_entries = 0;  // (workspace cell, working mode) pairs on a DKP singularity
  std::uint64_t ikp_faces = 0;    // faces between the workspace and a cell where some chain cannot be assembled
  std::uint64_t ikp_entries = 0;  // those faces once per chain that cannot be assembled across them
  // (face, working mode) pairs where the mode meets a limit of the robot, by the limit
  // broken across the face: actuator limit, joint cone, interference.
  std::uint64_t limit_entries = 0, cone_entries = 0, interference_entries = 0;
  // Faces between two cells across which a layer thinner than the step lies: the workspace
  // or some working mode's regions do not join across them (faceCut).
  std::uint64_t thin_layer_faces = 0;
};

// An entry of the singularity map: a workspace cell where some working mode is
// DKP-singular (in the singular band, or beside a workspace cell of the other sign); a
// face of a workspace cell to a cell where some chain cannot be assembled (the IKP
// boundary); or a face across which working modes meet a limit of the robot (a wall).
struct SingularityEntry {
  enum class Kind : std::uint8_t { Dkp = 0, Ikp = 1, Limit = 2 };
  Kind kind = Kind::Dkp;
  std::uint64_t cell = 0;   // grid index of the workspace cell
  std::uint64_t modes = 0;  // Dkp: bit m set where working mode m is singular; Limit: walled
  int dim = 0;              // Ikp, Limit: the grid variable crossed, and the direction (+1 or -1)
  int direction = 0;
};

struct AnalysisData;  // the engine's storage

class WorkspaceAnalysis {
 public:
  const Grid& grid() const;
  const BlockLayout& blocks() const;
  const std::vector<WorkingMode>& modes() const;
  int startMode() const;
  bool factorised() const;  // the per-pose classifier used the couple factorisation
  const AnalysisSettings& settings() const;

  std::uint64_t voxelCount() const;  // workspace cells
  double workspaceVolume() const;
  const VolumeBounds& workspaceBounds() const;
  // Boxes of cells the classification gave to interval proofs.
  std::uint64_t boxesProven() const;
  std::uint64_t posesEvaluated() const;
  const std::vector<Region>& regions() const;
  const TransitionGraph& transitions() const;
  const std::array<AssemblyModeSummary, 2>& assemblyModes() const;  // sign +1, then -1
  // When the options asked for it.
  const std::optional<ConditioningSummary>& conditioning() const;
  const SingularityCounts& singularityCounts() const;
  const StageSeconds& seconds() const;
  // Bytes the analysis holds in memory.
  std::uint64_t memoryBytes() const;

  // Cell queries, by grid index. label: the region of working mode `mode` there, or -1
  // (singular band, or not in the workspace).
  bool inside(std::uint64_t cell) const;
  // True when the regions of working mode `mode` do not join across the face between
  // `cell` and its neighbour towards +d: a layer thinner than the step lies between their
  // centres (docs/kinematics.md, "Layers thinner than the step").
  bool faceCut(std::uint64_t cell, int d, int mode) const;
  std::int32_t label(std::uint64_t cell, int mode) const;
  // The cell belongs to the maximal operational workspace of the assembly mode `sign`:
  // some working mode has a non-debris region of that sign there.
  bool inMaximalWorkspace(std::uint64_t cell, std::int8_t sign) const;

  // The same by block (of blocks()) and cell within it; cells beyond the box are outside.
  bool inside(std::uint64_t block, int cell) const;
  std::int32_t label(std::uint64_t block, int cell, int mode) const;
  bool inMaximalWorkspace(std::uint64_t block, int cell, std::int8_t sign) const;
  // Every cell of the block has the same classification and the same region in every
  // working mode: one query at any cell answers for all.
  bool blockUniform(std::uint64_t block) const;
  // The regions of working mode `mode` at every cell of the block (blocks().cellsPerBlock()
  // values, -1 where none): what label(block, cell, mode) gives, a block at once.
  void blockLabels(std::uint64_t block, int mode, std::int32_t* labels) const;

  // The singularity map, entry by entry in block order.
  void forEachSingularity(const std::function<void(const SingularityEntry&)>& visit) const;

 private:
  friend struct AnalysisAccess;
  explicit WorkspaceAnalysis(std::shared_ptr<const AnalysisData> data) : data_(std::move(data)) {}
  std::shared_ptr<const AnalysisData> data_;
};

// Throws InputError for a bad grid, an unknown start mode, a start outside the workspace,
// or more working modes than an analysis handles; Cancelled when options.cancelled says so.
WorkspaceAnalysis analyseWorkspace(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options);

// The bytes analyseWorkspace will need at its peak for this request, from the block count
// of the grid and an analysis of the same box at a coarser step, whose surfaces (blocks
// that are not uniform, transition points) are scaled to the fine step. Throws InputError
// for a bad grid.
std::uint64_t estimateAnalysisBytes(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options);

// The memory budget an options' 0 stands for: half the machine's physical memory.
std::uint64_t defaultMemoryBudget();
// The machine's physical memory (8 GiB when the system does not say).
std::uint64_t physicalMemoryBytes();

// The working modes an analysis with these options covers, in canonical order. Throws
// InputError for an unknown name.
std::vector<WorkingMode> analysedWorkingModes(const RobotModel& model, const AnalysisOptions& options);

// The working mode at the start: `name` when given, else the reference inputs' one.
int resolveStartMode(const RobotModel& model, const std::vector<WorkingMode>& modes, const Pose& start,
                     const std::string& name);

}  // namespace maximal_workspace
