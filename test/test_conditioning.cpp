// The conditioning index (kinematics/conditioning.h) against an SVD of the Jacobian of the
// inputs as functions of the pose, differentiated numerically through the chains' own
// IKP; closed forms on a 5R; its invariances; and the summary's conditioning figures.

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <assimp/Importer.hpp>
#include <assimp/scene.h>

#include "maximal_workspace/io/mesh_files.h"
#include "maximal_workspace/io/workspace_state.h"
#include "maximal_workspace/kinematics/conditioning.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "maximal_workspace/surfaces/vertex_conditioning.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

using Vector = Eigen::VectorXd;

const RobotModel& planar3rrr() {
  static const RobotModel model = loadRobotFile(test::sourcePath("test/robots/planar_3rrr.yaml"));
  return model;
}

// docs/kinematics.md's characteristic length: the RMS distance of the platform nodes from
// the TCP.
double rmsNodeDistance(const RobotModel& model) {
  double sum = 0.0;
  for (const ChainPtr& chain : model.chains) sum += chain->platformNode().squaredNorm();
  return std::sqrt(sum / model.chainCount());
}

// How far a chain's intermediate node travels per unit of its input.
double nodeTravel(const Chain& chain) {
  if (const auto* crank = dynamic_cast<const RssChain*>(&chain)) return crank->crankLength();
  return 1.0;  // a slider's input is the node's travel
}

// The base-frame direction of output variable j's column: a translation along x, y, z or a
// rotation about x, y, z (z alone for a planar platform), both through the TCP.
int motionAxis(const RobotModel& model, int j) {
  const int v = static_cast<int>(model.output_variables[j]);
  if (v < 3) return v;
  return model.hasOutputVariable(OutputVariable::Theta) ? v : 5;
}

// Both IKP branches' inputs of every chain (row 2 i + branch) for a platform at `position`
// turned by `rotation`; NaN where a chain cannot be assembled. One IKP serves every
// working mode.
Vector branchInputs(const RobotModel& model, const Eigen::Vector3d& position, const Eigen::Matrix3d& rotation) {
  Vector inputs(2 * model.chainCount());
  for (int i = 0; i < model.chainCount(); ++i) {
    const Chain& chain = *model.chains[i];
    const ChainSolution solution = chain.solve(position + rotation * chain.platformNode());
    for (int b = 0; b < 2; ++b) inputs[2 * i + b] = solution.assembled ? solution.branches[b].q : NAN;
  }
  return inputs;
}

// The same with the platform moved from `pose` by s along motion axis `axis` (a rotation
// by s / length), as the distance each node travelled from its input in `origin`.
Vector movedInputs(const RobotModel& model, const Pose& pose, int axis, double s, double length, const Vector& origin) {
  Eigen::Vector3d position = pose.position;
  Eigen::Matrix3d rotation = pose.rotation();
  if (axis < 3) position[axis] += s;
  else rotation = Eigen::AngleAxisd(s / length, Eigen::Vector3d::Unit(axis - 3)).toRotationMatrix() * rotation;
  Vector travel = branchInputs(model, position, rotation) - origin;
  for (int row = 0; row < travel.size(); ++row) {
    const Chain& chain = *model.chains[row / 2];
    // A crank angle wraps at +/-pi.
    if (chain.inputKind() == InputKind::Revolute) travel[row] = std::remainder(travel[row], 2 * M_PI);
    travel[row] *= nodeTravel(chain);
  }
  return travel;
}

