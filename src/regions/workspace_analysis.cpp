#include "maximal_workspace/regions/workspace_analysis.h"

#include <algorithm>
#include <chrono>

#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/model/input_error.h"

namespace maximal_workspace {

namespace {

void summarise(WorkspaceAnalysis& analysis) {
  const int modes = analysis.map.mode_count;
  std::vector<std::int32_t> labels(modes);
  auto labelsAt = [&](std::uint32_t voxel) {
    for (int m = 0; m < modes; ++m) labels[m] = analysis.regions.label(voxel, m);
    return labels.data();
  };
  AssemblyModeTally tally(analysis.regions.regions, analysis.transitions, labelsAt(0), analysis.start_mode, modes);
  for (std::uint32_t v = 0; v < analysis.map.voxelCount(); ++v) tally.add(labelsAt(v), 1);
  analysis.assembly_modes = tally.finish(analysis.grid.cellVolume());
}

}  // namespace

AssemblyModeTally::AssemblyModeTally(const std::vector<Region>& regions, const TransitionGraph& graph,
                                     const std::int32_t* start_labels, int start_mode, int mode_count)
    : regions_(regions), graph_(graph), mode_count_(mode_count) {
  for (int a = 0; a < 2; ++a) {
    AssemblyModeSummary& summary = summaries_[a];
    summary.sign = a == 0 ? 1 : -1;
    std::vector<bool> component_seen;
    for (const Region& region : regions) {
      if (region.sign != summary.sign) continue;
      (region.debris ? summary.debris_regions : summary.regions)++;
      const std::int32_t component = graph.component[region.id];
      if (component >= static_cast<std::int32_t>(component_seen.size())) component_seen.resize(component + 1, false);
      if (!region.debris && !component_seen[component]) {
        component_seen[component] = true;
        summary.components++;
      }
    }
    for (const Transition& transition : graph.transitions) {
      summary.transitions += transition.sign == summary.sign && !regions[transition.from_region].debris &&
                             !regions[transition.to_region].debris;
    }
    const std::int32_t own = start_labels[start_mode];
    if (own >= 0 && regions[own].sign == summary.sign) {
      summary.traditional_region = own;
    } else {
      for (int m = 0; m < mode_count; ++m) {
        const std::int32_t label = start_labels[m];
        if (label >= 0 && regions[label].sign == summary.sign &&
            (summary.traditional_region < 0 || regions[label].voxels > regions[summary.traditional_region].voxels)) {
          summary.traditional_region = label;
        }
      }
    }
    if (summary.traditional_region >= 0) summary.traditional_volume = regions[summary.traditional_region].volume;
    reachable_component_[a] = summary.traditional_region >= 0 ? graph.component[summary.traditional_region] : -1;
  }
}

void AssemblyModeTally::add(const std::int32_t* labels, std::uint64_t voxels) {
  for (int a = 0; a < 2; ++a) {
    bool in_maximal = false, in_reachable = false;
    for (int m = 0; m < mode_count_; ++m) {
      const std::int32_t label = labels[m];
      if (label < 0 || regions_[label].debris) continue;
      in_maximal = in_maximal || regions_[label].sign == summaries_[a].sign;
      in_reachable = in_reachable || graph_.component[label] == reachable_component_[a];
    }
    summaries_[a].maximal_voxels += in_maximal ? voxels : 0;
    summaries_[a].reachable_voxels += in_reachable ? voxels : 0;
  }
}

void AssemblyModeTally::merge(const AssemblyModeTally& other) {
  for (int a = 0; a < 2; ++a) {
    summaries_[a].maximal_voxels += other.summaries_[a].maximal_voxels;
    summaries_[a].reachable_voxels += other.summaries_[a].reachable_voxels;
  }
}

std::array<AssemblyModeSummary, 2> AssemblyModeTally::finish(double cell_volume) const {
  std::array<AssemblyModeSummary, 2> result = summaries_;
  for (AssemblyModeSummary& summary : result) {
    summary.maximal_volume = static_cast<double>(summary.maximal_voxels) * cell_volume;
    summary.reachable_volume = static_cast<double>(summary.reachable_voxels) * cell_volume;
  }
  return result;
}

TransitionOptions transitionOptions(const AnalysisOptions& options) {
  return TransitionOptions{options.transition_tolerance, options.singular_threshold, options.uncoupled, options.threads};
}

bool inMaximalWorkspace(const WorkspaceAnalysis& analysis, std::uint32_t voxel, std::int8_t sign) {
  return inMaximalWorkspace(analysis.regions.regions, analysis.map.mode_count, sign,
                            [&](int mode) { return analysis.regions.label(voxel, mode); });
}

std::vector<WorkingMode> analysedWorkingModes(const RobotModel& model, const AnalysisOptions& options) {
  const std::vector<WorkingMode> all = options.uncoupled ? uncoupledWorkingModes(model) : coupledWorkingModes(model);
  if (options.working_modes.empty()) return all;
  for (const std::string& name : options.working_modes) {
    if (findWorkingMode(all, name) == nullptr) {
      throw InputError("unknown working mode '" + name + "' (known: " + workingModeNames(all) + ")");
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
    throw InputError("unknown working mode '" + name + "' (analysed: " + workingModeNames(modes) + ")");
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

WorkspaceAnalysis analyseWorkspace(const RobotModel& model, const GridSpec& spec, const AnalysisOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  WorkspaceAnalysis analysis{Grid(model, spec)};
  const Grid& grid = analysis.grid;
  analysis.modes = analysedWorkingModes(model, options);
  analysis.start_mode = resolveStartMode(model, analysis.modes, grid.spec().start, options.start_mode);
  bool orientation_fixed = true;
  for (OutputVariable variable : grid.spec().variables) orientation_fixed = orientation_fixed && !isRotational(variable);
  const PoseClassifier classifier(model, analysis.modes, grid.spec().start, orientation_fixed);
  analysis.factorised = classifier.factorised();

  StageSeconds& seconds = analysis.seconds;
  seconds.wave_front = stageSeconds([&] {
    analysis.map = propagateWaveFront(grid, classifier, WaveFrontOptions{options.singular_threshold, options.threads, options.progress});
  });
  seconds.singularities =
      stageSeconds([&] { analysis.singularities = findSingularities(model, grid, classifier, analysis.map, options.threads); });
  seconds.regions = stageSeconds([&] { analysis.regions = labelRegions(grid, analysis.map, options.debris, options.threads); });
  seconds.transitions = stageSeconds([&] {
    analysis.transitions = findTransitions(model, grid, classifier, analysis.map, analysis.singularities, analysis.regions,
                                           transitionOptions(options));
  });
  seconds.summary = stageSeconds([&] { summarise(analysis); });
  seconds.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return analysis;
}

}  // namespace maximal_workspace
