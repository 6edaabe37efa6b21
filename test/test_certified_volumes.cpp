// The certified volumes (regions/workspace_analysis.h, VolumeBounds): the exact volume
// lies in [inner, inner + boundary]. Checked against closed forms: the workspace of
// test/robots/tricylinder.yaml is the intersection of three orthogonal cylinders of
// radius R about the axes, 8 (2 - sqrt 2) R^3 (Moore's tricylinder); the 5R's is the
// intersection of two annuli (the perturbation path, no couples). And on the delta-like
// robot, where no closed form exists, against a finer analysis: its sampled volumes are
// within a small fraction of a 10 mm cell layer of the exact ones, well inside the 10 mm
// bounds' boundary band.

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

using OV = OutputVariable;

WorkspaceAnalysis analyse(const RobotModel& model, double step) {
  GridSpec spec;
  spec.variables = {OV::X, OV::Y, OV::Z};
  spec.steps = {step};
  spec.start = model.reference.pose;
  return analyseWorkspace(model, spec, {});
}

void expectHolds(const VolumeBounds& bounds, double volume, const char* what) {
  EXPECT_LE(bounds.inner, volume) << what;
  EXPECT_GE(bounds.inner + bounds.boundary, volume) << what;
}

TEST(CertifiedVolumes, TheTricylinderWorkspaceLiesWithinItsBounds) {
  const RobotModel model = loadRobotFile(test::sourcePath("test/robots/tricylinder.yaml"));
  const double radius = 0.3, exact = 8.0 * (2.0 - std::sqrt(2.0)) * radius * radius * radius;
  // Its surface, 3 dV/dR. Whole cells along it make a band of at least about area x step
  // (1.7 times that at 10 mm before the shares); with the shares proven on either side,
  // what is left is the part inside of the cells whose centre is outside, and a thin layer.
  const double area = 24.0 * (2.0 - std::sqrt(2.0)) * radius * radius;
  double last_boundary = INFINITY;
  for (double step : {0.01, 0.005}) {
    const WorkspaceAnalysis analysis = analyse(model, step);
    const VolumeBounds& bounds = analysis.workspaceBounds();
    std::printf("step %.3f: exact %.6f, sampled %.6f, certified [%.6f, %.6f]\n", step, exact, analysis.workspaceVolume(),
                bounds.inner, bounds.inner + bounds.boundary);
    expectHolds(bounds, exact, "the tricylinder");
    expectHolds(bounds, analysis.workspaceVolume(), "the sampled workspace");
    // The proofs decide most of it, and more at a finer step.
    EXPECT_GT(bounds.inner, 0.5 * exact) << step;
    EXPECT_LT(bounds.boundary, last_boundary) << step;
    EXPECT_LT(bounds.boundary, 0.5 * area * step) << step;
    last_boundary = bounds.boundary;
  }
}

// The area where two discs of radii r1, r2 with centres d apart overlap.
double lens(double r1, double r2, double d) {
  if (d >= r1 + r2) return 0.0;
  if (d <= std::abs(r1 - r2)) return M_PI * std::min(r1, r2) * std::min(r1, r2);
  const double a = r1 * r1 * std::acos((d * d + r1 * r1 - r2 * r2) / (2 * d * r1));
  const double b = r2 * r2 * std::acos((d * d + r2 * r2 - r1 * r1) / (2 * d * r2));
  return a + b - 0.5 * std::sqrt((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2));
}

// config/five_bar.yaml: annuli 0.05 to 0.45 m about base joints 0.2 m apart.
TEST(CertifiedVolumes, TheFiveBarWorkspaceLiesWithinItsBounds) {
  const RobotModel& model = test::fiveBar();
  const double exact = lens(0.45, 0.45, 0.2) - 2.0 * lens(0.45, 0.05, 0.2) + lens(0.05, 0.05, 0.2);
  for (double step : {0.01, 0.004}) {
    GridSpec spec;
    spec.variables = {OV::X, OV::Y};
    spec.steps = {step};
    spec.start = model.reference.pose;
    const WorkspaceAnalysis analysis = analyseWorkspace(model, spec, {});
    const VolumeBounds& bounds = analysis.workspaceBounds();
    std::printf("step %.3f: exact %.6f m^2, sampled %.6f, certified [%.6f, %.6f]\n", step, exact,
                analysis.workspaceVolume(), bounds.inner, bounds.inner + bounds.boundary);
    expectHolds(bounds, exact, "the 5R's annuli");
    EXPECT_GT(bounds.inner, 0.5 * exact) << step;
  }
}