// Ridders' extrapolation of central differences (Numerical Recipes' dfridr), for a vector
// function: steps h0, h0 / 1.4, ... (all of them: stopping where the error estimate first
// grows, as dfridr does, kept a wrong estimate near a reach limit, 1 % off), the
// estimate of least error; steps where the function is not finite (a chain out of reach)
// are skipped.
Vector derivative(const std::function<Vector(double)>& f, double h0) {
  constexpr int kSteps = 20;
  constexpr double kShrink = 1.4, kShrink2 = kShrink * kShrink;
  std::vector<std::vector<Vector>> table(kSteps, std::vector<Vector>(kSteps));
  Vector best;
  double best_error = INFINITY;
  int first = 0;  // the first finite row
  double h = h0;
  for (int i = 0; i < kSteps; ++i, h /= kShrink) {
    table[0][i] = (f(h) - f(-h)) / (2 * h);
    if (!table[0][i].allFinite()) {
      first = i + 1;
      continue;
    }
    double factor = kShrink2;
    for (int j = 1; j <= i - first; ++j, factor *= kShrink2) {
      table[j][i] = (table[j - 1][i] * factor - table[j - 1][i - 1]) / (factor - 1);
      const double error = std::max((table[j][i] - table[j - 1][i]).cwiseAbs().maxCoeff(),
                                    (table[j][i] - table[j - 1][i - 1]).cwiseAbs().maxCoeff());
      if (error <= best_error) best_error = error, best = table[j][i];
    }
  }
  return best;
}

// Per working mode, sigma_min / sigma_max of the inputs' Jacobian over the platform's
// motions, each input and each rotation as a length travelled, by finite differences of
// the IKP and an SVD in long double.
std::vector<double> indicesByDifferences(const RobotModel& model, const Pose& pose, const std::vector<WorkingMode>& modes) {
  const double length = rmsNodeDistance(model);
  const Vector origin = branchInputs(model, pose.position, pose.rotation());
  Eigen::MatrixXd both_branches(2 * model.chainCount(), model.dof());
  for (int j = 0; j < model.dof(); ++j) {
    const int axis = motionAxis(model, j);
    both_branches.col(j) = derivative([&](double s) { return movedInputs(model, pose, axis, s, length, origin); }, 1e-3);
  }
  std::vector<double> indices;
  for (const WorkingMode& mode : modes) {
    Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic> jacobian(model.chainCount(), model.dof());
    for (int i = 0; i < model.chainCount(); ++i) {
      jacobian.row(i) = both_branches.row(2 * i + static_cast<int>(mode.branch(i))).cast<long double>();
    }
    const Eigen::JacobiSVD<Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>> svd(jacobian);
    const auto& sigma = svd.singularValues();
    indices.push_back(static_cast<double>(sigma[sigma.size() - 1] / sigma[0]));
  }
  return indices;
}

// Assembled poses within `spread` (m) of the reference and 0.3 rad of its orientation.
std::vector<Pose> randomAssembledPoses(const RobotModel& model, int count, double spread) {
  std::vector<Pose> poses;
  while (static_cast<int>(poses.size()) < count) {
    Pose pose = model.reference.pose;
    for (OutputVariable variable : model.output_variables) {
      const double half = isRotational(variable) ? 0.3 : spread;
      pose.setValue(variable, pose.value(variable) + test::uniform(-half, half));
    }
    if (solveIkp(model, pose).assembled) poses.push_back(pose);
  }
  return poses;
}

double indexAt(const RobotModel& model, const Pose& pose, const WorkingMode& mode) {
  return conditioningIndex(model, configurationOf(pose, solveIkp(model, pose), mode));
}

// The acceptance test of issue 31: 1000 poses, every working mode, relative error 1e-6.
TEST(ConditioningIndex, MatchesAnSvdOfTheNumericallyDifferentiatedIkp) {
  for (const RobotModel* model : {&test::deltaLike(), &test::hexapod(), &planar3rrr()}) {
    const double spread = model == &test::hexapod() ? 0.05 : 0.15;
    double worst = 0.0, smallest = 1.0;
    int compared = 0;
    const std::vector<WorkingMode> modes = coupledWorkingModes(*model);
    for (const Pose& pose : randomAssembledPoses(*model, 1000, spread)) {
      const std::vector<double> references = indicesByDifferences(*model, pose, modes);
      for (std::size_t m = 0; m < modes.size(); ++m) {
        const WorkingMode& mode = modes[m];
        const double index = indexAt(*model, pose, mode);
        const double reference = references[m];
        ASSERT_GT(reference, 0.0) << model->name;
        const double error = std::abs(index - reference) / reference;
        EXPECT_LT(error, 1e-6) << model->name << " mode " << mode.name << " index " << index << " reference " << reference;
        worst = std::max(worst, error);
        smallest = std::min(smallest, reference);
        ++compared;
      }
    }
    std::cout << model->name << ": " << compared << " indices, max relative error " << worst << ", smallest index "
              << smallest << "\n";
  }
}

