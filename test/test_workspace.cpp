// The workspace engine against closed forms and hand-made cases: the PSS reach cylinder,
// the 5R's two annuli, the wave front against a brute-force flood fill, region labelling
// on synthetic sign fields, exact transition points, thread-count independence, the
// couple factorisation against LU, and the voxel budget.

#include <cmath>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "maximal_workspace/io/workspace_state.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/pss_chain.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

GridSpec spatialSpec(const RobotModel& model, double step) {
  GridSpec spec;
  for (OutputVariable variable : model.output_variables) {
    if (!isRotational(variable)) spec.variables.push_back(variable);
  }
  spec.steps = {step};
  spec.start = model.reference.pose;
  return spec;
}

// A one-chain mechanism (DOF x) whose workspace over x y z is the reach of one PSS chain:
// the cylinder of radius R about the slider line, cut by the box.
RobotModel singlePss(double rod_length) {
  return parseRobotFile(R"(
name: one_pss
output_variables: [x]
inputs: [{name: q}]
chains:
  - {name: leg, type: PSS, input: q, fixed_node: [0.013, -0.021, 0], direction: [0, 0, 1],
     rod_length: )" + std::to_string(rod_length) + R"(, platform_node: [0, 0, 0]}
reference: {position: [0.05, 0.02, 0.0]}
)",
                        "one_pss.yaml");
}

TEST(WaveFront, SinglePssChainFillsItsReachCylinder) {
  const double radius = 0.3, step = 0.01;
  const RobotModel model = singlePss(radius);
  GridSpec spec;
  spec.variables = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
  spec.steps = {step};
  spec.start = model.reference.pose;
  spec.bounds = {{-0.5, 0.5}, {-0.5, 0.5}, {-0.4, 0.4}};
  AnalysisOptions options;
  options.start_mode = "p";
  const WorkspaceAnalysis analysis = analyseWorkspace(model, spec, options);
  // The box cuts the cylinder across its axis: length = the box's cells along z.
  const double length = analysis.grid.size(2) * step;
  const double closed_form = M_PI * radius * radius * length;
  // Voxels whose centre is inside: off by at most the cells the circle's perimeter crosses.
  const double grid_error = 2.0 * M_PI * radius * step * length;
  EXPECT_NEAR(analysis.workspaceVolume(), closed_form, grid_error);
  // Exactly: the lattice points of the cross-section inside the circle, times the layers;
  // points within rounding of the circle may fall either way.
  std::uint64_t surely_inside = 0, maybe_inside = 0;
  for (std::int64_t i = 0; i < analysis.grid.size(0); ++i) {
    for (std::int64_t j = 0; j < analysis.grid.size(1); ++j) {
      const double r = std::hypot(analysis.grid.centre(0, i) - 0.013, analysis.grid.centre(1, j) + 0.021);
      surely_inside += r < radius - 1e-12;
      maybe_inside += r <= radius + 1e-12;
    }
  }
  EXPECT_GE(analysis.map.voxelCount(), surely_inside * analysis.grid.size(2));
  EXPECT_LE(analysis.map.voxelCount(), maybe_inside * analysis.grid.size(2));
}

// Area of the intersection of two discs of radii r1, r2 with centres d apart.
double lens(double r1, double r2, double d) {
  if (d >= r1 + r2) return 0.0;
  if (d <= std::abs(r1 - r2)) return M_PI * std::pow(std::min(r1, r2), 2);
  const double a = r1 * r1 * std::acos((d * d + r1 * r1 - r2 * r2) / (2 * d * r1));
  const double b = r2 * r2 * std::acos((d * d + r2 * r2 - r1 * r1) / (2 * d * r2));
  return a + b - 0.5 * std::sqrt((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2));
}

TEST(WaveFront, FiveBarAreaIsTheIntersectionOfTwoAnnuli) {
  // Each leg reaches the annulus 0.05 <= r <= 0.45 about its base; bases 0.2 apart.
  const double outer = 0.45, inner = 0.05, d = 0.2;
  const double closed_form = lens(outer, outer, d) - 2 * lens(outer, inner, d) + lens(inner, inner, d);
  const WorkspaceAnalysis analysis = analyseWorkspace(test::fiveBar(), spatialSpec(test::fiveBar(), 0.002), {});
  EXPECT_NEAR(analysis.workspaceVolume(), closed_form, 0.005 * closed_form);
  EXPECT_EQ(analysis.modes.size(), 4u);
}

