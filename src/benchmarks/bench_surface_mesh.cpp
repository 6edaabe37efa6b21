// Time and memory of the boundary mesh of the delta-like robot's maximal operational
// workspace (+) at 5 mm and 2 mm: the analysis is made once per step, outside the timed
// loop; each iteration reads its cells into a voxel tree and meshes it. Run from the package
// root (config/delta_like.yaml). Counters: the mesh's triangles, the volume it encloses
// against the analysis's, and mesh_peak_MiB, the resident memory the extraction adds at
// its peak over what the process held before it (the kernel's high-water mark is reset
// first through /proc/self/clear_refs, so the analysis's own peak does not hide it).

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>

#include <benchmark/benchmark.h>

#include "maximal_workspace/io/workspace_request.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "maximal_workspace/surfaces/surface_mesh.h"

namespace maximal_workspace {
namespace {

const WorkspaceAnalysis& analysisAt(double step) {
  static std::map<double, WorkspaceAnalysis> analyses;
  auto found = analyses.find(step);
  if (found == analyses.end()) {
    const RobotModel model = loadRobotFile("config/delta_like.yaml");
    GridSpec spec;
    spec.variables = translationalVariables(model);
    spec.steps = {step};
    spec.start = model.reference.pose;
    found = analyses.emplace(step, analyseWorkspace(model, spec, AnalysisOptions{})).first;
  }
  return found->second;
}

// A field of /proc/self/status in KiB ("VmRSS", "VmHWM").
double statusKib(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string name;
  double value = 0.0;
  while (status >> name) {
    if (name == field + ":") return (status >> value) ? value : 0.0;
    status.ignore(1 << 10, '\n');
  }
  return 0.0;
}

void resetPeakMemory() { std::ofstream("/proc/self/clear_refs") << "5"; }

void BM_MaximalWorkspaceMesh(benchmark::State& state) {
  const double step = static_cast<double>(state.range(0)) * 1e-6;
  const WorkspaceAnalysis& analysis = analysisAt(step);
  const AssemblyModeSummary& plus = analysis.assemblyModes()[0];
  SurfaceMesh mesh;
  double peak_added_kib = 0.0;
  for (auto _ : state) {
    mesh = SurfaceMesh();
    const double before = statusKib("VmRSS");
    resetPeakMemory();
    mesh = surfaceMesh(maximalWorkspaceCells(analysis, plus.sign));
    benchmark::DoNotOptimize(mesh.triangles.data());
    peak_added_kib = std::max(peak_added_kib, statusKib("VmHWM") - before);
  }
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
  state.counters["mesh_volume"] = enclosedVolume(mesh);
  state.counters["analysis_volume"] = plus.maximal_volume;
  state.counters["mesh_peak_MiB"] = peak_added_kib / 1024.0;
}

BENCHMARK(BM_MaximalWorkspaceMesh)->Arg(5000)->Arg(2000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace maximal_workspace

BENCHMARK_MAIN();