// A 5R whose cranks are both perpendicular to their distal links, the links at +/-gamma
// from the y axis: each input row of the scaled Jacobian is the link's unit direction,
// so the singular values are sqrt(1 +/- cos 2 gamma) and the index is tan gamma or
// cot gamma, 1 at 45 degrees.
TEST(ConditioningIndex, IsTanGammaOnA5RWithCranksPerpendicularToTheirLinks) {
  const double crank = 0.2, link = 0.25;
  for (double degrees : {40.0, 45.0, 55.0, 70.0}) {
    const double gamma = degrees * M_PI / 180.0;
    const double half_base = link * std::sin(gamma) - crank * std::cos(gamma);
    const double y = crank * std::sin(gamma) + link * std::cos(gamma);
    const std::string chain = "type: RSS, axis: [0, 0, 1], crank_length: " + std::to_string(crank) +
                              ", rod_length: " + std::to_string(link) + ", platform_node: [0, 0, 0]";
    const RobotModel model = parseRobotFile(
        "name: five_bar_perpendicular\noutput_variables: [x, y]\ninputs: [{name: l}, {name: r}]\nchains:\n"
        "  - {name: l, input: l, fixed_node: [" + exactText(-half_base) + ", 0, 0], " + chain + "}\n"
        "  - {name: r, input: r, fixed_node: [" + exactText(half_base) + ", 0, 0], " + chain + "}\n"
        "reference: {position: [0, " + exactText(y) + ", 0]}\n", "five_bar_perpendicular");
    const Pose pose = model.reference.pose;
    const IkpResult ikp = solveIkp(model, pose);
    ASSERT_TRUE(ikp.assembled);
    const Eigen::Vector3d left_node(-half_base - crank * std::cos(gamma), crank * std::sin(gamma), 0.0);
    int found = 0;
    for (const WorkingMode& mode : coupledWorkingModes(model)) {
      const Configuration configuration = configurationOf(pose, ikp, mode);
      const Eigen::Vector3d right_node(-left_node.x(), left_node.y(), 0.0);
      if ((configuration.a[0] - left_node).norm() > 1e-9 || (configuration.a[1] - right_node).norm() > 1e-9) continue;
      EXPECT_NEAR(conditioningIndex(model, configuration), std::min(std::tan(gamma), 1.0 / std::tan(gamma)), 1e-12)
          << degrees << " deg, mode " << mode.name;
      ++found;
    }
    EXPECT_EQ(found, 1) << degrees << " deg";
  }
}

TEST(ConditioningIndex, IsUnchangedInMillimetres) {
  const double scale = 1000.0;
  for (const RobotModel* model : {&test::deltaLike(), &test::hexapod(), &planar3rrr()}) {
    const RobotModel model_mm = test::scaled(*model, scale);
    const double spread = model == &test::hexapod() ? 0.05 : 0.15;
    for (const Pose& pose : randomAssembledPoses(*model, 100, spread)) {
      Pose pose_mm = pose;
      pose_mm.position *= scale;
      for (const WorkingMode& mode : coupledWorkingModes(*model)) {
        const double metres = indexAt(*model, pose, mode);
        EXPECT_NEAR(indexAt(model_mm, pose_mm, mode), metres, 1e-9 * metres) << model->name << " " << mode.name;
        EXPECT_GE(metres, 0.0);
        EXPECT_LE(metres, 1.0);
      }
    }
  }
}