TEST(WaveFront, EqualsTheConnectedComponentOfABruteForceScan) {
  const RobotModel& model = test::fiveBar();
  const WorkspaceAnalysis analysis = analyseWorkspace(model, spatialSpec(model, 0.01), {});
  const Grid& grid = analysis.grid;
  // Every cell of the box tested, then a flood fill from the start written here.
  std::vector<char> assembled(grid.cellCount());
  for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) assembled[cell] = solveIkp(model, grid.pose(cell)).assembled;
  std::uint64_t start = 0;
  ASSERT_TRUE(grid.cellOf(grid.spec().start, &start));
  std::set<std::uint64_t> reached = {start};
  std::vector<std::uint64_t> stack = {start};
  while (!stack.empty()) {
    const GridCell cell = grid.cell(stack.back());
    stack.pop_back();
    for (int d = 0; d < grid.dims(); ++d) {
      for (int step : {-1, 1}) {
        GridCell next = cell;
        next[d] += step;
        if (next[d] < 0 || next[d] >= grid.size(d)) continue;
        const std::uint64_t index = grid.index(next);
        if (assembled[index] && reached.insert(index).second) stack.push_back(index);
      }
    }
  }
  const std::set<std::uint64_t> found(analysis.map.voxel_cell.begin(), analysis.map.voxel_cell.end());
  EXPECT_EQ(found, reached);
}

TEST(WaveFront, RotationalVariableSliceHoldsTheConstantOrientationWorkspace) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis fixed = analyseWorkspace(model, spatialSpec(model, 0.04), {});
  GridSpec spec = spatialSpec(model, 0.04);
  spec.variables.push_back(OutputVariable::Phi);
  spec.steps = {0.04, 0.04, 0.04, 0.1};
  spec.bounds = {fixed.grid.spec().bounds[0], fixed.grid.spec().bounds[1], fixed.grid.spec().bounds[2], {-0.3, 0.3}};
  const WorkspaceAnalysis turning = analyseWorkspace(model, spec, {});
  ASSERT_FALSE(turning.factorised);  // the orientation varies: LU per working mode
  // Every voxel of the x y z workspace is in the phi = 0 slice, with the same signs (the
  // same poses, classified by the other path); the slice may hold more, reached through
  // other orientations.
  std::uint64_t slice = 0;
  for (std::uint32_t v = 0; v < turning.map.voxelCount(); ++v) {
    slice += std::abs(turning.grid.pose(turning.map.voxel_cell[v]).euler_zyz[0]) < 1e-12;
  }
  EXPECT_GE(slice, fixed.map.voxelCount());
  int compared = 0;
  for (std::uint32_t v = 0; v < fixed.map.voxelCount(); ++v) {
    const Pose pose = fixed.grid.pose(fixed.map.voxel_cell[v]);
    std::uint64_t cell = 0;
    ASSERT_TRUE(turning.grid.cellOf(pose, &cell));
    ASSERT_LT(turning.map.cell_voxel[cell], kCellOutside);
    const std::uint32_t other = turning.map.cell_voxel[cell];
    EXPECT_EQ(turning.grid.pose(cell).position, pose.position);
    for (int m = 0; m < 8; ++m) compared += turning.map.sign(other, m) == fixed.map.sign(v, m);
  }
  EXPECT_EQ(compared, 8 * static_cast<int>(fixed.map.voxelCount()));
}

// A hand-made sign field on a 2-D grid, one working mode.
struct SyntheticField {
  Grid grid;
  WorkspaceMap map;
};

SyntheticField syntheticField(const std::vector<std::string>& rows) {
  GridSpec spec;
  spec.variables = {OutputVariable::X, OutputVariable::Y};
  spec.steps = {1.0};
  // Cell centres at k + 1/2: these bounds hold exactly the field's cells.
  spec.bounds = {{0.5, rows[0].size() - 0.5}, {0.5, rows.size() - 0.5}};
  spec.start.position = Eigen::Vector3d(0.5, 0.5, 0.0);
  SyntheticField field{Grid(test::fiveBar(), spec), WorkspaceMap{}};
  field.map.mode_count = 1;
  field.map.cell_voxel.assign(field.grid.cellCount(), kCellOutside);
  // rows[j][i]: '+' or '-' a signed voxel, '0' the singular band, '.' outside.
  for (std::size_t j = 0; j < rows.size(); ++j) {
    for (std::size_t i = 0; i < rows[j].size(); ++i) {
      const char c = rows[j][i];
      if (c == '.') continue;
      const std::uint64_t cell = field.grid.index(GridCell{static_cast<std::int64_t>(i), static_cast<std::int64_t>(j)});
      field.map.cell_voxel[cell] = static_cast<std::uint32_t>(field.map.voxel_cell.size());
      field.map.voxel_cell.push_back(static_cast<std::uint32_t>(cell));
      field.map.signs.push_back(c == '+' ? 1 : c == '-' ? -1 : 0);
    }
  }
  return field;
}

