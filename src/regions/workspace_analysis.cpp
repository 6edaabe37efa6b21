#include "maximal_workspace/regions/workspace_analysis.h"

#include <algorithm>
#include <chrono>
#include <mutex>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "regions/analysis_data.h"
#include "regions/conditioning_summary.h"
#include "regions/memory_estimate.h"
#include "regions/singularities.h"
#include "regions/transition_search.h"
#include "workspace/classification.h"

namespace maximal_workspace {

namespace {

using Clock = std::chrono::steady_clock;

// Each stage's share of an analysis's time (the delta-like robot at 2 and 3 mm: 0.64,
// 0.07, 0.05, 0.16 and 0.08 at both), so the fraction reported moves evenly with time
// whatever the stage.
struct StageWeight {
  const char* name;
  double weight;
};
constexpr StageWeight kStages[] = {
    {"classification", 0.64}, {"regions", 0.07}, {"singularities", 0.05}, {"transitions", 0.16}, {"summary", 0.08}};

// Reports AnalysisProgress over the stages, throttled to five calls a second.
class StageProgress {
 public:
  StageProgress(const std::function<void(const AnalysisProgress&)>& report, const CancelCheck& cancelled)
      : report_(report), cancelled_(cancelled), started_(Clock::now()) {}

  // Enters stage `index` of kStages.
  void stage(int index) {
    throwIfCancelled(cancelled_);
    const std::lock_guard<std::mutex> lock(mutex_);
    stage_ = index;
    before_ = 0.0;
    for (int s = 0; s < index; ++s) before_ += kStages[s].weight;
    reportLocked(0.0, true);
  }
  // Every stage reports as it goes: where it may also stop.
  void update(double stage_fraction) {
    throwIfCancelled(cancelled_);
    const std::lock_guard<std::mutex> lock(mutex_);
    reportLocked(stage_fraction, false);
  }
  void setEvaluated(std::uint64_t evaluated) { progress_.evaluated = evaluated; }
  void setInside(std::uint64_t inside) { progress_.inside = inside; }
  double elapsed() const { return std::chrono::duration<double>(Clock::now() - started_).count(); }

 private:
  void reportLocked(double stage_fraction, bool always) {
    if (!report_) return;
    const Clock::time_point now = Clock::now();
    if (!always && now - last_ < std::chrono::milliseconds(200)) return;
    last_ = now;
    progress_.stage = kStages[stage_].name;
    progress_.fraction = std::min(1.0, before_ + kStages[stage_].weight * stage_fraction);
    progress_.elapsed_seconds = elapsed();
    report_(progress_);
  }