// Bisects between poses a and b, where `side` differs, down to 1e-13 of the segment;
// returns the end where side is true.
Pose bisect(const Pose& a, const Pose& b, const std::function<bool(const Pose&)>& side) {
  Pose low = side(a) ? a : b, high = side(a) ? b : a;
  for (int k = 0; k < 45; ++k) {
    Pose middle = low;
    middle.position = 0.5 * (low.position + high.position);
    (side(middle) ? low : high) = middle;
  }
  return low;
}

// Both kinds of singularity bound the index: on a DKP singularity sigma_min is 0, on an
// IKP singularity a chain's input rate (its row) is unbounded.
TEST(ConditioningIndex, VanishesOnDkpAndIkpSingularities) {
  const RobotModel& model = test::deltaLike();
  const std::vector<WorkingMode> modes = coupledWorkingModes(model);
  int dkp = 0, ikp = 0;
  for (int k = 0; k < 400 && (dkp < 20 || ikp < 20); ++k) {
    const std::vector<Pose> ends = randomAssembledPoses(model, 1, 0.3);
    Pose far = ends[0];
    far.position += test::uniformVector(-0.3, 0.3);
    const WorkingMode& mode = modes[k % modes.size()];
    const auto measure = [&](const Pose& pose) {
      const IkpResult solved = solveIkp(model, pose);
      return solved.assembled ? dkpSingularity(model, configurationOf(pose, solved, mode)).measure : NAN;
    };
    if (!solveIkp(model, far).assembled) {
      const Pose edge = bisect(ends[0], far, [&](const Pose& pose) { return solveIkp(model, pose).assembled; });
      EXPECT_LT(indexAt(model, edge, mode), 1e-5) << mode.name;
      ++ikp;
    } else if (measure(ends[0]) * measure(far) < 0.0) {
      const bool positive = measure(ends[0]) > 0.0;
      const Pose singular = bisect(ends[0], far, [&](const Pose& pose) { return (measure(pose) > 0.0) == positive; });
      // Along the way a chain may have left its reach: only a sign change within it counts.
      if (!(std::abs(measure(singular)) < 1e-9)) continue;
      EXPECT_LT(indexAt(model, singular, mode), 1e-7) << mode.name;
      ++dkp;
    }
  }
  EXPECT_GE(dkp, 20);
  EXPECT_GE(ikp, 20);
}

// --- The summary's figures (regions/conditioning_summary.h).

AnalysisOptions conditioningOptions(double threshold, std::uint64_t evaluations = 1000000, int threads = 0) {
  AnalysisOptions options;
  options.threads = threads;
  options.conditioning = ConditioningRequest{threshold, evaluations};
  return options;
}

// The best index at a cell of the working modes with a non-debris region of `sign` there.
double bestIndexAt(const RobotModel& model, const WorkspaceAnalysis& analysis, std::uint64_t cell, std::int8_t sign) {
  double best = 0.0;
  for (std::size_t m = 0; m < analysis.modes().size(); ++m) {
    const std::int32_t label = analysis.label(cell, static_cast<int>(m));
    if (label < 0 || analysis.regions()[label].debris || analysis.regions()[label].sign != sign) continue;
    best = std::max(best, indexAt(model, analysis.grid().pose(cell), analysis.modes()[m]));
  }
  return best;
}

// Per assembly mode: the cells of the maximal workspace on the sub-lattice of `stride`
// and the sum of their best index, cell by cell through the analysis's public queries.
struct BruteForce {
  std::array<std::uint64_t, 2> cells{};
  std::array<double, 2> index_sum{};
};

BruteForce bruteForce(const RobotModel& model, const WorkspaceAnalysis& analysis, int stride) {
  BruteForce result;
  const Grid& grid = analysis.grid();
  for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
    const GridCell coords = grid.cell(cell);
    bool on_lattice = true;
    for (int d = 0; d < grid.dims(); ++d) on_lattice = on_lattice && coords[d] % stride == stride / 2;
    if (!on_lattice || !analysis.inside(cell)) continue;
    for (int a = 0; a < 2; ++a) {
      const std::int8_t sign = a == 0 ? 1 : -1;
      if (!analysis.inMaximalWorkspace(cell, sign)) continue;
      ++result.cells[a];
      result.index_sum[a] += bestIndexAt(model, analysis, cell, sign);
    }
  }
  return result;
}