TEST(Regions, LabelsFaceConnectedComponentsOfOneSign) {
  const SyntheticField field = syntheticField({
      "++0--",
      "++0--",
      "000-+",  // the lone + touches the - block only by faces: its own region
      "+.0--",  // the + at (0,3) touches the top-left block only through the band
      "-+.--",  // diagonal neighbours (0,4)-(1,3)... are not connected
  });
  const RegionMap regions = labelRegions(field.grid, field.map, DebrisThreshold{2, 0.0}, 1);
  // + : top-left 2x2 block, (4,2), (0,3), (1,4); - : right block, (0,4).
  std::multiset<std::pair<int, std::uint64_t>> found;
  for (const Region& region : regions.regions) found.insert({region.sign, region.voxels});
  const std::multiset<std::pair<int, std::uint64_t>> expected = {{1, 4}, {1, 1}, {1, 1}, {1, 1}, {-1, 9}, {-1, 1}};
  EXPECT_EQ(found, expected);
  for (const Region& region : regions.regions) EXPECT_EQ(region.debris, region.voxels < 2);
  // Band voxels have no region; voxels of one block share theirs.
  auto label_at = [&](int i, int j) {
    return regions.label(field.map.cell_voxel[field.grid.index(GridCell{i, j})], 0);
  };
  EXPECT_EQ(label_at(2, 0), -1);
  EXPECT_EQ(label_at(0, 0), label_at(1, 1));
  EXPECT_EQ(label_at(3, 0), label_at(4, 4));
  EXPECT_NE(label_at(0, 3), label_at(0, 0));
  EXPECT_NE(label_at(1, 4), label_at(0, 3));
}

TEST(Regions, DebrisThresholdScalesWithTheWorkspace) {
  const SyntheticField field = syntheticField({"+++++", "+++++", "--0+-", "+++++"});
  // 18 voxels: 2 % of them is 0.36 voxel, 30 % is 5.4 voxels.
  const RegionMap small = labelRegions(field.grid, field.map, DebrisThreshold{1, 0.02}, 1);
  const RegionMap large = labelRegions(field.grid, field.map, DebrisThreshold{1, 0.3}, 1);
  for (const Region& region : small.regions) EXPECT_FALSE(region.debris);
  for (const Region& region : large.regions) EXPECT_EQ(region.debris, region.voxels < 5.4);
}

TEST(Transitions, BisectionLandsOnTheReachBoundary) {
  const double radius = 0.3;
  const RobotModel model = singlePss(radius);
  const Chain& chain = *model.chains[0];
  for (int k = 0; k < 100; ++k) {
    // From inside the cylinder to outside along a random direction, one step apart.
    const double angle = test::uniform(-M_PI, M_PI), step = test::uniform(0.001, 0.05);
    const Eigen::Vector3d axis_point(0.013, -0.021, test::uniform(-1, 1));
    const Eigen::Vector3d outward(std::cos(angle), std::sin(angle), 0.0);
    Pose inside, outside;
    inside.position = axis_point + (radius - test::uniform(0.0, step)) * outward;
    outside.position = inside.position + step * outward;
    const Pose point = bisectReachBoundary(chain, chain.platformNode(), inside, outside, step, 1e-9);
    EXPECT_NEAR((point.position - axis_point).norm(), radius, 1e-9);
    EXPECT_LE((point.position - axis_point).norm(), radius);  // on the assembled side
  }
}

