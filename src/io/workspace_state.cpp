#include "maximal_workspace/io/workspace_state.h"

#include <algorithm>
#include <cstring>

#include "io/state_archive.h"
#include "regions/analysis_data.h"

namespace maximal_workspace {

namespace {

constexpr char kMagic[8] = {'M', 'O', 'W', 'S', 'T', 'A', 'T', 'E'};
// 2: the block-structured analysis; 3: the margin; 4: robot limits; 5: transitions whose
// modes keep their sign from the cell to the point; 10: the conditioning figures
constexpr std::uint32_t kVersion = 11;

// Each stored type once, for both directions (io/state_archive.h).

template <class A>
void describe(A& a, Pose& pose) {
  for (int i = 0; i < 3; ++i) a.value(pose.position[i]);
  for (int i = 0; i < 3; ++i) a.value(pose.euler_zyz[i]);
  a.check(pose.position.allFinite() && pose.euler_zyz.allFinite(), "a pose is not finite");
}

template <class A>
void describe(A& a, GridSpec& spec) {
  a.items(spec.variables, 4, [&](OutputVariable& variable) {
    std::int32_t code = static_cast<std::int32_t>(variable);
    a.value(code);
    a.check(code >= 0 && code < kOutputVariableCount, "bad grid variable");
    variable = static_cast<OutputVariable>(code);
  });
  a.values(spec.steps);
  a.items(spec.bounds, 16, [&](std::array<double, 2>& bounds) {
    a.value(bounds[0]);
    a.value(bounds[1]);
  });
  describe(a, spec.start);
  std::uint8_t orientation = static_cast<std::uint8_t>(spec.orientation);
  a.value(orientation);
  a.check(orientation <= 1, "bad orientation coordinates");
  spec.orientation = static_cast<OrientationCoordinates>(orientation);
}

template <class A>
void describe(A& a, AnalysisSettings& settings) {
  a.value(settings.margin);
  a.value(settings.debris.min_voxels);
  a.value(settings.debris.min_fraction);
  std::uint8_t uncoupled = settings.uncoupled;
  a.value(uncoupled);
  settings.uncoupled = uncoupled != 0;
  a.value(settings.transition_tolerance);
}

template <class A>
void describe(A& a, WorkingMode& mode) {
  a.text(mode.name);
  a.value(mode.negative_chains);
}

template <class A>
void describe(A& a, WorkspaceCells& cells, const Grid& grid) {
  std::int32_t modes = cells.patterns.modes;
  a.value(modes);
  a.check(modes >= 1 && modes <= kMaxAnalysedModes, "bad working-mode count");
  cells.patterns.modes = modes;
  a.items(cells.patterns.patterns, 16, [&](SignPattern& pattern) {
    a.value(pattern[0]);
    a.value(pattern[1]);
  });
  a.check(cells.patterns.patterns.size() <= kMaxSignPatterns, "too many sign patterns");
  a.value(cells.evaluated);
  a.value(cells.proofs);
  a.value(cells.inside_cells);
  a.value(cells.start_block);
  a.value(cells.start_cell);
  if (A::kReading) {
    cells.layout = BlockLayout(grid);
    // The block table is stored whole: refused before it is made when the file cannot
    // hold it (the grid's size is read from the same bytes).
    a.checkFits(cells.layout.blockCount(), sizeof(std::uint32_t));
    cells.codes = CodeMap(cells.layout.blockCount(), cells.layout.cellsPerBlock());
  }
  cells.codes.describe(a, cells.patterns.patterns.size());
  // The thin layers: the regions are labelled again from the codes and these.
  a.items(cells.cuts.faces, 17, [&](FaceCut& cut) {
    a.value(cut.face);
    a.value(cut.gap);
    a.value(cut.modes);
  });
  a.values(cells.cuts.blocks);
  if (A::kReading) {
    const auto before = [](const FaceCut& x, const FaceCut& y) { return x.face < y.face; };
    a.check(std::is_sorted(cells.cuts.faces.begin(), cells.cuts.faces.end(), before) &&
                (cells.cuts.faces.empty() || cells.cuts.faces.back().face < grid.cellCount() * kMaxGridDims),
            "a cut face is out of range");
    a.check(std::is_sorted(cells.cuts.blocks.begin(), cells.cuts.blocks.end()) &&
                (cells.cuts.blocks.empty() || cells.cuts.blocks.back() < cells.layout.blockCount()),
            "a cut's block is out of range");
    for (std::uint64_t b : cells.cuts.blocks) a.check(!cells.codes.uniform(b), "a cut's block has no page of codes");
  }
  a.check(cells.start_block < cells.layout.blockCount() && cells.start_cell >= 0 &&
              cells.start_cell < cells.layout.cellsPerBlock() &&
              codeInside(cells.codes.code(cells.start_block, cells.start_cell)),
          "the start cell is not in the workspace");
}

template <class A>
void describe(A& a, Region& region) {
  std::int32_t mode = region.mode;
  a.value(mode);
  region.mode = mode;
  a.value(region.sign);
  a.value(region.voxels);
  std::uint8_t debris = region.debris;
  a.value(debris);
  region.debris = debris != 0;
}

// `inputs` and `chains`: the robot's counts, which indices must stay under.
template <class A>
void describe(A& a, TransitionGraph& graph, const AnalysisData& data, int inputs, int chains) {
  // Each point as a whole pose: on a grid without rotational variables the graph keeps the
  // grid's orientation once, and a point of another one is damage.
  const bool turning = !data.grid.orientationFixed();
  std::uint64_t count = graph.points.size();
  a.count(count, 6 * sizeof(double) + 10);
  if (A::kReading) {
    graph.orientation = data.grid.spec().start.euler_zyz;
    graph.points.assign(count, TransitionPoint{});
    graph.orientations.assign(turning ? count : 0, Eigen::Vector3d::Zero());
  }
  for (std::size_t p = 0; p < count; ++p) {
    Pose pose = graph.pose(p);
    std::uint64_t cell = graph.points[p].cell;
    std::uint8_t input = graph.points[p].input, chain = graph.points[p].chain;
    describe(a, pose);
    a.value(cell);
    a.value(input);
    a.value(chain);
    a.check(cell < data.grid.cellCount() && input < inputs && chain < chains, "bad transition point");
    a.check(turning || pose.euler_zyz == graph.orientation, "a transition point is not at the grid's orientation");
    if (A::kReading) {
      graph.points[p] = TransitionPoint{pose.position, cell, input, chain};
      if (turning) graph.orientations[p] = pose.euler_zyz;
    }
  }
  const std::size_t regions = data.regions.regions.size();
  a.items(graph.transitions, 18, [&](Transition& transition) {
    a.value(transition.from_region);
    a.value(transition.to_region);
    a.value(transition.input);
    a.value(transition.sign);
    a.values(transition.points);
    a.check(transition.from_region < regions && transition.to_region < regions && transition.input < inputs,
            "bad transition");
    for (std::uint32_t p : transition.points) a.check(p < graph.points.size(), "bad transition point index");
  });
  a.values(graph.component);
  a.check(graph.component.size() == regions, "bad component table");
  for (std::int32_t component : graph.component) {
    a.check(component >= 0 && static_cast<std::size_t>(component) < regions, "bad component");
  }
}

template <class A>
void describe(A& a, VolumeBounds& bounds) {
  a.value(bounds.inner_voxels);
  a.value(bounds.boundary_voxels);
  a.value(bounds.inner);
  a.value(bounds.boundary);
}

template <class A>
void describe(A& a, AssemblyModeSummary& am, std::size_t regions) {
  a.value(am.sign);
  for (int* n : {&am.regions, &am.debris_regions, &am.transitions, &am.components}) a.value(*n);
  a.value(am.maximal_voxels);
  a.value(am.maximal_volume);
  a.value(am.traditional_region);
  a.value(am.traditional_volume);
  a.value(am.reachable_voxels);
  a.value(am.reachable_volume);
  for (VolumeBounds* bounds : {&am.maximal_bounds, &am.traditional_bounds, &am.reachable_bounds}) describe(a, *bounds);
  a.check(am.traditional_region < static_cast<std::int32_t>(regions), "bad traditional region");
}

template <class A>
void describe(A& a, SingularityCounts& counts, StageSeconds& s) {
  for (std::uint64_t* n : {&counts.dkp_entries, &counts.ikp_faces, &counts.ikp_entries, &counts.limit_entries,
                           &counts.cone_entries, &counts.interference_entries, &counts.thin_layer_faces}) {
    a.value(*n);
  }
  for (double* t : {&s.classification, &s.regions, &s.singularities, &s.transitions, &s.summary, &s.total}) a.value(*t);
}

template <class A>
void describe(A& a, std::optional<ConditioningSummary>& conditioning) {
  std::uint8_t present = conditioning.has_value();
  a.value(present);
  a.check(present <= 1, "bad conditioning flag");
  if (present == 0) return;
  if (!conditioning) conditioning.emplace();
  a.value(conditioning->request.threshold);
  a.value(conditioning->request.evaluations);
  a.value(conditioning->stride);
  a.check(conditioning->request.threshold >= 0.0 && conditioning->request.threshold <= 1.0 && conditioning->stride >= 1,
          "bad conditioning request");
  for (ConditioningFigures& figures : conditioning->assembly_modes) {
    a.value(figures.samples);
    a.value(figures.well_conditioned);
    a.value(figures.well_conditioned_volume);
    a.value(figures.global_index);
    a.check(figures.well_conditioned <= figures.samples, "bad conditioning figures");
  }
  a.value(conditioning->seconds);
}

// Working modes as stored must be the model's own, under their own names.
void checkModes(const StateReader& r, const RobotModel& model, const AnalysisData& data) {
  const std::vector<WorkingMode> all =
      data.settings.uncoupled ? uncoupledWorkingModes(model) : coupledWorkingModes(model);
  r.check(!data.modes.empty() && data.modes.size() <= kMaxAnalysedModes, "bad working-mode count");
  for (const WorkingMode& mode : data.modes) {
    const WorkingMode* known = findWorkingMode(all, mode.name);
    r.check(known != nullptr && known->negative_chains == mode.negative_chains, "a working mode is not the robot's");
  }
  r.check(data.start_mode >= 0 && data.start_mode < static_cast<int>(data.modes.size()), "bad start mode");
  r.check(static_cast<std::size_t>(data.cells.patterns.modes) == data.modes.size(), "working-mode count mismatch");
}

// The region table as stored against the one recomputed from the codes.
template <class A>
void describeRegions(A& a, AnalysisData& data, int threads) {
  std::vector<Region> stored = data.regions.regions;
  a.items(stored, 14, [&](Region& region) { describe(a, region); });
  if (!A::kReading) return;
  data.regions = labelRegions(data.grid, data.cells, data.settings.debris, threads);
  bool same = stored.size() == data.regions.regions.size();
  for (std::size_t r = 0; same && r < stored.size(); ++r) {
    const Region &read = stored[r], &made = data.regions.regions[r];
    same = read.mode == made.mode && read.sign == made.sign && read.voxels == made.voxels && read.debris == made.debris;
  }
  a.check(same, "the region table does not match the codes");
}

}  // namespace

std::uint32_t workspaceStateVersion() { return kVersion; }

void writeWorkspaceState(const WorkspaceAnalysis& analysis, std::ostream& out) {
  // Describing reads every field: the writer never changes them.
  AnalysisData& data = const_cast<AnalysisData&>(AnalysisAccess::data(analysis));
  StateWriter w(out);
  out.write(kMagic, sizeof kMagic);
  w.value(kVersion);
  GridSpec spec = data.grid.spec();
  describe(w, spec);
  describe(w, data.settings);
  w.items(data.modes, 12, [&](WorkingMode& mode) { describe(w, mode); });
  w.value(data.start_mode);
  w.value(static_cast<std::uint8_t>(data.factorised));
  describe(w, data.cells, data.grid);
  describeRegions(w, data, 0);
  describe(w, data.transitions, data, kMaxChains, kMaxChains);
  for (AssemblyModeSummary& am : data.assembly_modes) describe(w, am, data.regions.regions.size());
  describe(w, data.conditioning);
  describe(w, data.workspace_bounds);
  describe(w, data.singularities, data.seconds);
}

WorkspaceAnalysis readWorkspaceState(const RobotModel& model, std::istream& in, const std::string& source, int threads) {
  StateReader r(in, source);
  char magic[sizeof kMagic];
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof kMagic) != 0) r.fail("wrong magic");
  std::uint32_t version = 0;
  r.value(version);
  r.check(version == kVersion, "another version");
  GridSpec spec;
  describe(r, spec);
  auto data = std::make_shared<AnalysisData>([&] {
    try {
      return Grid(model, spec);
    } catch (const InputError& error) {
      r.fail(error.what());
    }
  }());
  describe(r, data->settings);
  r.items(data->modes, 12, [&](WorkingMode& mode) { describe(r, mode); });
  r.value(data->start_mode);
  std::uint8_t factorised = 0;
  r.value(factorised);
  data->factorised = factorised != 0;
  describe(r, data->cells, data->grid);
  checkModes(r, model, *data);
  describeRegions(r, *data, threads);
  describe(r, data->transitions, *data, model.inputCount(), model.chainCount());
  for (AssemblyModeSummary& am : data->assembly_modes) describe(r, am, data->regions.regions.size());
  describe(r, data->conditioning);
  describe(r, data->workspace_bounds);
  describe(r, data->singularities, data->seconds);
  r.check(r.atEnd(), "bytes after the end");
  return AnalysisAccess::make(std::move(data));
}

}  // namespace maximal_workspace