TEST(ConditioningSummary, ThresholdZeroIsTheMaximalWorkspaceAndHigherThresholdsKeepLess) {
  const RobotModel& model = test::deltaLike();
  const GridSpec spec = test::referenceGrid(model, 0.04);
  std::array<double, 2> previous{INFINITY, INFINITY};
  for (double threshold : {0.0, 0.05, 0.2}) {
    const WorkspaceAnalysis analysis = analyseWorkspace(model, spec, conditioningOptions(threshold));
    ASSERT_TRUE(analysis.conditioning());
    const ConditioningSummary& summary = *analysis.conditioning();
    EXPECT_EQ(summary.stride, 1);
    for (int a = 0; a < 2; ++a) {
      const AssemblyModeSummary& am = analysis.assemblyModes()[a];
      const ConditioningFigures& figures = summary.assembly_modes[a];
      EXPECT_EQ(figures.samples, am.maximal_voxels);
      if (threshold == 0.0) {
        EXPECT_EQ(figures.well_conditioned_volume, am.maximal_volume);
      }
      EXPECT_LE(figures.well_conditioned_volume, previous[a]) << threshold;
      EXPECT_GT(figures.global_index, 0.0);
      EXPECT_LE(figures.global_index, 1.0);
      previous[a] = figures.well_conditioned_volume;
    }
  }
  // Some cells are conditioned worse than 0.2: the threshold does remove volume.
  const WorkspaceAnalysis plain = analyseWorkspace(model, spec, AnalysisOptions());
  EXPECT_FALSE(plain.conditioning());
  for (int a = 0; a < 2; ++a) EXPECT_LT(previous[a], 0.9 * plain.assemblyModes()[a].maximal_volume);
}

TEST(ConditioningSummary, EqualsACellByCellEvaluationAtAnyStrideAndThreadCount) {
  const RobotModel& model = test::deltaLike();
  const GridSpec spec = test::referenceGrid(model, 0.04);
  for (std::uint64_t evaluations : {std::uint64_t{1000000}, std::uint64_t{20000}}) {
    const WorkspaceAnalysis analysis = analyseWorkspace(model, spec, conditioningOptions(0.1, evaluations));
    const ConditioningSummary& summary = *analysis.conditioning();
    EXPECT_EQ(summary.stride, evaluations == 20000 ? 2 : 1);
    const BruteForce expected = bruteForce(model, analysis, summary.stride);
    for (int a = 0; a < 2; ++a) {
      EXPECT_EQ(summary.assembly_modes[a].samples, expected.cells[a]);
      EXPECT_NEAR(summary.assembly_modes[a].global_index, expected.index_sum[a] / expected.cells[a], 1e-12);
    }
    const WorkspaceAnalysis one_thread = analyseWorkspace(model, spec, conditioningOptions(0.1, evaluations, 1));
    for (int a = 0; a < 2; ++a) {
      EXPECT_EQ(one_thread.conditioning()->assembly_modes[a].global_index, summary.assembly_modes[a].global_index);
      EXPECT_EQ(one_thread.conditioning()->assembly_modes[a].well_conditioned_volume,
                summary.assembly_modes[a].well_conditioned_volume);
    }
  }
}


// workspace.bin keeps the figures: an analysis read back from the cache has them too.
TEST(ConditioningSummary, IsKeptInTheStateFile) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis analysis = analyseWorkspace(model, test::referenceGrid(model, 0.1), conditioningOptions(0.3, 5000));
  std::stringstream bytes;
  writeWorkspaceState(analysis, bytes);
  const WorkspaceAnalysis read = readWorkspaceState(model, bytes, "memory", 1);
  ASSERT_TRUE(read.conditioning());
  EXPECT_EQ(read.conditioning()->request.threshold, 0.3);
  EXPECT_EQ(read.conditioning()->request.evaluations, 5000u);
  EXPECT_EQ(read.conditioning()->stride, analysis.conditioning()->stride);
  for (int a = 0; a < 2; ++a) {
    const ConditioningFigures &written = analysis.conditioning()->assembly_modes[a], &back = read.conditioning()->assembly_modes[a];
    EXPECT_EQ(back.samples, written.samples);
    EXPECT_EQ(back.well_conditioned, written.well_conditioned);
    EXPECT_EQ(back.well_conditioned_volume, written.well_conditioned_volume);
    EXPECT_EQ(back.global_index, written.global_index);
  }
  std::stringstream plain;
  writeWorkspaceState(analyseWorkspace(model, test::referenceGrid(model, 0.1), AnalysisOptions()), plain);
  EXPECT_FALSE(readWorkspaceState(model, plain, "memory", 1).conditioning());
}