TEST(Transitions, FiveBarPointsAreExactlyOnAnAnnulusAndJoinEqualConfigurations) {
  const RobotModel& model = test::fiveBar();
  const WorkspaceAnalysis analysis = analyseWorkspace(model, spatialSpec(model, 0.005), {});
  ASSERT_FALSE(analysis.transitions.points.empty());
  const Eigen::Vector3d bases[2] = {{-0.1, 0, 0}, {0.1, 0, 0}};
  for (const TransitionPoint& point : analysis.transitions.points) {
    const double r = (point.pose.position - bases[point.chain]).norm();
    EXPECT_LT(std::min(std::abs(r - 0.45), std::abs(r - 0.05)), 1e-9) << r;
  }
  // At a transition point the two working modes are one configuration: same measure, up
  // to the bisection's tolerance delta = 1e-9 m inside the boundary, where the branches
  // still differ by about sqrt(2 R delta) = 2e-5 m on 0.25 m rods (measure ~1e-4).
  const PoseClassifier classifier(model, analysis.modes, model.reference.pose, true);
  std::vector<double> measures(analysis.modes.size());
  for (const Transition& transition : analysis.transitions.transitions) {
    const int from = analysis.regions.regions[transition.from_region].mode;
    const int to = analysis.regions.regions[transition.to_region].mode;
    for (std::uint32_t p : transition.points) {
      ASSERT_TRUE(classifier.classify(analysis.transitions.points[p].pose, measures.data()));
      EXPECT_NEAR(measures[from], measures[to], 1e-3);
      EXPECT_EQ(bandedSign(measures[from], 1e-3), transition.sign);
    }
  }
}

TEST(Transitions, DeltaLikeJoinsModesThatDifferInOneCouple) {
  const WorkspaceAnalysis analysis = analyseWorkspace(test::deltaLike(), spatialSpec(test::deltaLike(), 0.02), {});
  ASSERT_FALSE(analysis.transitions.transitions.empty());
  for (const Transition& transition : analysis.transitions.transitions) {
    const std::string& from = analysis.modes[analysis.regions.regions[transition.from_region].mode].name;
    const std::string& to = analysis.modes[analysis.regions.regions[transition.to_region].mode].name;
    int differences = 0;
    for (std::size_t k = 0; k < from.size(); ++k) differences += from[k] != to[k];
    EXPECT_EQ(differences, 1);
    EXPECT_NE(from[transition.input], to[transition.input]);
    EXPECT_EQ(analysis.regions.regions[transition.from_region].sign, transition.sign);
    EXPECT_EQ(analysis.regions.regions[transition.to_region].sign, transition.sign);
  }
}

void expectSameAnalysis(const WorkspaceAnalysis& a, const WorkspaceAnalysis& b) {
  EXPECT_EQ(a.map.voxel_cell, b.map.voxel_cell);
  EXPECT_EQ(a.map.signs, b.map.signs);
  EXPECT_EQ(a.regions.labels, b.regions.labels);
  ASSERT_EQ(a.transitions.points.size(), b.transitions.points.size());
  for (std::size_t p = 0; p < a.transitions.points.size(); ++p) {
    EXPECT_EQ(a.transitions.points[p].pose.position, b.transitions.points[p].pose.position);
  }
  ASSERT_EQ(a.transitions.transitions.size(), b.transitions.transitions.size());
  for (std::size_t t = 0; t < a.transitions.transitions.size(); ++t) {
    EXPECT_EQ(a.transitions.transitions[t].points, b.transitions.transitions[t].points);
  }
  EXPECT_EQ(a.singularities.dkp.size(), b.singularities.dkp.size());
  EXPECT_EQ(a.singularities.ikp.size(), b.singularities.ikp.size());
  for (int am = 0; am < 2; ++am) EXPECT_EQ(a.assembly_modes[am].reachable_voxels, b.assembly_modes[am].reachable_voxels);
}

TEST(WorkspaceAnalysis, ResultsDoNotDependOnTheThreadCount) {
  for (const RobotModel* model : {&test::deltaLike(), &test::fiveBar()}) {
    AnalysisOptions one, three;
    one.threads = 1;
    three.threads = 3;
    const GridSpec spec = spatialSpec(*model, model == &test::deltaLike() ? 0.02 : 0.005);
    expectSameAnalysis(analyseWorkspace(*model, spec, one), analyseWorkspace(*model, spec, three));
  }
}