// Where no closed form exists: each analysis's own volumes lie within its bounds, the finer
// one's volumes within the coarser one's bounds, and smaller cells decide more.
void expectFinerWithinCoarse(const RobotModel& model, const WorkspaceAnalysis& coarse, const WorkspaceAnalysis& fine) {
  SCOPED_TRACE(model.name);
  expectHolds(coarse.workspaceBounds(), fine.workspaceVolume(), "workspace");
  for (int a = 0; a < 2; ++a) {
    SCOPED_TRACE(a == 0 ? "assembly mode +" : "assembly mode -");
    const AssemblyModeSummary &bounds = coarse.assemblyModes()[a], &finer = fine.assemblyModes()[a];
    for (const AssemblyModeSummary* own : {&bounds, &finer}) {
      SCOPED_TRACE(own == &bounds ? "coarse" : "fine");
      expectHolds(own->maximal_bounds, own->maximal_volume, "its own maximal volume");
      expectHolds(own->traditional_bounds, own->traditional_volume, "its own traditional volume");
      expectHolds(own->reachable_bounds, own->reachable_volume, "its own reachable volume");
    }
    expectHolds(bounds.maximal_bounds, finer.maximal_volume, "maximal, finer");
    expectHolds(bounds.traditional_bounds, finer.traditional_volume, "traditional, finer");
    expectHolds(bounds.reachable_bounds, finer.reachable_volume, "reachable, finer");
    // Proofs over smaller cells decide more.
    if (finer.maximal_volume > 0.0) EXPECT_GE(finer.maximal_bounds.inner, bounds.maximal_bounds.inner);
    EXPECT_LE(finer.maximal_bounds.boundary, bounds.maximal_bounds.boundary);
  }
}

TEST(CertifiedVolumes, TheDeltaLikeRobotsFinerVolumesLieWithinTheCoarseBounds) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis coarse = analyse(model, 0.01), fine = analyse(model, 0.005);
  expectFinerWithinCoarse(model, coarse, fine);
  for (int a = 0; a < 2; ++a) {
    EXPECT_GT(fine.assemblyModes()[a].maximal_bounds.inner, coarse.assemblyModes()[a].maximal_bounds.inner);
  }
}

// Robots whose limits bind (inputs and cones): the limits are proven over boxes
// (kinematics/mode_constraints.h), so the inner volumes hold a good share (over 40 %) of the
// workspace at steps that suit the robot's size, and they never exceed the volume where, by the limits' own
// code path (RobotConstraints, from each pose's IKP), some working mode is admissible: a
// Monte-Carlo estimate over the grid's box, 4 sigma allowed.
TEST(CertifiedVolumes, LimitedRobotsInnerVolumesAreProvenAndBelowTheAdmissibleVolume) {
  struct Case {
    const char* robot;
    double coarse, fine;  // steps, m
  };
  for (const Case& robot_case : {Case{"config/delta_like_limited.yaml", 0.01, 0.005}, Case{"config/linear_delta.yaml", 0.005, 0.0025}}) {
    const char* robot = robot_case.robot;
    const RobotModel model = loadRobotFile(test::sourcePath(robot));
    const WorkspaceAnalysis coarse = analyse(model, robot_case.coarse), fine = analyse(model, robot_case.fine);
    expectFinerWithinCoarse(model, coarse, fine);
    const VolumeBounds& bounds = fine.workspaceBounds();
    EXPECT_GT(bounds.inner, 0.4 * fine.workspaceVolume()) << robot;

    const Grid& grid = fine.grid();
    const RobotConstraints constraints(model);
    const std::vector<WorkingMode> modes = coupledWorkingModes(model);
    double box_volume = 1.0;
    for (int d = 0; d < 3; ++d) box_volume *= grid.step(d) * static_cast<double>(grid.size(d));
    const int samples = 100000;
    int admissible = 0;
    for (int i = 0; i < samples; ++i) {
      Pose pose = model.reference.pose;
      for (int d = 0; d < 3; ++d) {
        pose.position[d] = test::uniform(grid.centre(d, 0), grid.centre(d, grid.size(d) - 1)) + test::uniform(-0.5, 0.5) * grid.step(d);
      }
      const IkpResult ikp = solveIkp(model, pose);
      if (!ikp.assembled) continue;
      admissible += std::any_of(modes.begin(), modes.end(), [&](const WorkingMode& mode) {
        return constraints.margins(pose, ikp, mode).satisfied();
      });
    }
    const double p = static_cast<double>(admissible) / samples, estimate = p * box_volume;
    const double sigma = box_volume * std::sqrt(p * (1.0 - p) / samples);
    std::printf("%s at %g m: certified [%.6f, %.6f], sampled %.6f, admissible by Monte Carlo %.6f +/- %.6f m^3\n",
                robot, robot_case.fine, bounds.inner, bounds.inner + bounds.boundary, fine.workspaceVolume(), estimate, sigma);
    EXPECT_LE(bounds.inner, estimate + 4.0 * sigma) << robot;
  }
}

}  // namespace
}  // namespace maximal_workspace