// --- The index on a maximal workspace's surface (surfaces/vertex_conditioning.h).

// Every vertex of the delta-like robot's maximal surfaces at 20 mm gets the best index of the
// maximal cell nearest to the point half a step inside along its normal, found here by
// scanning every cell (any of the cells equally near).
TEST(VertexConditioning, IsTheIndexOfTheNearestMaximalCellInside) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis analysis = analyseWorkspace(model, test::referenceGrid(model, 0.02), AnalysisOptions());
  const Grid& grid = analysis.grid();
  for (const AssemblyModeSummary& am : analysis.assemblyModes()) {
    const SurfaceMesh mesh = surfaceMesh(maximalWorkspaceCells(analysis, am.sign));
    const std::vector<float> indices = vertexConditioning(model, analysis, mesh, am.sign, grid.step(0));
    ASSERT_EQ(indices.size(), mesh.vertices.size());
    const std::vector<std::array<float, 3>> normals = vertexNormals(mesh);
    std::vector<std::uint64_t> maximal;
    for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
      if (analysis.inMaximalWorkspace(cell, am.sign)) maximal.push_back(cell);
    }
    int checked = 0;
    for (std::size_t v = 0; v < mesh.vertices.size(); v += 37, ++checked) {
      const Eigen::Vector3d point = Eigen::Vector3d(mesh.vertices[v][0], mesh.vertices[v][1], mesh.vertices[v][2]) -
                                    0.5 * grid.step(0) * Eigen::Vector3d(normals[v][0], normals[v][1], normals[v][2]);
      double nearest = INFINITY;
      for (std::uint64_t cell : maximal) nearest = std::min(nearest, (grid.pose(cell).position - point).norm());
      ASSERT_LT(nearest, grid.step(0)) << v;  // half a step inside lies in or next to a cell of the set
      bool matched = false;
      for (std::uint64_t cell : maximal) {
        if ((grid.pose(cell).position - point).norm() > nearest + 1e-9) continue;
        matched = matched || std::abs(bestIndexAt(model, analysis, cell, am.sign) - indices[v]) < 1e-6;
      }
      EXPECT_TRUE(matched) << "vertex " << v << " index " << indices[v];
    }
    EXPECT_GT(checked, 100);
  }
}

// The scale's top holds 95 % of the indices; viridis runs from dark violet to yellow,
// lighter at every step (its design), grey for NaN.
TEST(VertexConditioning, ScaleAndColoursAreViridisOnTheIndicesRange) {
  std::vector<float> indices;
  for (int k = 0; k < 100; ++k) indices.push_back(0.0004f * k);  // 0 to 0.0396
  indices.push_back(NAN);
  EXPECT_EQ(conditioningScaleTop(indices), 0.05);
  indices.push_back(0.9f);  // one index in a hundred above: still 0.05
  EXPECT_EQ(conditioningScaleTop(indices), 0.05);
  EXPECT_EQ(conditioningScaleTop({0.3f, 0.6f}), 1.0);
  EXPECT_EQ(conditioningScaleTop({NAN}), 1.0);
  EXPECT_EQ(conditioningColour(0.0, 0.2), (std::array<std::uint8_t, 3>{68, 1, 84}));
  EXPECT_EQ(conditioningColour(0.2, 0.2), (std::array<std::uint8_t, 3>{253, 231, 37}));
  EXPECT_EQ(conditioningColour(0.7, 0.2), conditioningColour(0.2, 0.2));
  EXPECT_EQ(conditioningColour(NAN, 0.2), (std::array<std::uint8_t, 3>{128, 128, 128}));
  double previous = -1.0;
  for (int k = 0; k <= 64; ++k) {
    const std::array<std::uint8_t, 3> c = conditioningColour(k / 64.0, 1.0);
    const double luminance = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    EXPECT_GT(luminance, previous) << k;
    previous = luminance;
  }
}