TEST(WorkspaceState, ReadsBackTheSameAnalysis) {
  for (const RobotModel* model : {&test::deltaLike(), &test::fiveBar()}) {
    AnalysisOptions options;
    const WorkspaceAnalysis analysis = analyseWorkspace(*model, spatialSpec(*model, model == &test::deltaLike() ? 0.02 : 0.01), options);
    std::stringstream bytes;
    writeWorkspaceState(analysis, options, bytes);
    const WorkspaceAnalysis back = readWorkspaceState(*model, bytes, "state");
    expectSameAnalysis(back, analysis);
    EXPECT_EQ(back.map.cell_voxel, analysis.map.cell_voxel);  // outside cells too
    EXPECT_EQ(back.transitions.component, analysis.transitions.component);
    EXPECT_EQ(back.start_mode, analysis.start_mode);
    for (int am = 0; am < 2; ++am) {
      EXPECT_EQ(back.assembly_modes[am].maximal_voxels, analysis.assembly_modes[am].maximal_voxels);
      EXPECT_EQ(back.assembly_modes[am].traditional_region, analysis.assembly_modes[am].traditional_region);
    }
  }
}

TEST(WorkspaceState, DamagedBytesAreAClearErrorNotACrash) {
  const RobotModel& model = test::fiveBar();
  AnalysisOptions options;
  const WorkspaceAnalysis analysis = analyseWorkspace(model, spatialSpec(model, 0.02), options);
  std::stringstream bytes;
  writeWorkspaceState(analysis, options, bytes);
  const std::string good = bytes.str();
  auto message_of = [&](const std::string& damaged) {
    std::stringstream in(damaged);
    try {
      readWorkspaceState(model, in, "damaged.bin");
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  for (std::size_t cut : {std::size_t{0}, std::size_t{5}, std::size_t{200}, good.size() / 2, good.size() - 1}) {
    EXPECT_NE(message_of(good.substr(0, cut)).find("damaged.bin: not a usable workspace state file"), std::string::npos)
        << "cut at " << cut;
  }
  std::string other = good;
  other[0] = 'X';
  EXPECT_NE(message_of(other).find("wrong magic"), std::string::npos);
  EXPECT_NE(message_of(good + "x").find("bytes after the end"), std::string::npos);
  // A flipped sign changes the regions the labels give: the table no longer matches.
  std::stringstream flipped_source;
  WorkspaceAnalysis flipped = analyseWorkspace(model, spatialSpec(model, 0.02), options);
  for (std::int8_t& sign : flipped.map.signs) sign = static_cast<std::int8_t>(-sign);
  writeWorkspaceState(flipped, options, flipped_source);
  std::string mixed = flipped_source.str();
  EXPECT_NE(message_of(mixed).find("region table does not match"), std::string::npos);
}

TEST(WorkspaceAnalysis, WorkingModeFilterAnalysesOnlyThoseModes) {
  const RobotModel& model = test::deltaLike();
  AnalysisOptions options;
  options.working_modes = {"npn", "ppn", "nnn"};
  const WorkspaceAnalysis analysis = analyseWorkspace(model, spatialSpec(model, 0.02), options);
  ASSERT_EQ(analysis.modes.size(), 3u);
  EXPECT_EQ(analysis.modes[0].name, "ppn");  // canonical order
  EXPECT_EQ(analysis.modes[analysis.start_mode].name, "npn");
  for (const Transition& transition : analysis.transitions.transitions) {
    // Only npn - ppn differ in one couple (nnn differs from npn in KC2, from ppn in two).
    const std::string& from = analysis.modes[analysis.regions.regions[transition.from_region].mode].name;
    const std::string& to = analysis.modes[analysis.regions.regions[transition.to_region].mode].name;
    EXPECT_TRUE((from == "ppn" && to == "npn") || (from == "npn" && to == "nnn")) << from << " " << to;
  }
  options.working_modes = {"ppp"};  // without the start mode
  EXPECT_THROW(analyseWorkspace(model, spatialSpec(model, 0.02), options), InputError);
  options.working_modes = {"pqp"};
  EXPECT_THROW(analyseWorkspace(model, spatialSpec(model, 0.02), options), InputError);
}

TEST(WorkspaceAnalysis, AssemblyModeFiguresAreConsistent) {
  const WorkspaceAnalysis analysis = analyseWorkspace(test::deltaLike(), spatialSpec(test::deltaLike(), 0.02), {});
  for (const AssemblyModeSummary& am : analysis.assembly_modes) {
    ASSERT_GE(am.traditional_region, 0);
    // traditional <= reachable <= maximal <= workspace
    EXPECT_LE(analysis.regions.regions[am.traditional_region].voxels, am.reachable_voxels);
    EXPECT_LE(am.reachable_voxels, am.maximal_voxels);
    EXPECT_LE(am.maximal_voxels, analysis.map.voxelCount());
    EXPECT_EQ(analysis.regions.regions[am.traditional_region].sign, am.sign);
  }
  // The robot starts in its reference working mode, whose region holds the start voxel.
  const int start_region = analysis.regions.label(0, analysis.start_mode);
  const int start_sign = analysis.regions.regions[start_region].sign;
  EXPECT_EQ(analysis.assembly_modes[start_sign > 0 ? 0 : 1].traditional_region, start_region);
}

TEST(PoseClassifier, CoupleFactorisationAgreesWithLu) {
  const RobotModel& model = test::deltaLike();
  const std::vector<WorkingMode> modes = coupledWorkingModes(model);
  const PoseClassifier factorised(model, modes, model.reference.pose, true);
  const PoseClassifier generic(model, modes, model.reference.pose, false);
  ASSERT_TRUE(factorised.factorised());
  ASSERT_FALSE(generic.factorised());
  std::vector<double> fast(modes.size()), slow(modes.size());
  int assembled = 0;
  for (int k = 0; k < 5000; ++k) {
    Pose pose = model.reference.pose;
    pose.position += test::uniformVector(-0.4, 0.4);
    const bool a = factorised.classify(pose, fast.data());
    ASSERT_EQ(a, generic.classify(pose, slow.data()));
    if (!a) continue;
    ++assembled;
    for (std::size_t m = 0; m < modes.size(); ++m) EXPECT_NEAR(fast[m], slow[m], 1e-12);
  }
  EXPECT_GT(assembled, 1000);
}

// The batch path against pose-by-pose classification, factorised (vectorised kernels,
// possibly with FMA) and generic, over a count that leaves a partial block.
TEST(PoseClassifier, BatchAgreesWithPoseByPose) {
  for (const RobotModel* model : {&test::deltaLike(), &test::fiveBar()}) {
    const std::vector<WorkingMode> modes = coupledWorkingModes(*model);
    for (bool fixed : {true, false}) {
      const PoseClassifier classifier(*model, modes, model->reference.pose, fixed);
      const std::size_t n = 1000, count = modes.size();
      std::vector<double> x(n), y(n), z(n), batch(n * count), one(count);
      std::vector<std::uint8_t> inside(n);
      for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector3d p = model->reference.pose.position + test::uniformVector(-0.4, 0.4);
        x[i] = p.x(), y[i] = p.y(), z[i] = model->hasOutputVariable(OutputVariable::Z) ? p.z() : model->reference.pose.position.z();
      }
      classifier.classify(PointBatch{x.data(), y.data(), z.data(), n}, inside.data(), batch.data());
      int assembled = 0;
      for (std::size_t i = 0; i < n; ++i) {
        Pose pose = model->reference.pose;
        pose.position = Eigen::Vector3d(x[i], y[i], z[i]);
        const bool a = classifier.classify(pose, one.data());
        ASSERT_EQ(inside[i] == 1, a) << model->name << " pose " << i;
        if (!a) continue;
        ++assembled;
        for (std::size_t m = 0; m < count; ++m) EXPECT_NEAR(batch[i * count + m], one[m], 1e-12) << model->name;
      }
      EXPECT_GT(assembled, 100) << model->name;
      EXPECT_LT(assembled, static_cast<int>(n)) << model->name;
    }
  }
}

TEST(Grid, RefusesABoxOverTheBudgetBeforeAllocating) {
  GridSpec spec = spatialSpec(test::deltaLike(), 0.001);
  try {
    const Grid grid(test::deltaLike(), spec);
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    const std::string message = error.what();
    // 0.001 m over the delta-like box: about a thousand cells a side.
    EXPECT_NE(message.find("needs"), std::string::npos) << message;
    EXPECT_NE(message.find("budget"), std::string::npos) << message;
    EXPECT_NE(message.find(" = "), std::string::npos) << message;
  }
}

TEST(Grid, DefaultBoxLeavesEveryVoxelItsNeighbours) {
  // The reach box is tight; unless the grid has a cell of margin, voxels on its edge
  // would have untested neighbours and their IKP faces, and transitions, would be lost.
  for (const RobotModel* model : {&test::deltaLike(), &test::fiveBar()}) {
    const WorkspaceAnalysis analysis = analyseWorkspace(*model, spatialSpec(*model, 0.02), {});
    for (std::uint32_t cell : analysis.map.voxel_cell) {
      for (int d = 0; d < analysis.grid.dims(); ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t neighbour = 0;
          EXPECT_TRUE(analysis.grid.neighbour(cell, d, direction, &neighbour)) << model->name;
        }
      }
    }
  }
}

