// What a box's interval proof costs (kinematics/measure_certificate.h): the workspace
// engine asks for one per cube it tries to decide, so its price sets how small a cube may
// be before sampling its cells is cheaper. Run from the package root (robot files under
// config/).
//
// Boxes: cubes of 2, 4, 8 and 16 cells of 2 mm about seeded-random TCP positions of the
// delta-like robot's safety box at the reference orientation, kept when every chain
// assembles over the whole box (the only boxes `certify` is asked for). BM_AssemblyOf
// times the cheaper assembly part alone on the same boxes. BM_AssemblyShares times the
// summary's shares of single cells the workspace's boundary crosses (assemblyOf undecided).
//
// BM_CertifyTurning: the same for boxes that turn the platform, cubes of 1, 2 and 4 cells a
// side of issue 30's grid (10 mm, 2.5 deg, tilt and torsion to 15 deg) over the hexaglide's
// rails' middle, with the 7 working modes of its planning example. Its counters say how
// often the perturbation bound proves a working mode's sign over such a box (`modes`, the
// share of (box, mode) pairs) and every mode's (`boxes`): where it does not, the engine
// samples every cell of a 6-D analysis.

#include <array>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "maximal_workspace/kinematics/measure_certificate.h"
#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/workspace/grid.h"

namespace maximal_workspace {
namespace {

constexpr double kCell = 0.002;
constexpr std::size_t kBoxesPerSet = 2000;

struct Fixture {
  RobotModel model;
  std::unique_ptr<MeasureCertificate> certificate;
};

const Fixture& deltaLike() {
  static const Fixture fixture = [] {
    Fixture made{loadRobotFile("config/delta_like.yaml"), nullptr};
    made.certificate = std::make_unique<MeasureCertificate>(made.model, coupledWorkingModes(made.model),
                                                            made.model.reference.pose);
    return made;
  }();
  return fixture;
}

// Boxes of `cells` cells a side whose assemblyOf is `wanted`; the same boxes on every run
// (fixed seed).
std::vector<PoseBox> boxesOf(int cells, BoxAssembly wanted) {
  const Fixture& fixture = deltaLike();
  std::array<std::uniform_real_distribution<double>, 3> coordinate;
  const OutputVariable axes[3] = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
  for (int a = 0; a < 3; ++a) {
    const std::array<double, 2> range = safetyBounds(fixture.model, fixture.model.reference.pose, axes[a]);
    coordinate[a] = std::uniform_real_distribution<double>(range[0], range[1]);
  }
  std::mt19937_64 random(20261128);
  std::vector<PoseBox> boxes;
  for (std::size_t drawn = 0; boxes.size() < kBoxesPerSet; ++drawn) {
    if (drawn > 1000 * kBoxesPerSet) {
      std::fprintf(stderr, "bench_certificate: almost no box of %d cells is of the kind wanted\n", cells);
      std::exit(1);
    }
    PoseBox box;
    box.centre = fixture.model.reference.pose;
    for (int a = 0; a < 3; ++a) box.centre.position[a] = coordinate[a](random);
    box.position_half_width.setConstant(0.5 * cells * kCell);
    if (fixture.certificate->assemblyOf(box) == wanted) boxes.push_back(box);
  }
  return boxes;
}

// One pass over the boxes of state.range(0) cells a side per iteration.
template <class Prove>
void timeProofs(benchmark::State& state, const Prove& prove, BoxAssembly boxes_of = BoxAssembly::Inside) {
  const std::vector<PoseBox> boxes = boxesOf(static_cast<int>(state.range(0)), boxes_of);
  const MeasureCertificate& certificate = *deltaLike().certificate;
  for (auto _ : state) {
    for (const PoseBox& box : boxes) benchmark::DoNotOptimize(prove(certificate, box));
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * boxes.size()));
}

void BM_Certify(benchmark::State& state) {
  timeProofs(state, [](const MeasureCertificate& certificate, const PoseBox& box) { return certificate.certify(box); });
}

void BM_AssemblyOf(benchmark::State& state) {
  timeProofs(state, [](const MeasureCertificate& certificate, const PoseBox& box) { return certificate.assemblyOf(box); });
}

// Issue 30's grid over the hexaglide (see the header), made once.
struct TurningFixture {
  RobotModel model;
  std::unique_ptr<Grid> grid;
  std::unique_ptr<MeasureCertificate> certificate;
};

const TurningFixture& hexaglide() {
  static const TurningFixture fixture = [] {
    TurningFixture made{loadRobotFile("config/hexaglide_6pss.yaml"), nullptr, nullptr};
    GridSpec spec;
    spec.variables = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
    spec.steps = {0.01};
    spec.start = made.model.reference.pose;
    spec.bounds = {{-0.02, 0.4}, {-0.1, 0.1}, {0.2, 0.36}};
    addOrientationSet(made.model, OrientationSet{0.2618, {-0.2618, 0.2618}, 0.0436}, &spec);
    made.grid = std::make_unique<Grid>(made.model, spec);
    const std::vector<WorkingMode> all = uncoupledWorkingModes(made.model);
    std::vector<WorkingMode> modes;
    std::istringstream names("ppnnpp npnnpp pnnnpp pppnpp ppnppp ppnnnp ppnnpn");
    for (std::string name; names >> name;) modes.push_back(all[workingModeIndex(all, name, "bench_certificate")]);
    made.certificate = std::make_unique<MeasureCertificate>(made.model, modes, made.model.reference.pose);
    return made;
  }();
  return fixture;
}

void BM_CertifyTurning(benchmark::State& state) {
  const TurningFixture& fixture = hexaglide();
  const Grid& grid = *fixture.grid;
  const int cells = static_cast<int>(state.range(0));
  std::mt19937_64 random(20261130);
  std::vector<PoseBox> boxes;
  for (std::size_t drawn = 0; boxes.size() < kBoxesPerSet / 4; ++drawn) {
    if (drawn > 1000 * kBoxesPerSet) {
      std::fprintf(stderr, "bench_certificate: almost no turning box of %d cells assembles\n", cells);
      std::exit(1);
    }
    GridCell first{}, last{};
    for (int d = 0; d < grid.dims(); ++d) {
      first[d] = std::uniform_int_distribution<std::int64_t>(0, std::max<std::int64_t>(0, grid.size(d) - cells))(random);
      last[d] = std::min<std::int64_t>(first[d] + cells - 1, grid.size(d) - 1);
    }
    const PoseBox box = grid.cellsBox(first, last);
    if (fixture.certificate->assemblyOf(box) == BoxAssembly::Inside) boxes.push_back(box);
  }
  std::size_t proven_modes = 0, proven_boxes = 0, pairs = 0;
  for (auto _ : state) {
    proven_modes = proven_boxes = pairs = 0;
    for (const PoseBox& box : boxes) {
      const BoxCertificate proof = fixture.certificate->certify(box);
      std::size_t proven = 0;
      for (double floor : proof.measure_floor) proven += floor > 0.0;
      proven_modes += proven;
      proven_boxes += proven == proof.measure_floor.size();
      pairs += proof.measure_floor.size();
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * boxes.size()));
  state.counters["modes"] = static_cast<double>(proven_modes) / static_cast<double>(pairs);
  state.counters["boxes"] = static_cast<double>(proven_boxes) / static_cast<double>(boxes.size());
}

void BM_AssemblyShares(benchmark::State& state) {
  timeProofs(
      state, [](const MeasureCertificate& certificate, const PoseBox& box) { return certificate.assemblyShares(box); },
      BoxAssembly::Undecided);
}

BENCHMARK(BM_Certify)->Arg(2)->Arg(4)->Arg(8)->Arg(16)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_AssemblyOf)->Arg(2)->Arg(8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_AssemblyShares)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CertifyTurning)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace maximal_workspace

BENCHMARK_MAIN();