// On a closed mesh a constant is kept, NaN stays NaN and is left out of its neighbours'
// averages, and an alternating field's spread shrinks.
TEST(VertexConditioning, SmoothingOverTheMeshKeepsConstantsAndShrinksStripes) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis analysis = analyseWorkspace(model, test::referenceGrid(model, 0.04), AnalysisOptions());
  const SurfaceMesh mesh = surfaceMesh(maximalWorkspaceCells(analysis, 1));
  ASSERT_GT(mesh.vertices.size(), 100u);
  std::vector<float> constant(mesh.vertices.size(), 0.25f);
  constant[0] = NAN;
  const std::vector<float> kept = smoothedOverMesh(mesh, constant, 3);
  EXPECT_TRUE(std::isnan(kept[0]));
  for (std::size_t v = 1; v < kept.size(); ++v) ASSERT_NEAR(kept[v], 0.25f, 1e-6f) << v;
  // Stripes a display cell wide along x: 0 and 1 alternating.
  std::vector<float> stripes;
  for (const auto& vertex : mesh.vertices) stripes.push_back(std::fmod(std::floor(vertex[0] / 0.04f + 0.5f), 2.0f) == 0.0f ? 0.0f : 1.0f);
  const std::vector<float> blended = smoothedOverMesh(mesh, stripes, 3);
  double spread = 0.0;
  for (std::size_t v = 0; v < blended.size(); ++v) spread += std::abs(blended[v] - 0.5);
  EXPECT_LT(spread / blended.size(), 0.35) << "stripes of 0 and 1 are 0.5 from their mean";
  EXPECT_THROW(smoothedOverMesh(mesh, {1.0f}, 1), InputError);
}

// A PLY of the maximal workspace with conditioning carries the index per vertex as colour and
// as a float "quality", read back by assimp (colours) and by the header; STL has neither.
TEST(VertexConditioning, PlyMeshesCarryTheIndexAsColourAndQuality) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis analysis = analyseWorkspace(model, test::referenceGrid(model, 0.04), conditioningOptions(0.1));
  const test::TemporaryDirectory directory("test_conditioning");
  const std::vector<MeshFile> files = writeWorkspaceMeshes(analysis, MeshFormat::Ply, {}, directory.path(), &model);
  int coloured = 0;
  for (const MeshFile& file : files) {
    const std::string path = directory.path() + "/" + file.name;
    std::ifstream in(path, std::ios::binary);
    std::string header(400, '\0');
    in.read(header.data(), static_cast<std::streamsize>(header.size()));
    const bool maximal = file.name.rfind("maximal_", 0) == 0;
    EXPECT_EQ(header.find("property float quality") != std::string::npos, maximal) << file.name;
    EXPECT_EQ(file.conditioning_top > 0.0, maximal) << file.name;
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(path, 0);
    ASSERT_NE(scene, nullptr) << path << ": " << importer.GetErrorString();
    EXPECT_EQ(scene->mMeshes[0]->mColors[0] != nullptr, maximal) << file.name;
    coloured += maximal;
  }
  EXPECT_EQ(coloured, 2);
  // Without a model, or without the figures, no colours.
  const test::TemporaryDirectory plain("test_conditioning");
  for (const MeshFile& file : writeWorkspaceMeshes(analysis, MeshFormat::Ply, {}, plain.path())) {
    EXPECT_EQ(file.conditioning_top, 0.0) << file.name;
  }
}

}  // namespace
}  // namespace maximal_workspace