TEST(Grid, UserBoundsHoldTheCellCentres) {
  GridSpec spec = spatialSpec(test::deltaLike(), 0.02);
  spec.bounds = {{0.013, 0.4}, {0.0, 0.4}, {0.5, 0.9}};
  const Grid grid(test::deltaLike(), spec);
  for (int d = 0; d < 3; ++d) {
    EXPECT_GE(grid.centre(d, 0), spec.bounds[d][0]);
    EXPECT_LE(grid.centre(d, grid.size(d) - 1), spec.bounds[d][1]);
    // and no cell centre within the bounds is left out
    EXPECT_LT(grid.centre(d, 0) - 0.02, spec.bounds[d][0]);
    EXPECT_GT(grid.centre(d, grid.size(d) - 1) + 0.02, spec.bounds[d][1]);
  }
}

TEST(Grid, VoxelCentresAreOctreeCellCentres) {
  const Grid grid(test::deltaLike(), spatialSpec(test::deltaLike(), 0.02));
  for (int d = 0; d < 3; ++d) {
    for (std::int64_t i : {std::int64_t{0}, grid.size(d) / 2, grid.size(d) - 1}) {
      // OctoMap cells of resolution r have centres at (k + 1/2) r.
      const double k = grid.centre(d, i) / 0.02 - 0.5;
      EXPECT_NEAR(k, std::round(k), 1e-9);
    }
  }
}