  const std::function<void(const AnalysisProgress&)>& report_;
  const CancelCheck& cancelled_;
  const Clock::time_point started_;
  std::mutex mutex_;
  Clock::time_point last_{};
  int stage_ = 0;
  double before_ = 0.0;
  AnalysisProgress progress_;
};

// Runs stage() and returns its wall time in seconds.
template <typename Stage>
double stageSeconds(const Stage& stage) {
  const Clock::time_point started = Clock::now();
  stage();
  return std::chrono::duration<double>(Clock::now() - started).count();
}

// The traditional workspace starts in the start working mode: it must keep the robot's
// limits at the start.
void checkStartLimits(const RobotModel& model, const Pose& start, const WorkingMode& mode) {
  const RobotConstraints constraints(model);
  const IkpResult ikp = solveIkp(model, start);
  if (!constraints.active() || !ikp.assembled) return;  // no limits, or startCell says why
  const std::string broken = constraints.violationText(start, ikp, mode);
  if (!broken.empty()) throw InputError("the start working mode " + mode.name + " breaks a limit at the start: " + broken);
}

// Refuses a request whose estimate is over the budget, before anything is allocated.
void admit(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  const std::uint64_t budget = options.memory_budget > 0 ? options.memory_budget : defaultMemoryBudget();
  // Under the ceiling the estimate's coarse pass (about 0.8 s of a 2 mm run) decides nothing.
  if (budget == ~std::uint64_t{0} || analysisMemoryCeiling(model, spec, options) <= budget) return;
  const MemoryEstimate estimate = estimateAnalysisMemory(model, spec, options);
  if (estimate.bytes <= budget) return;
  throw InputError(overBudgetText(estimate, budget) + "; use a larger step, smaller bounds or a larger budget");
}

// The stages in order; with `whole` false only those that decide the memory an analysis
// takes (cells, regions, transitions): the counts of singularities and the summary are
// left out.
std::shared_ptr<AnalysisData> analyse(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options,
                                      bool whole) {
  auto data = std::make_shared<AnalysisData>(Grid(model, spec));
  const Grid& grid = data->grid;
  data->modes = analysedWorkingModes(model, options);
  data->start_mode = resolveStartMode(model, data->modes, grid.spec().start, options.start_mode);
  checkStartLimits(model, grid.spec().start, data->modes[data->start_mode]);
  data->settings = AnalysisSettings{options.margin, options.debris, options.uncoupled,
                                    options.transition_tolerance};
  const PoseClassifier classifier(model, data->modes, grid.spec().start, grid.orientationFixed());
  const MeasureCertificate certificate(model, data->modes, grid.spec().start);
  data->factorised = classifier.factorised();

  StageProgress progress(options.progress, options.cancelled);
  StageSeconds& seconds = data->seconds;
  progress.stage(0);
  seconds.classification = stageSeconds([&] {
    ClassificationOptions classification{options.margin, options.threads, {}, options.cancelled};
    classification.progress = [&progress](double fraction, std::uint64_t evaluated) {
      progress.setEvaluated(evaluated);
      progress.update(fraction);
    };
    data->cells = classifyWorkspace(grid, classifier, certificate, classification);
  });
  data->singularities.thin_layer_faces = data->cells.cuts.faces.size();
  progress.setEvaluated(data->cells.evaluated);
  progress.setInside(data->cells.inside_cells);
  const auto stage_update = [&progress](double fraction) { progress.update(fraction); };
  progress.stage(1);
  seconds.regions = stageSeconds(
      [&] { data->regions = labelRegions(grid, data->cells, options.debris, options.threads, stage_update, options.cancelled); });
  if (whole) {
    progress.stage(2);
    seconds.singularities = stageSeconds([&] {
      data->singularities.dkp_entries = countDkpEntries(data->cells, options.threads, options.cancelled);
      countWallEntries(model, grid, data->modes, data->cells, options.threads, &data->singularities, options.cancelled);
    });
  }
  progress.stage(3);
  seconds.transitions = stageSeconds([&] {
    TransitionOptions transition{options.transition_tolerance, options.margin, options.uncoupled,
                                 options.threads, stage_update};
    TransitionSearch search = findTransitions(model, grid, classifier, data->cells, data->regions, transition);
    data->transitions = std::move(search.graph);
    data->singularities.ikp_faces = search.ikp_faces;
    data->singularities.ikp_entries = search.ikp_entries;
  });
  if (!whole) return data;
  progress.stage(4);
  seconds.summary = stageSeconds([&] {
    // With the conditioning figures, the volumes report the first half of the stage.
    const double share = options.conditioning ? 0.5 : 1.0;
    data->assembly_modes = summariseAssemblyModes(*data, &certificate, options.threads, &data->workspace_bounds,
                                                  [&](double fraction) { stage_update(share * fraction); });
    // The proofs served the certified volumes alone: not held, nor stored.
    data->cells.proven = ProofMap();
    if (!options.conditioning) return;
    data->conditioning = summariseConditioning(model, *data, *options.conditioning, options.threads,
                                               [&](double fraction) { stage_update(0.5 + 0.5 * fraction); });
  });
  seconds.total = progress.elapsed();
  return data;
}

}  // namespace

WorkspaceAnalysis analyseWorkspace(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  admit(model, spec, options);
  return AnalysisAccess::make(analyse(model, spec, options, true));
}

std::shared_ptr<const AnalysisData> analyseFootprint(const RobotModel& model, const GridSpec& spec,
                                                     const AnalysisOptions& options) {
  return analyse(model, spec, options, false);
}

std::string marginText(double margin) { return margin > 0.0 ? "margin " + numberText(margin) : std::string("exact"); }

const Grid& WorkspaceAnalysis::grid() const { return data_->grid; }
const BlockLayout& WorkspaceAnalysis::blocks() const { return data_->cells.layout; }
const std::vector<WorkingMode>& WorkspaceAnalysis::modes() const { return data_->modes; }
int WorkspaceAnalysis::startMode() const { return data_->start_mode; }
bool WorkspaceAnalysis::factorised() const { return data_->factorised; }
const AnalysisSettings& WorkspaceAnalysis::settings() const { return data_->settings; }
std::uint64_t WorkspaceAnalysis::voxelCount() const { return data_->cells.inside_cells; }
double WorkspaceAnalysis::workspaceVolume() const {
  return static_cast<double>(data_->cells.inside_cells) * data_->grid.cellVolume();
}
std::uint64_t WorkspaceAnalysis::posesEvaluated() const { return data_->cells.evaluated; }
std::uint64_t WorkspaceAnalysis::boxesProven() const { return data_->cells.proofs; }
const VolumeBounds& WorkspaceAnalysis::workspaceBounds() const { return data_->workspace_bounds; }
bool WorkspaceAnalysis::faceCut(std::uint64_t cell, int d, int mode) const { return data_->cells.cuts.cut(cell, d, mode); }
const std::vector<Region>& WorkspaceAnalysis::regions() const { return data_->regions.regions; }
const TransitionGraph& WorkspaceAnalysis::transitions() const { return data_->transitions; }
const std::array<AssemblyModeSummary, 2>& WorkspaceAnalysis::assemblyModes() const { return data_->assembly_modes; }
const std::optional<ConditioningSummary>& WorkspaceAnalysis::conditioning() const { return data_->conditioning; }
const SingularityCounts& WorkspaceAnalysis::singularityCounts() const { return data_->singularities; }
const StageSeconds& WorkspaceAnalysis::seconds() const { return data_->seconds; }

std::uint64_t WorkspaceAnalysis::memoryBytes() const {
  const AnalysisData& data = *data_;
  std::uint64_t bytes = data.cells.codes.bytes() + data.cells.patterns.patterns.size() * sizeof(SignPattern);
  for (const LabelLayer& layer : data.regions.layers) bytes += layer.bytes();
  bytes += data.regions.regions.size() * sizeof(Region);
  bytes += data.transitions.points.size() * (sizeof(TransitionPoint) + sizeof(std::uint32_t));
  bytes += data.transitions.transitions.size() * sizeof(Transition) + data.transitions.component.size() * sizeof(std::int32_t);
  return bytes;
}

bool WorkspaceAnalysis::inside(std::uint64_t block, int cell) const {
  return codeInside(data_->cells.codes.code(block, cell));
}

std::int32_t WorkspaceAnalysis::label(std::uint64_t block, int cell, int mode) const {
  return data_->regions.label(block, cell, mode);
}

bool WorkspaceAnalysis::inMaximalWorkspace(std::uint64_t block, int cell, std::int8_t sign) const {
  const std::vector<Region>& regions = data_->regions.regions;
  for (std::size_t m = 0; m < data_->modes.size(); ++m) {
    const std::int32_t region = label(block, cell, static_cast<int>(m));
    if (region >= 0 && regions[region].sign == sign && !regions[region].debris) return true;
  }
  return false;
}

bool WorkspaceAnalysis::blockUniform(std::uint64_t block) const {
  if (!data_->cells.codes.uniform(block)) return false;
  for (const LabelLayer& layer : data_->regions.layers) {
    if (!layer.uniform(block)) return false;
  }
  return true;
}

void WorkspaceAnalysis::blockLabels(std::uint64_t block, int mode, std::int32_t* labels) const {
  const LabelLayer& layer = data_->regions.layers[mode];
  const int cells = data_->cells.layout.cellsPerBlock();
  if (layer.uniform(block)) {
    std::fill_n(labels, cells, layer.label(block, 0));
    return;
  }
  const LabelLayer::LocalPage local = layer.localPage(block);
  const std::int32_t* local_labels = layer.localLabels(block);
  for (int c = 0; c < cells; ++c) {
    const std::uint16_t component = local[c];
    labels[c] = component == LabelLayer::kNoLocal ? kNoLabel : local_labels[component];
  }
}

bool WorkspaceAnalysis::inside(std::uint64_t cell) const {
  std::uint64_t block = 0;
  int in_block = 0;
  return data_->cells.layout.locate(cell, &block, &in_block) && inside(block, in_block);
}

std::int32_t WorkspaceAnalysis::label(std::uint64_t cell, int mode) const {
  std::uint64_t block = 0;
  int in_block = 0;
  return data_->cells.layout.locate(cell, &block, &in_block) ? label(block, in_block, mode) : kNoLabel;
}

bool WorkspaceAnalysis::inMaximalWorkspace(std::uint64_t cell, std::int8_t sign) const {
  std::uint64_t block = 0;
  int in_block = 0;
  return data_->cells.layout.locate(cell, &block, &in_block) && inMaximalWorkspace(block, in_block, sign);
}

void WorkspaceAnalysis::forEachSingularity(const std::function<void(const SingularityEntry&)>& visit) const {
  const WorkspaceCells& cells = data_->cells;
  const BlockLayout& layout = cells.layout;
  const std::vector<std::uint8_t> with_outside = blocksWithOutside(cells, 1);
  const DkpScan dkp(cells);
  const WallScan walls(cells);
  SingularityEntry entry;
  // Block by block, DKP entries first, then IKP faces and walls, so all come in block order.
  for (std::uint64_t block = 0; block < layout.blockCount(); ++block) {
    entry.kind = SingularityEntry::Kind::Dkp;
    dkp.scan(block, block + 1, [&](std::uint64_t b, int c, std::uint64_t modes) {
      entry.cell = layout.gridIndex(b, c);
      entry.modes = modes;
      visit(entry);
    });
    entry.kind = SingularityEntry::Kind::Ikp;
    entry.modes = 0;
    forEachIkpFace(cells, with_outside, block, block + 1, [&](std::uint64_t b, int c, int d, int direction) {
      entry.cell = layout.gridIndex(b, c);
      entry.dim = d;
      entry.direction = direction;
      visit(entry);
    });
    entry.kind = SingularityEntry::Kind::Limit;
    walls.scan(block, block + 1, [&](std::uint64_t b, int c, int d, int direction, std::uint64_t modes) {
      entry.cell = layout.gridIndex(b, c);
      entry.modes = modes;
      entry.dim = d;
      entry.direction = direction;
      visit(entry);
    });
  }
}

std::vector<WorkingMode> analysedWorkingModes(const RobotModel& model, const AnalysisOptions& options) {
  const std::vector<WorkingMode> all = options.uncoupled ? uncoupledWorkingModes(model) : coupledWorkingModes(model);
  if (options.working_modes.empty()) return all;
  for (const std::string& name : options.working_modes) {
    if (findWorkingMode(all, name) == nullptr) {
      throw InputError("unknown working mode '" + clippedText(name) + "' (known: " + workingModeNames(all) + ")");
    }
  }
  std::vector<WorkingMode> chosen;
  for (const WorkingMode& mode : all) {
    if (std::find(options.working_modes.begin(), options.working_modes.end(), mode.name) != options.working_modes.end()) {
      chosen.push_back(mode);
    }
  }
  return chosen;
}

int resolveStartMode(const RobotModel& model, const std::vector<WorkingMode>& modes, const Pose& start,
                     const std::string& name) {
  if (!name.empty()) {
    for (std::size_t m = 0; m < modes.size(); ++m) {
      if (modes[m].name == name) return static_cast<int>(m);
    }
    throw InputError("unknown working mode '" + clippedText(name) + "' (analysed: " + workingModeNames(modes) + ")");
  }
  const Pose& reference = model.reference.pose;
  if (model.reference.inputs.empty() || start.position != reference.position || start.euler_zyz != reference.euler_zyz) {
    throw InputError("give the start working mode: the robot file's reference inputs only tell it at the reference pose");
  }
  const WorkingModeIdentification found =
      identifyWorkingMode(model, solveIkp(model, reference), model.reference.inputs);
  if (!found.found) throw InputError("the working mode at the reference pose is unknown: " + found.reason);
  // Coupled names have a letter per input, uncoupled ones a letter per chain.
  const bool coupled_names = !modes.empty() && static_cast<int>(modes.front().name.size()) == model.inputCount();
  const std::string mode_name = coupled_names && found.coupled ? found.working_mode.name : found.uncoupled.name;
  for (std::size_t m = 0; m < modes.size(); ++m) {
    if (modes[m].name == mode_name) return static_cast<int>(m);
  }
  throw InputError("the robot starts in working mode " + mode_name + ", which is not among those analysed (" +
                   workingModeNames(modes) + "); give the start working mode");
}

}  // namespace maximal_workspace