TEST(Grid, RejectsBadSpecsWithAClearReason) {
  const RobotModel& model = test::deltaLike();
  auto message_of = [&](GridSpec spec) {
    try {
      Grid grid(model, spec);
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  GridSpec spec = spatialSpec(model, 0.01);
  spec.steps = {-0.01};
  EXPECT_NE(message_of(spec).find("step of x"), std::string::npos);
  spec.steps = {NAN};
  EXPECT_NE(message_of(spec).find("finite"), std::string::npos);
  spec = spatialSpec(model, 0.01);
  spec.bounds = {{0.5, 0.0}, {-1, 1}, {-1, 1}};
  EXPECT_NE(message_of(spec).find("lower < upper"), std::string::npos);
  spec.bounds = {{0.3, 0.4}, {-1, 1}, {-1, 1}};
  EXPECT_NE(message_of(spec).find("outside the bounds"), std::string::npos);
  spec = spatialSpec(model, 0.01);
  spec.variables = {OutputVariable::X, OutputVariable::X};
  EXPECT_NE(message_of(spec).find("twice"), std::string::npos);
  // Steps so fine that cell indices overflow (found by fuzz_workspace_request): refused,
  // not converted (undefined behaviour).
  for (double tiny : {1e-300, 4.9e-324}) {
    spec = spatialSpec(model, tiny);
    EXPECT_NE(message_of(spec).find("too fine for its bounds"), std::string::npos) << message_of(spec);
  }
  // A lone PSS chain leaves its slider axis unbounded.
  const RobotModel one = singlePss(0.3);
  GridSpec open;
  open.variables = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
  open.steps = {0.01};
  open.start = one.reference.pose;
  try {
    Grid grid(one, open);
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("unbounded along z"), std::string::npos) << error.what();
  }
}

TEST(WorkspaceAnalysis, StartOutsideTheWorkspaceOrUnknownModeIsRefused) {
  const RobotModel& model = test::deltaLike();
  GridSpec spec = spatialSpec(model, 0.02);
  AnalysisOptions options;
  options.start_mode = "xyz";
  EXPECT_THROW(analyseWorkspace(model, spec, options), InputError);
  options.start_mode = "ppp";
  spec.start.position = Eigen::Vector3d(0.9, 0.9, 0.7);  // inside the box, no chain reaches
  try {
    analyseWorkspace(model, spec, options);
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("outside the workspace"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace maximal_workspace
