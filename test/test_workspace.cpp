// The workspace engine against closed forms and hand-made cases: the PSS reach cylinder,
// the 5R's two annuli, region labelling and component search on synthetic fields, exact
// transition points, thread-count independence, the state file, the couple factorisation
// against LU, grids (periodic ones included), block layouts, and the memory budget.
// test_engine_reference.cpp checks whole analyses against a brute-force reference.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

#include <fstream>

#include "maximal_workspace/io/workspace_state.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/pss_chain.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "io/state_archive.h"
#include "regions/analysis_data.h"
#include "regions/transition_search.h"
#include "test_support.h"
#include "workspace/block_components.h"
#include "workspace/block_storage.h"
#include "workspace/classification.h"
#include "workspace/parallel.h"

namespace maximal_workspace {
namespace {

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

// Cells of the box in the workspace, in grid order.
std::vector<std::uint64_t> workspaceCells(const WorkspaceAnalysis& analysis) {
  std::vector<std::uint64_t> cells;
  for (std::uint64_t cell = 0; cell < analysis.grid().cellCount(); ++cell) {
    if (analysis.inside(cell)) cells.push_back(cell);
  }
  return cells;
}

// The sign of det J_DKP a working mode's regions give a cell: 0 in the band or outside.
int regionSign(const WorkspaceAnalysis& analysis, std::uint64_t cell, int mode) {
  const std::int32_t label = analysis.label(cell, mode);
  return label >= 0 ? analysis.regions()[label].sign : 0;
}

TEST(Workspace, SinglePssChainFillsItsReachCylinder) {
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
  const Grid& grid = analysis.grid();
  // The box cuts the cylinder across its axis: length = the box's cells along z.
  const double length = grid.size(2) * step;
  const double closed_form = M_PI * radius * radius * length;
  // Voxels whose centre is inside: off by at most the cells the circle's perimeter crosses.
  const double grid_error = 2.0 * M_PI * radius * step * length;
  EXPECT_NEAR(analysis.workspaceVolume(), closed_form, grid_error);
  // Exactly: the lattice points of the cross-section inside the circle, times the layers;
  // points within rounding of the circle may fall either way.
  std::uint64_t surely_inside = 0, maybe_inside = 0;
  for (std::int64_t i = 0; i < grid.size(0); ++i) {
    for (std::int64_t j = 0; j < grid.size(1); ++j) {
      const double r = std::hypot(grid.centre(0, i) - 0.013, grid.centre(1, j) + 0.021);
      surely_inside += r < radius - 1e-12;
      maybe_inside += r <= radius + 1e-12;
    }
  }
  EXPECT_GE(analysis.voxelCount(), surely_inside * grid.size(2));
  EXPECT_LE(analysis.voxelCount(), maybe_inside * grid.size(2));
}

// Area of the intersection of two discs of radii r1, r2 with centres d apart.
double lens(double r1, double r2, double d) {
  if (d >= r1 + r2) return 0.0;
  if (d <= std::abs(r1 - r2)) return M_PI * std::pow(std::min(r1, r2), 2);
  const double a = r1 * r1 * std::acos((d * d + r1 * r1 - r2 * r2) / (2 * d * r1));
  const double b = r2 * r2 * std::acos((d * d + r2 * r2 - r1 * r1) / (2 * d * r2));
  return a + b - 0.5 * std::sqrt((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2));
}

TEST(Workspace, FiveBarAreaIsTheIntersectionOfTwoAnnuli) {
  // Each leg reaches the annulus 0.05 <= r <= 0.45 about its base; bases 0.2 apart.
  const double outer = 0.45, inner = 0.05, d = 0.2;
  const double closed_form = lens(outer, outer, d) - 2 * lens(outer, inner, d) + lens(inner, inner, d);
  const WorkspaceAnalysis analysis = analyseWorkspace(test::fiveBar(), test::referenceGrid(test::fiveBar(), 0.002), {});
  EXPECT_NEAR(analysis.workspaceVolume(), closed_form, 0.005 * closed_form);
  EXPECT_EQ(analysis.modes().size(), 4u);
}

TEST(Workspace, RotationalVariableSliceHoldsTheConstantOrientationWorkspace) {
  const RobotModel& model = test::deltaLike();
  const WorkspaceAnalysis fixed = analyseWorkspace(model, test::referenceGrid(model, 0.04), {});
  GridSpec spec = test::referenceGrid(model, 0.04);
  spec.variables.push_back(OutputVariable::Phi);
  spec.steps = {0.04, 0.04, 0.04, 0.1};
  const std::vector<std::array<double, 2>>& box = fixed.grid().spec().bounds;
  spec.bounds = {box[0], box[1], box[2], {-0.3, 0.3}};
  const WorkspaceAnalysis turning = analyseWorkspace(model, spec, {});
  ASSERT_FALSE(turning.factorised());  // the orientation varies: LU per working mode
  // Every cell of the x y z workspace is in the phi = 0 slice, with the same regions' signs
  // (the same poses, classified by the other path); the slice may hold more, reached
  // through other orientations.
  std::uint64_t slice = 0;
  for (std::uint64_t cell : workspaceCells(turning)) slice += std::abs(turning.grid().pose(cell).euler_zyz[0]) < 1e-12;
  const std::vector<std::uint64_t> cells = workspaceCells(fixed);
  EXPECT_GE(slice, cells.size());
  std::uint64_t compared = 0;
  for (std::uint64_t cell : cells) {
    const Pose pose = fixed.grid().pose(cell);
    std::uint64_t other = 0;
    ASSERT_TRUE(turning.grid().cellOf(pose, &other));
    ASSERT_TRUE(turning.inside(other));
    EXPECT_EQ(turning.grid().pose(other).position, pose.position);
    for (int m = 0; m < 8; ++m) compared += regionSign(turning, other, m) == regionSign(fixed, cell, m);
  }
  EXPECT_EQ(compared, 8 * cells.size());
}

// A hand-made field on a 2-D grid, one working mode: rows[j][i] is '+' or '-' a signed
// workspace cell, '0' the singular band, '.' outside.
struct SyntheticField {
  Grid grid;
  WorkspaceCells cells;
};

SyntheticField syntheticField(const std::vector<std::string>& rows) {
  GridSpec spec;
  spec.variables = {OutputVariable::X, OutputVariable::Y};
  spec.steps = {1.0};
  // Cell centres at k + 1/2: these bounds hold exactly the field's cells.
  spec.bounds = {{0.5, rows[0].size() - 0.5}, {0.5, rows.size() - 0.5}};
  spec.start.position = Eigen::Vector3d(0.5, 0.5, 0.0);
  SyntheticField field{Grid(test::fiveBar(), spec), {}};
  WorkspaceCells& cells = field.cells;
  cells.layout = BlockLayout(field.grid);
  cells.codes = CodeMap(cells.layout.blockCount(), cells.layout.cellsPerBlock());
  // Codes 0, 1, 2: the patterns of sign +, - and the band.
  cells.patterns = SignPatterns{1, {{1, 0}, {2, 0}, {0, 0}}};
  for (std::uint64_t b = 0; b < cells.layout.blockCount(); ++b) {
    std::vector<CellCode> page(cells.layout.cellsPerBlock(), kCodeVoid);
    for (int c = 0; c < cells.layout.cellsPerBlock(); ++c) {
      const GridCell at = cells.layout.cellCoords(b, c);
      if (!cells.layout.inBox(at)) continue;
      const char sign = rows[at[1]][at[0]];
      page[c] = sign == '+' ? 0 : sign == '-' ? 1 : sign == '0' ? 2 : kCodeOutside;
      cells.inside_cells += sign != '.';
    }
    cells.codes.addPage(b, page.data());
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
  const RegionLabels regions = labelRegions(field.grid, field.cells, DebrisThreshold{2, 0.0}, 1);
  // + : top-left 2x2 block, (4,2), (0,3), (1,4); - : right block, (0,4).
  std::multiset<std::pair<int, std::uint64_t>> found;
  for (const Region& region : regions.regions) found.insert({region.sign, region.voxels});
  const std::multiset<std::pair<int, std::uint64_t>> expected = {{1, 4}, {1, 1}, {1, 1}, {1, 1}, {-1, 9}, {-1, 1}};
  EXPECT_EQ(found, expected);
  for (const Region& region : regions.regions) EXPECT_EQ(region.debris, region.voxels < 2);
  // Band cells have no region; cells of one block share theirs.
  auto label_at = [&](int i, int j) {
    std::uint64_t block = 0;
    int cell = 0;
    field.cells.layout.locate(GridCell{i, j}, &block, &cell);
    return regions.label(block, cell, 0);
  };
  EXPECT_EQ(label_at(2, 0), -1);
  EXPECT_EQ(label_at(0, 0), label_at(1, 1));
  EXPECT_EQ(label_at(3, 0), label_at(4, 4));
  EXPECT_NE(label_at(0, 3), label_at(0, 0));
  EXPECT_NE(label_at(1, 4), label_at(0, 3));
}

TEST(Regions, DebrisThresholdScalesWithTheWorkspace) {
  const SyntheticField field = syntheticField({"+++++", "+++++", "--0+-", "+++++"});
  // 20 workspace cells: 2 % of them is 0.4 cell, 30 % is 6 cells.
  const RegionLabels small = labelRegions(field.grid, field.cells, DebrisThreshold{1, 0.02}, 1);
  const RegionLabels large = labelRegions(field.grid, field.cells, DebrisThreshold{1, 0.3}, 1);
  for (const Region& region : small.regions) EXPECT_FALSE(region.debris);
  for (const Region& region : large.regions) EXPECT_EQ(region.debris, region.voxels < 6);
}

TEST(BlockLayout, CellsAndNeighboursRoundTrip) {
  const RobotModel& model = test::deltaLike();
  // Three variables (blocks of 8^3, octree nodes), and four (blocks of 4^4) with a
  // periodic one.
  GridSpec xyz = test::referenceGrid(model, 0.03), turning = test::referenceGrid(model, 0.06);
  turning.variables.push_back(OutputVariable::Psi);
  turning.steps = {0.06, 0.06, 0.06, 0.5};
  for (const GridSpec& spec : {xyz, turning}) {
    const Grid grid(model, spec);
    const BlockLayout layout(grid);
    for (std::uint64_t index = 0; index < grid.cellCount(); index += 7) {
      const GridCell coords = grid.cell(index);
      std::uint64_t block = 0;
      int block_cell = 0;
      ASSERT_TRUE(layout.locate(coords, &block, &block_cell));
      EXPECT_EQ(layout.cellCoords(block, block_cell), coords);
      EXPECT_EQ(layout.gridIndex(block, block_cell), index);
      EXPECT_EQ(layout.gridIndex(block, 0) + layout.cellGridOffset(block_cell), index);
      // Blocks follow the lattice: a block's first cell has a lattice index divisible by
      // the block side.
      const GridCell first = layout.cellCoords(block, 0);
      for (int d = 0; d < grid.dims(); ++d) EXPECT_EQ((first[d] + grid.firstLatticeIndex(d)) % layout.side(), 0);
      // Neighbours agree with the grid's, wrap included.
      for (int d = 0; d < grid.dims(); ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t want = 0, next_block = 0;
          int next_cell = 0;
          if (!grid.neighbour(index, d, direction, &want)) continue;
          ASSERT_TRUE(layout.neighbour(block, block_cell, d, direction, &next_block, &next_cell));
          EXPECT_EQ(layout.gridIndex(next_block, next_cell), want);
        }
      }
    }
  }
}

// Labels a field of codes (keys: code 0 -> 1, 1 -> 2, 2 -> 3, others 0) over the block
// structure and checks the partition against a flood fill over the dense field; returns
// the number of components.
template <typename CodeAt>
std::size_t expectFloodFillPartition(const Grid& grid, const BlockLayout& layout, const CodeAt& codeAt) {
  CodeMap codes(layout.blockCount(), layout.cellsPerBlock());
  for (std::uint64_t b = 0; b < layout.blockCount(); ++b) {
    const CellCode first = codeAt(layout.cellCoords(b, 0));
    bool uniform = true;
    for (int c = 1; c < layout.cellsPerBlock() && uniform; ++c) uniform = codeAt(layout.cellCoords(b, c)) == first;
    if (uniform) {
      codes.setUniform(b, first);
      continue;
    }
    std::vector<CellCode> page(layout.cellsPerBlock());
    for (int c = 0; c < layout.cellsPerBlock(); ++c) page[c] = codeAt(layout.cellCoords(b, c));
    codes.addPage(b, page.data());
  }
  CodeTable<std::uint8_t> keys(3, 0);
  keys[0] = 1;
  keys[1] = 2;
  keys[2] = 3;
  LabelLayer layer;
  const std::vector<Component> components = labelComponents(layout, codes, keys, FaceCuts{}, -1, &layer);

  // Reference: a flood fill over the dense field.
  std::vector<int> reference(grid.cellCount(), -1);
  std::vector<std::uint64_t> sizes;
  for (std::uint64_t seed = 0; seed < grid.cellCount(); ++seed) {
    const int key = keys[codeAt(grid.cell(seed))];
    if (key == 0 || reference[seed] >= 0) continue;
    std::vector<std::uint64_t> queue = {seed};
    reference[seed] = static_cast<int>(sizes.size());
    for (std::size_t head = 0; head < queue.size(); ++head) {
      for (int d = 0; d < 3; ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t next = 0;
          if (!grid.neighbour(queue[head], d, direction, &next) || reference[next] >= 0) continue;
          if (keys[codeAt(grid.cell(next))] != key) continue;
          reference[next] = reference[seed];
          queue.push_back(next);
        }
      }
    }
    sizes.push_back(queue.size());
  }
  EXPECT_EQ(components.size(), sizes.size());
  // Same partition: labels map one to one, with the same sizes.
  std::map<int, std::int32_t> to_blocks;
  for (std::uint64_t index = 0; index < grid.cellCount(); ++index) {
    std::uint64_t block = 0;
    int block_cell = 0;
    layout.locate(grid.cell(index), &block, &block_cell);
    const std::int32_t label = layer.label(block, block_cell);
    if (reference[index] < 0) {
      EXPECT_EQ(label, kNoLabel);
      if (label != kNoLabel) break;
      continue;
    }
    const auto [entry, inserted] = to_blocks.emplace(reference[index], label);
    EXPECT_EQ(entry->second, label);
    if (entry->second != label) break;
    if (inserted && label >= 0 && static_cast<std::size_t>(label) < components.size()) {
      EXPECT_EQ(components[label].cells, sizes[reference[index]]);
    }
  }
  EXPECT_EQ(to_blocks.size(), sizes.size());
  return sizes.size();
}

// Code pages take two bytes a cell until a code needs more; then every page widens, and
// every cell, markers included, reads as it was written, before and after a state file.
TEST(CodeMap, PagesWidenWhenACodePassesTwoBytes) {
  constexpr int kCells = 8;
  CodeMap map(4, kCells);
  const std::vector<CellCode> narrow = {0, 1, kCodeOutside, kCodeDetached, kCodeBlocked, kCodeVoid, 65529, 2};
  map.addPage(0, narrow.data());
  map.setUniform(1, kCodeBlocked);
  map.setUniform(3, 123456);  // a block entry holds any code
  map.setMarker(0, 1, kCodeDetached);
  EXPECT_FALSE(map.widePages());
  std::vector<CellCode> expected = narrow;
  expected[1] = kCodeDetached;
  for (int c = 0; c < kCells; ++c) EXPECT_EQ(map.code(0, c), expected[c]) << c;
  const std::vector<CellCode> wide = {70000, kCodeOutside, 0, 65530, 65535, 65536, kCodeBlocked, 1};
  map.addPage(2, wide.data());
  EXPECT_TRUE(map.widePages());
  for (int c = 0; c < kCells; ++c) {
    EXPECT_EQ(map.code(0, c), expected[c]) << c;
    EXPECT_EQ(map.code(2, c), wide[c]) << c;
  }
  EXPECT_EQ(map.code(1, 5), kCodeBlocked);
  EXPECT_EQ(map.code(3, 0), 123456u);
  EXPECT_TRUE(map.holds(2, 65535) && map.holds(0, kCodeVoid) && !map.holds(0, 70000));
  std::stringstream bytes;
  StateWriter writer(bytes);
  map.describe(writer, 123457);
  CodeMap read(4, kCells);
  StateReader reader(bytes, "codes");
  read.describe(reader, 123457);
  EXPECT_TRUE(read.widePages());
  for (std::uint64_t b = 0; b < 4; ++b) {
    for (int c = 0; c < kCells; ++c) EXPECT_EQ(read.code(b, c), map.code(b, c)) << b << " " << c;
  }
  std::stringstream again;
  StateWriter rewriter(again);
  map.describe(rewriter, 123457);
  CodeMap short_of_codes(4, kCells);
  StateReader strict(again, "codes");
  EXPECT_THROW(short_of_codes.describe(strict, 70000), InputError);  // 70000 and 123456 unknown
}

// What the classification proves of a cell holds at random poses of its box: assembled
// wherever its proof says so, and each working mode it proves keeps the code's sign
// beyond the band. The certified volumes count these proofs; a certificate made for the
// modes not proven over a box holding it takes the others from that box, which this
// checks too (on the delta-like robot it fails, with 50,188 wrong signs, when a failed
// cube's certificate passes every mode to its parts as proven). Robots without limits:
// with limits a proof says more than assembly, which test_engine_reference covers.
struct ProofCheck {
  std::uint64_t cells = 0, poses = 0, unassembled = 0, wrong_sign = 0;
};
ProofCheck checkProofs(const RobotModel& model, const GridSpec& spec, int every) {
  const Grid grid(model, spec);
  const std::vector<WorkingMode> modes = analysedWorkingModes(model, {});
  bool orientation_fixed = true;
  for (OutputVariable variable : spec.variables) orientation_fixed = orientation_fixed && !isRotational(variable);
  const PoseClassifier classifier(model, modes, grid.spec().start, orientation_fixed);
  const MeasureCertificate certificate(model, modes, grid.spec().start);
  const WorkspaceCells cells = classifyWorkspace(grid, classifier, certificate, {});
  std::uniform_real_distribution<double> unit(-0.5, 0.5);
  std::vector<double> measures(modes.size());
  ProofCheck check;
  std::uint64_t candidates = 0;
  for (std::uint64_t b = 0; b < cells.layout.blockCount(); ++b) {
    if (cells.proven.noneProven(b)) continue;
    for (int c = 0; c < cells.layout.cellsPerBlock(); ++c) {
      const CellProof proof = cells.proven.proof(b, c);
      if (!codeInside(cells.codes.code(b, c)) || !proof.assembly || proof.modes == 0) continue;
      if (candidates++ % every != 0) continue;
      ++check.cells;
      const Pose centre = grid.pose(cells.layout.gridIndex(b, c));
      for (int draw = 0; draw < 2; ++draw) {
        Pose pose = centre;
        for (int d = 0; d < grid.dims(); ++d) grid.move(&pose, d, unit(test::rng()) * grid.step(d));
        ++check.poses;
        if (!classifier.classify(pose, measures.data())) {
          ++check.unassembled;
          continue;
        }
        for (std::size_t m = 0; m < modes.size(); ++m) {
          const int mode = static_cast<int>(m);
          check.wrong_sign += (proof.modes >> m & 1u) != 0 && bandedSign(measures[m], 0.0) != cells.sign(b, c, mode);
        }
      }
    }
  }
  std::printf("%s: %llu poses in %llu of %llu proven cells\n", model.name.c_str(),
              static_cast<unsigned long long>(check.poses), static_cast<unsigned long long>(check.cells),
              static_cast<unsigned long long>(candidates));
  return check;
}

TEST(Classification, WhatACellsProofSaysHoldsAtRandomPosesOfItsBox) {
  struct Case {
    const RobotModel* model;
    GridSpec spec;
    int every;
  };
  const RobotModel planar = loadRobotFile(test::sourcePath("test/robots/planar_3rrr.yaml"));
  GridSpec turning = test::referenceGrid(planar, 0.01);
  turning.variables.push_back(OutputVariable::Phi);
  turning.steps = {0.01, 0.01, 0.05};
  // The factorised path (delta-like robot), the perturbation path over a plane (5R), with
  // 64 working modes (hexapod) and over a turning platform (planar 3-RRR).
  const std::vector<Case> cases = {{&test::deltaLike(), test::referenceGrid(test::deltaLike(), 0.01), 5},
                                   {&test::fiveBar(), test::referenceGrid(test::fiveBar(), 0.002), 1},
                                   {&test::hexapod(), test::referenceGrid(test::hexapod(), 0.002), 1},
                                   {&planar, turning, 1}};
  for (const Case& one : cases) {
    SCOPED_TRACE(one.model->name);
    const ProofCheck check = checkProofs(*one.model, one.spec, one.every);
    EXPECT_GT(check.poses, 1000u);
    EXPECT_EQ(check.unassembled, 0u);
    EXPECT_EQ(check.wrong_sign, 0u);
  }
}

// A proof page keeps what was packed: the assembly flag and near_boundary (bits), the
// working modes (the mode set itself up to 8 modes), for every cell.
TEST(ProofMap, APageKeepsEveryCellsProof) {
  constexpr int kCells = 512, kModes = 8;
  ProofMap map(2, kCells, kModes);
  std::vector<std::uint8_t> packed(static_cast<std::size_t>(kCells) * map.width());
  std::vector<CellProof> proofs(kCells);
  std::mt19937 random(20261129);
  for (int c = 0; c < kCells; ++c) {
    CellProof& proof = proofs[c];
    proof.assembly = random() % 4 != 0;
    // Modes mean something only with the flag; 64 mode sets, well within the palette.
    proof.modes = proof.assembly ? random() % 64 : 0;
    proof.near_boundary = proof.assembly && random() % 3 == 0;
    map.pack(proof, &packed[static_cast<std::size_t>(c) * map.width()]);
  }
  map.addPage(1, packed.data());
  EXPECT_TRUE(map.noneProven(0));
  for (int c = 0; c < kCells; ++c) {
    const CellProof proof = map.proof(1, c);
    EXPECT_EQ(proof.assembly, proofs[c].assembly) << c;
    EXPECT_EQ(proof.modes, proofs[c].modes) << c;
    EXPECT_EQ(proof.near_boundary, proofs[c].near_boundary) << c;
  }
}

// Every mode set of 8 working modes, assembled, on pages stored in any order: none loses
// its modes. (A one-byte palette of whole proofs had 254 places for 255 sets: the set that
// came last lost its modes, and which one that was depended on the threads' order.) And
// beyond 8 modes, the two-byte palette keeps 600 distinct sets of 20 modes.
TEST(ProofMap, NoModeSetIsDroppedWhateverThePagesOrder) {
  constexpr int kCells = 512;
  for (const unsigned seed : {1u, 2u}) {
    ProofMap map(2, kCells, 8);
    std::vector<std::uint8_t> packed(static_cast<std::size_t>(kCells) * map.width());
    std::vector<int> order(kCells);
    for (int c = 0; c < kCells; ++c) order[c] = c % 256;
    std::shuffle(order.begin(), order.end(), std::mt19937(seed));
    for (int c = 0; c < kCells; ++c) {
      map.pack(CellProof{true, static_cast<std::uint64_t>(order[c]), false}, &packed[static_cast<std::size_t>(c) * map.width()]);
    }
    map.addPage(0, packed.data());
    for (int c = 0; c < kCells; ++c) {
      const CellProof proof = map.proof(0, c);
      EXPECT_TRUE(proof.assembly) << c;
      EXPECT_EQ(proof.modes, static_cast<std::uint64_t>(order[c])) << "seed " << seed << " cell " << c;
    }
  }
  ProofMap wide(2, kCells, 20);
  std::vector<std::uint8_t> packed(static_cast<std::size_t>(kCells) * wide.width());
  for (int page = 0; page < 2; ++page) {
    for (int c = 0; c < kCells; ++c) {
      const std::uint64_t modes = (static_cast<std::uint64_t>(page * 300 + c % 300) * 2654435761u) & 0xFFFFF;
      wide.pack(CellProof{true, modes, c % 7 == 0}, &packed[static_cast<std::size_t>(c) * wide.width()]);
    }
    wide.addPage(page, packed.data());
  }
  for (int page = 0; page < 2; ++page) {
    for (int c = 0; c < kCells; ++c) {
      const CellProof proof = wide.proof(page, c);
      EXPECT_EQ(proof.modes, (static_cast<std::uint64_t>(page * 300 + c % 300) * 2654435761u) & 0xFFFFF) << page << " " << c;
      EXPECT_EQ(proof.near_boundary, c % 7 == 0);
    }
  }
}

TEST(BlockComponents, MatchAFloodFillOnASyntheticField) {
  // Codes 0 and 1 in two slabs, 2 in a ball, 3 elsewhere in the first slab, and a wall of
  // outside cells: code 3 has key 0, so components follow the slabs and the ball, split by
  // the wall.
  const RobotModel& model = test::deltaLike();
  const Grid grid(model, test::referenceGrid(model, 0.05));
  const BlockLayout layout(grid);
  auto codeAt = [&](const GridCell& c) -> CellCode {
    if (!layout.inBox(c)) return kCodeVoid;
    if (c[1] == grid.size(1) / 2) return kCodeOutside;
    const double dx = c[0] - grid.size(0) / 2.0, dy = c[1] - grid.size(1) / 4.0, dz = c[2] - grid.size(2) / 2.0;
    if (dx * dx + dy * dy + dz * dz < 9.0) return 2;
    if (c[2] < 3) return 3;
    return c[0] < grid.size(0) / 3 ? 0 : 1;
  };
  EXPECT_EQ(expectFloodFillPartition(grid, layout, codeAt), 5u) << "two slabs on each side of the wall, and the ball";
}

// Codes drawn at random per cell (seeded), mostly repeating the previous cell's along the
// last variable: runs of every length, components that wind through rows and blocks.
TEST(BlockComponents, MatchAFloodFillOnARandomField) {
  const RobotModel& model = test::deltaLike();
  const Grid grid(model, test::referenceGrid(model, 0.05));
  const BlockLayout layout(grid);
  std::mt19937 random(29);
  std::vector<CellCode> field(grid.cellCount());
  for (std::uint64_t index = 0; index < field.size(); ++index) {
    const bool repeat = index > 0 && random() % 4 != 0 && grid.cell(index)[2] > 0;
    field[index] = repeat ? field[index - 1] : static_cast<CellCode>(random() % 4);
  }
  auto codeAt = [&](const GridCell& c) -> CellCode {
    if (!layout.inBox(c)) return kCodeVoid;
    return field[grid.index(c)];
  };
  EXPECT_GT(expectFloodFillPartition(grid, layout, codeAt), 100u);
}

// One key everywhere, the field uniform block by block: a wall of cut faces across the
// whole box splits it in two; the same wall with one face left open does not. Walls
// across the first variable and across the last (the rows a block's labelling runs along).
TEST(BlockComponents, CutFacesSplitWhatTheCodesJoin) {
  const RobotModel& model = test::deltaLike();
  const Grid grid(model, test::referenceGrid(model, 0.05));
  const BlockLayout layout(grid);
  const CodeTable<std::uint8_t> keys = [] {
    CodeTable<std::uint8_t> k(1, 0);
    k[0] = 1;
    return k;
  }();
  for (const int axis : {0, 2}) {
    const std::int64_t wall = grid.size(axis) / 2;  // faces between cells wall - 1 and wall, mid-block
    const int across[2] = {axis == 0 ? 1 : 0, axis == 2 ? 1 : 2};
    for (const bool open_one : {false, true}) {
      CodeMap codes(layout.blockCount(), layout.cellsPerBlock());
      FaceCuts cuts;
      const auto codeAt = [&](std::uint64_t b, int c) { return layout.inBox(layout.cellCoords(b, c)) ? CellCode{0} : kCodeVoid; };
      for (std::uint64_t index = 0; index < grid.cellCount(); ++index) {
        const GridCell cell = grid.cell(index);
        if (cell[axis] != wall - 1 || (open_one && cell[across[0]] == 1 && cell[across[1]] == 1)) continue;
        cuts.faces.push_back(FaceCut{index * kMaxGridDims + static_cast<std::uint64_t>(axis), false, 1});
        for (std::int64_t x : {wall - 1, wall}) {
          std::uint64_t block = 0;
          int block_cell = 0;
          GridCell side = cell;
          side[axis] = x;
          ASSERT_TRUE(layout.locate(side, &block, &block_cell));
          cuts.blocks.push_back(block);
        }
      }
      std::sort(cuts.faces.begin(), cuts.faces.end(), [](const FaceCut& a, const FaceCut& b) { return a.face < b.face; });
      std::sort(cuts.blocks.begin(), cuts.blocks.end());
      cuts.blocks.erase(std::unique(cuts.blocks.begin(), cuts.blocks.end()), cuts.blocks.end());
      for (std::uint64_t b = 0; b < layout.blockCount(); ++b) {
        bool uniform = true;
        for (int c = 1; c < layout.cellsPerBlock() && uniform; ++c) uniform = codeAt(b, c) == codeAt(b, 0);
        // The labelling reads a cut's blocks cell by cell.
        if (uniform && !std::binary_search(cuts.blocks.begin(), cuts.blocks.end(), b)) {
          codes.setUniform(b, codeAt(b, 0));
          continue;
        }
        std::vector<CellCode> page(layout.cellsPerBlock());
        for (int c = 0; c < layout.cellsPerBlock(); ++c) page[c] = codeAt(b, c);
        codes.addPage(b, page.data());
      }
      // Mode 0's components obey the cuts (bit 0); the workspace's (-1) see no gap.
      for (const int mode : {0, -1}) {
        LabelLayer layer;
        const std::vector<Component> components = labelComponents(layout, codes, keys, cuts, mode, &layer);
        const bool split = mode == 0 && !open_one;
        ASSERT_EQ(components.size(), split ? 2u : 1u) << "axis " << axis << ", one face open: " << open_one << ", mode " << mode;
        if (split) {
          const std::uint64_t below = static_cast<std::uint64_t>(wall) * grid.cellCount() / grid.size(axis);
          EXPECT_EQ(components[0].cells, below);
          EXPECT_EQ(components[0].cells + components[1].cells, grid.cellCount());
        }
      }
    }
  }
}

// A row's cuts as FaceCuts::forEachCut visits them (after one search) are those cut()
// finds face by face: random faces, gaps and working modes, rows of every length and
// place, the first and last indices included.
TEST(FaceCuts, ARowsCutsAreThoseFoundFaceByFace) {
  std::mt19937 random(30);
  FaceCuts cuts;
  const std::uint64_t cells = 2000;
  for (std::uint64_t index = 0; index < cells; ++index) {
    for (int d = 0; d < kMaxGridDims; ++d) {
      if (random() % 5 != 0) continue;
      cuts.faces.push_back(FaceCut{index * kMaxGridDims + static_cast<std::uint64_t>(d), random() % 3 == 0,
                                   static_cast<std::uint64_t>(random() % 16)});
    }
  }
  int visited = 0;
  for (int row = 0; row < 500; ++row) {
    const std::uint64_t first = random() % cells, count = 1 + random() % std::min<std::uint64_t>(16, cells - first);
    for (const int mode : {-1, 0, 2}) {
      std::set<std::pair<std::uint64_t, int>> seen;
      cuts.forEachCut(first, count, mode, [&](std::uint64_t i, int d) {
        ASSERT_LT(i, count);
        EXPECT_TRUE(seen.emplace(i, d).second) << "visited twice: " << first + i << " along " << d;
      });
      for (std::uint64_t i = 0; i < count; ++i) {
        for (int d = 0; d < kMaxGridDims; ++d) {
          EXPECT_EQ(seen.count({i, d}) == 1, cuts.cut(first + i, d, mode)) << first + i << " along " << d << " mode " << mode;
        }
      }
      visited += static_cast<int>(seen.size());
    }
  }
  EXPECT_GT(visited, 1000);
}

// Every face the analysis cuts is witnessed again here, from the robot's IKP and measure:
// a gap, where a pose of the segment between the two centres cannot be assembled (sampled
// at 8193 poses), or a working mode whose sign at the face's centre is not its sign at
// both cells. The Clavel delta at 10 mm has both kinds.
TEST(WorkspaceAnalysis, EveryThinLayerCutIsWitnessed) {
  const RobotModel model = loadRobotFile(test::sourcePath("config/clavel_delta.yaml"));
  const WorkspaceAnalysis analysis = analyseWorkspace(model, test::referenceGrid(model, 0.01), AnalysisOptions{});
  const Grid& grid = analysis.grid();
  const PoseClassifier classifier(model, analysis.modes(), grid.spec().start, false);
  std::vector<double> measures(analysis.modes().size());
  int gaps = 0, layers = 0;
  for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
    for (int d = 0; d < grid.dims(); ++d) {
      std::uint64_t next = 0;
      if (!analysis.inside(cell) || !grid.neighbour(cell, d, 1, &next)) continue;
      const Pose centre = grid.pose(cell);
      const auto along = [&](double fraction) {
        Pose pose = centre;
        pose.setValue(grid.variable(d), centre.value(grid.variable(d)) + fraction * grid.step(d));
        return pose;
      };
      if (analysis.faceCut(cell, d, -1)) {
        ++gaps;
        bool leaves = false;
        for (int k = 1; k < 8192 && !leaves; ++k) leaves = !solveIkp(model, along(k / 8192.0)).assembled;
        EXPECT_TRUE(leaves) << "gap between " << vectorText(centre.position) << " and its +" << d << " neighbour";
        continue;
      }
      for (int m = 0; m < static_cast<int>(analysis.modes().size()); ++m) {
        if (!analysis.faceCut(cell, d, m)) continue;
        ++layers;
        ASSERT_TRUE(classifier.classify(along(0.5), measures.data()));
        const std::int32_t region = analysis.label(cell, m);
        ASSERT_GE(region, 0);
        EXPECT_NE(bandedSign(measures[m], 0.0), analysis.regions()[region].sign)
            << "layer of mode " << analysis.modes()[m].name << " at " << vectorText(along(0.5).position);
      }
    }
  }
  std::printf("Clavel delta at 10 mm: %d gap faces, %d (face, working mode) sign layers\n", gaps, layers);
  EXPECT_GT(gaps, 0);
  EXPECT_GT(layers, 0);
}

TEST(Transitions, TheBracketLandsOnTheReachBoundary) {
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
    const Pose point = findReachBoundary(chain, chain.platformNode(), inside, outside, step, 1e-9);
    EXPECT_NEAR((point.position - axis_point).norm(), radius, 1e-9);
    EXPECT_LE((point.position - axis_point).norm(), radius);  // on the assembled side
  }
}

TEST(Transitions, FiveBarPointsAreExactlyOnAnAnnulusAndJoinEqualConfigurations) {
  const RobotModel& model = test::fiveBar();
  const WorkspaceAnalysis analysis = analyseWorkspace(model, test::referenceGrid(model, 0.005), {});
  const TransitionGraph& graph = analysis.transitions();
  ASSERT_FALSE(graph.points.empty());
  const Eigen::Vector3d bases[2] = {{-0.1, 0, 0}, {0.1, 0, 0}};
  for (const TransitionPoint& point : graph.points) {
    const double r = (point.position - bases[point.chain]).norm();
    EXPECT_LT(std::min(std::abs(r - 0.45), std::abs(r - 0.05)), 1e-9) << r;
  }
  // At a transition point the two working modes are one configuration: same measure, up
  // to the bisection's tolerance delta = 1e-9 m inside the boundary, where the branches
  // still differ by about sqrt(2 R delta) = 2e-5 m on 0.25 m rods (measure ~1e-4).
  const PoseClassifier classifier(model, analysis.modes(), model.reference.pose, true);
  std::vector<double> measures(analysis.modes().size());
  for (const Transition& transition : graph.transitions) {
    const int from = analysis.regions()[transition.from_region].mode;
    const int to = analysis.regions()[transition.to_region].mode;
    for (std::uint32_t p : transition.points) {
      ASSERT_TRUE(classifier.classify(graph.pose(p), measures.data()));
      EXPECT_NEAR(measures[from], measures[to], 1e-3);
      EXPECT_EQ(bandedSign(measures[from], analysis.settings().margin), transition.sign);
    }
  }
}

TEST(Transitions, DeltaLikeJoinsModesThatDifferInOneCouple) {
  const WorkspaceAnalysis analysis = analyseWorkspace(test::deltaLike(), test::referenceGrid(test::deltaLike(), 0.02), {});
  ASSERT_FALSE(analysis.transitions().transitions.empty());
  for (const Transition& transition : analysis.transitions().transitions) {
    const Region &from_region = analysis.regions()[transition.from_region], &to_region = analysis.regions()[transition.to_region];
    const std::string& from = analysis.modes()[from_region.mode].name;
    const std::string& to = analysis.modes()[to_region.mode].name;
    int differences = 0;
    for (std::size_t k = 0; k < from.size(); ++k) differences += from[k] != to[k];
    EXPECT_EQ(differences, 1);
    EXPECT_NE(from[transition.input], to[transition.input]);
    EXPECT_EQ(from_region.sign, transition.sign);
    EXPECT_EQ(to_region.sign, transition.sign);
  }
}

void expectSameAnalysis(const WorkspaceAnalysis& a, const WorkspaceAnalysis& b) {
  ASSERT_EQ(a.grid().cellCount(), b.grid().cellCount());
  ASSERT_EQ(a.modes().size(), b.modes().size());
  std::uint64_t differing = 0;
  for (std::uint64_t cell = 0; cell < a.grid().cellCount(); ++cell) {
    differing += a.inside(cell) != b.inside(cell);
    for (std::size_t m = 0; m < a.modes().size(); ++m) differing += a.label(cell, int(m)) != b.label(cell, int(m));
  }
  EXPECT_EQ(differing, 0u);
  const TransitionGraph &ga = a.transitions(), &gb = b.transitions();
  ASSERT_EQ(ga.points.size(), gb.points.size());
  for (std::size_t p = 0; p < ga.points.size(); ++p) {
    EXPECT_EQ(ga.pose(p).position, gb.pose(p).position);
    EXPECT_EQ(ga.pose(p).euler_zyz, gb.pose(p).euler_zyz);
    EXPECT_EQ(ga.points[p].cell, gb.points[p].cell);
  }
  ASSERT_EQ(ga.transitions.size(), gb.transitions.size());
  for (std::size_t t = 0; t < ga.transitions.size(); ++t) EXPECT_EQ(ga.transitions[t].points, gb.transitions[t].points);
  EXPECT_EQ(ga.component, gb.component);
  EXPECT_EQ(a.singularityCounts().dkp_entries, b.singularityCounts().dkp_entries);
  EXPECT_EQ(a.singularityCounts().ikp_entries, b.singularityCounts().ikp_entries);
  for (int am = 0; am < 2; ++am) {
    EXPECT_EQ(a.assemblyModes()[am].maximal_voxels, b.assemblyModes()[am].maximal_voxels);
    EXPECT_EQ(a.assemblyModes()[am].reachable_voxels, b.assemblyModes()[am].reachable_voxels);
    EXPECT_EQ(a.assemblyModes()[am].traditional_region, b.assemblyModes()[am].traditional_region);
  }
}

TEST(WorkspaceAnalysis, ResultsDoNotDependOnTheThreadCount) {
  for (const RobotModel* model : {&test::deltaLike(), &test::fiveBar()}) {
    AnalysisOptions one, three;
    one.threads = 1;
    three.threads = 3;
    const GridSpec spec = test::referenceGrid(*model, model == &test::deltaLike() ? 0.02 : 0.005);
    expectSameAnalysis(analyseWorkspace(*model, spec, one), analyseWorkspace(*model, spec, three));
  }
}

// parallelForEach hands out items one at a time as threads come free: every item once,
// whatever the thread count, with items of very uneven cost; an item's exception reaches
// the caller.
TEST(Parallel, EachItemIsVisitedOnceAndAnErrorReachesTheCaller) {
  for (int threads : {1, 2, 3, 5}) {
    for (std::size_t count : {0, 1, 2, 7, 300}) {
      std::vector<std::atomic<int>> visits(count);
      std::atomic<int> calls{0};
      parallelForEach(count, threads, [&](std::size_t begin, std::size_t end) {
        ++calls;
        EXPECT_EQ(end, begin + 1);
        // The first items cost far more than the others, as chunks of a surface's blocks do.
        if (begin < 3) std::this_thread::sleep_for(std::chrono::milliseconds(5));
        for (std::size_t i = begin; i < end; ++i) ++visits[i];
      });
      EXPECT_EQ(calls, static_cast<int>(count)) << threads << " threads, " << count << " items";
      for (std::size_t i = 0; i < count; ++i) EXPECT_EQ(visits[i], 1) << "item " << i;
    }
    EXPECT_THROW(parallelForEach(50, threads, [](std::size_t begin, std::size_t) {
                   if (begin == 17) throw std::runtime_error("item 17");
                 }),
                 std::runtime_error);
  }
}

TEST(WorkspaceState, ReadsBackTheSameAnalysis) {
  for (const RobotModel* model : {&test::deltaLike(), &test::fiveBar()}) {
    AnalysisOptions options;
    options.margin = model == &test::deltaLike() ? 0.0 : 1e-3;  // the file carries the margin
    const WorkspaceAnalysis analysis =
        analyseWorkspace(*model, test::referenceGrid(*model, model == &test::deltaLike() ? 0.02 : 0.01), options);
    std::stringstream bytes;
    writeWorkspaceState(analysis, bytes);
    const WorkspaceAnalysis back = readWorkspaceState(*model, bytes, "state");
    expectSameAnalysis(back, analysis);
    EXPECT_EQ(back.settings().margin, options.margin);
    EXPECT_EQ(back.startMode(), analysis.startMode());
    EXPECT_EQ(back.voxelCount(), analysis.voxelCount());
    EXPECT_EQ(back.posesEvaluated(), analysis.posesEvaluated());
    EXPECT_EQ(back.memoryBytes(), analysis.memoryBytes());
  }
}

std::string stateBytes(const WorkspaceAnalysis& analysis) {
  std::stringstream bytes;
  writeWorkspaceState(analysis, bytes);
  return bytes.str();
}

TEST(WorkspaceState, DamagedBytesAreAClearErrorNotACrash) {
  const RobotModel& model = test::fiveBar();
  const WorkspaceAnalysis analysis = analyseWorkspace(model, test::referenceGrid(model, 0.02), {});
  const std::string good = stateBytes(analysis);
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
  AnalysisData& data = const_cast<AnalysisData&>(AnalysisAccess::data(analysis));
  // A grid of one orientation keeps it once for its transition points: a point stored at
  // another one is damage.
  ASSERT_FALSE(data.transitions.points.empty());
  ASSERT_TRUE(data.transitions.orientations.empty());
  const Eigen::Vector3d orientation = data.transitions.orientation;
  data.transitions.orientation.x() += 0.1;
  EXPECT_NE(message_of(stateBytes(analysis)).find("a transition point is not at the grid's orientation"),
            std::string::npos);
  data.transitions.orientation = orientation;
  EXPECT_EQ(stateBytes(analysis), good);
  // Every pattern's signs flipped: the labels the codes give no longer have the stored
  // regions' signs.
  for (SignPattern& pattern : data.cells.patterns.patterns) {
    for (std::uint64_t& word : pattern) word = ((word & 0x5555555555555555ull) << 1) | ((word >> 1) & 0x5555555555555555ull);
  }
  EXPECT_NE(message_of(stateBytes(analysis)).find("region table does not match"), std::string::npos);
}

// fuzz_workspace_state's find once its seeds were of the current format: a thin layer's
// `gap` byte of 105 was loaded as a bool (undefined) and labelled regions with it.
TEST(WorkspaceState, AFlagByteThatIsNeitherZeroNorOneIsRefused) {
  std::ifstream file(test::sourcePath("test/fuzz/corpus/workspace_state/regression-flag-not-bool.bin"), std::ios::binary);
  std::stringstream bytes;
  bytes << file.rdbuf();
  ASSERT_GT(bytes.str().size(), 1000u);
  try {
    readWorkspaceState(test::deltaLike(), bytes, "regression.bin", 1);
    ADD_FAILURE() << "read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("a flag is neither 0 nor 1"), std::string::npos) << error.what();
  }
}

TEST(WorkspaceAnalysis, WorkingModeFilterAnalysesOnlyThoseModes) {
  const RobotModel& model = test::deltaLike();
  AnalysisOptions options;
  options.working_modes = {"npn", "ppn", "nnn"};
  const WorkspaceAnalysis analysis = analyseWorkspace(model, test::referenceGrid(model, 0.02), options);
  ASSERT_EQ(analysis.modes().size(), 3u);
  EXPECT_EQ(analysis.modes()[0].name, "ppn");  // canonical order
  EXPECT_EQ(analysis.modes()[analysis.startMode()].name, "npn");
  for (const Transition& transition : analysis.transitions().transitions) {
    // Only npn - ppn differ in one couple (nnn differs from npn in KC2, from ppn in two).
    const std::string& from = analysis.modes()[analysis.regions()[transition.from_region].mode].name;
    const std::string& to = analysis.modes()[analysis.regions()[transition.to_region].mode].name;
    EXPECT_TRUE((from == "ppn" && to == "npn") || (from == "npn" && to == "nnn")) << from << " " << to;
  }
  options.working_modes = {"ppp"};  // without the start mode
  EXPECT_THROW(analyseWorkspace(model, test::referenceGrid(model, 0.02), options), InputError);
  options.working_modes = {"pqp"};
  EXPECT_THROW(analyseWorkspace(model, test::referenceGrid(model, 0.02), options), InputError);
}

TEST(WorkspaceAnalysis, AssemblyModeFiguresAreConsistent) {
  const WorkspaceAnalysis analysis = analyseWorkspace(test::deltaLike(), test::referenceGrid(test::deltaLike(), 0.02), {});
  const std::vector<Region>& regions = analysis.regions();
  for (const AssemblyModeSummary& am : analysis.assemblyModes()) {
    ASSERT_GE(am.traditional_region, 0);
    // traditional <= reachable <= maximal <= workspace
    EXPECT_LE(regions[am.traditional_region].voxels, am.reachable_voxels);
    EXPECT_LE(am.reachable_voxels, am.maximal_voxels);
    EXPECT_LE(am.maximal_voxels, analysis.voxelCount());
    EXPECT_EQ(regions[am.traditional_region].sign, am.sign);
  }
  // The robot starts in its reference working mode, whose region holds the start cell.
  std::uint64_t start = 0;
  ASSERT_TRUE(analysis.grid().cellOf(analysis.grid().spec().start, &start));
  const int start_region = analysis.label(start, analysis.startMode());
  const int start_sign = regions[start_region].sign;
  EXPECT_EQ(analysis.assemblyModes()[start_sign > 0 ? 0 : 1].traditional_region, start_region);
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

// Byte counts in messages: three significant digits in the largest unit under 1024, never
// in exponent form ("about 1e+03 MiB" was printed for 1000 MiB).
TEST(ByteText, ThreeDigitsOfTheLargestUnitWithoutAnExponent) {
  EXPECT_EQ(byteText(512), "512 bytes");
  EXPECT_EQ(byteText(1.5 * (1 << 20)), "1.5 MiB");
  EXPECT_EQ(byteText(123.4 * 1024), "123 KiB");
  EXPECT_EQ(byteText(999.6 * (1 << 20)), "1000 MiB");
  EXPECT_EQ(byteText(1023.0 * (1 << 30)), "1023 GiB");
  EXPECT_EQ(byteText(2.43 * (1 << 30)), "2.43 GiB");
}

TEST(WorkspaceAnalysis, RefusesARequestOverTheMemoryBudgetBeforeAllocating) {
  AnalysisOptions options;
  options.memory_budget = 1'000'000;
  try {
    analyseWorkspace(test::deltaLike(), test::referenceGrid(test::deltaLike(), 0.01), options);
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    // The per-block part alone (its fixed 8 MiB for the process) is over 977 KiB: the
    // coarse pass is not run, and the figure is a lower bound.
    const std::string message = error.what();
    EXPECT_NE(message.find("would need at least"), std::string::npos) << message;
    EXPECT_NE(message.find("memory budget of 977 KiB"), std::string::npos) << message;
  }
  // Just under the whole estimate, the coarse pass runs and the figure is the estimate.
  options.memory_budget = 0;
  const std::uint64_t whole = estimateAnalysisBytes(test::deltaLike(), test::referenceGrid(test::deltaLike(), 0.01), options);
  options.memory_budget = whole - 1;
  try {
    analyseWorkspace(test::deltaLike(), test::referenceGrid(test::deltaLike(), 0.01), options);
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("would need about " + byteText(static_cast<double>(whole)) + " of memory"), std::string::npos)
        << message;
  }
  // The estimate grows with the refinement (test_memory_estimate sets it beside measured
  // peaks).
  options.memory_budget = 0;
  const RobotModel& model = test::deltaLike();
  EXPECT_GT(estimateAnalysisBytes(model, test::referenceGrid(model, 0.01), options),
            estimateAnalysisBytes(model, test::referenceGrid(model, 0.02), options));
}

TEST(Grid, DefaultBoxLeavesEveryWorkspaceCellItsNeighbours) {
  // The reach box is tight; unless the grid has a cell of margin, cells on its edge would
  // have untested neighbours and their IKP faces, and transitions, would be lost.
  for (const RobotModel* model : {&test::deltaLike(), &test::fiveBar()}) {
    const WorkspaceAnalysis analysis = analyseWorkspace(*model, test::referenceGrid(*model, 0.02), {});
    for (std::uint64_t cell : workspaceCells(analysis)) {
      for (int d = 0; d < analysis.grid().dims(); ++d) {
        for (int direction : {-1, 1}) {
          std::uint64_t neighbour = 0;
          EXPECT_TRUE(analysis.grid().neighbour(cell, d, direction, &neighbour)) << model->name;
        }
      }
    }
  }
}

TEST(Grid, UserBoundsHoldTheCellCentres) {
  GridSpec spec = test::referenceGrid(test::deltaLike(), 0.02);
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
  const Grid grid(test::deltaLike(), test::referenceGrid(test::deltaLike(), 0.02));
  for (int d = 0; d < 3; ++d) {
    for (std::int64_t i : {std::int64_t{0}, grid.size(d) / 2, grid.size(d) - 1}) {
      // OctoMap cells of resolution r have centres at (k + 1/2) r.
      const double k = grid.centre(d, i) / 0.02 - 0.5;
      EXPECT_NEAR(k, std::round(k), 1e-9);
    }
  }
}

TEST(Grid, AFullTurnOfPhiOrPsiIsPeriodic) {
  const RobotModel& model = test::deltaLike();
  GridSpec spec = test::referenceGrid(model, 0.05);
  spec.variables = {OutputVariable::X, OutputVariable::Phi, OutputVariable::Theta};
  spec.steps = {0.05, 0.3, 0.3};
  spec.start.euler_zyz = Eigen::Vector3d(0.2, 0.1, 0.0);
  const Grid grid(model, spec);
  // phi: start +/- pi by default, a full turn; theta the same span, but not a turn of the
  // platform about one axis.
  ASSERT_TRUE(grid.periodic(1));
  EXPECT_FALSE(grid.periodic(2));
  EXPECT_FALSE(grid.periodic(0));
  // 2 pi / 0.3 = 20.94: 21 cells of 2 pi / 21, one of them centred on the start.
  EXPECT_EQ(grid.size(1), 21);
  EXPECT_NEAR(grid.step(1), 2 * M_PI / 21, 1e-15);
  std::uint64_t start = 0;
  ASSERT_TRUE(grid.cellOf(spec.start, &start));
  EXPECT_NEAR(grid.pose(start).euler_zyz[0], 0.2, 1e-12);
  // The last cell's neighbour is the first, and a pose a turn away is in the same cell.
  const std::uint64_t last = grid.index({0, grid.size(1) - 1, 0});
  std::uint64_t next = 0;
  ASSERT_TRUE(grid.neighbour(last, 1, 1, &next));
  EXPECT_EQ(next, grid.index({0, 0, 0}));
  ASSERT_TRUE(grid.neighbour(grid.index({0, 0, 0}), 1, -1, &next));
  EXPECT_EQ(next, last);
  Pose turned = grid.pose(start);
  turned.euler_zyz[0] += 6 * M_PI;
  std::uint64_t again = 0;
  ASSERT_TRUE(grid.cellOf(turned, &again));
  EXPECT_EQ(again, start);
  // Neighbouring centres are one step apart all the way round, across the seam too.
  const double seam = grid.centre(1, 0) + 2 * M_PI - grid.centre(1, grid.size(1) - 1);
  EXPECT_NEAR(seam, grid.step(1), 1e-12);
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
  GridSpec spec = test::referenceGrid(model, 0.01);
  spec.steps = {-0.01};
  EXPECT_NE(message_of(spec).find("step of x"), std::string::npos);
  spec.steps = {NAN};
  EXPECT_NE(message_of(spec).find("finite"), std::string::npos);
  spec = test::referenceGrid(model, 0.01);
  spec.bounds = {{0.5, 0.0}, {-1, 1}, {-1, 1}};
  EXPECT_NE(message_of(spec).find("lower < upper"), std::string::npos);
  spec.bounds = {{0.3, 0.4}, {-1, 1}, {-1, 1}};
  EXPECT_NE(message_of(spec).find("outside the bounds"), std::string::npos);
  spec = test::referenceGrid(model, 0.01);
  spec.variables = {OutputVariable::X, OutputVariable::X};
  EXPECT_NE(message_of(spec).find("twice"), std::string::npos);
  // Steps so fine that cell indices overflow (found by fuzz_workspace_request): refused,
  // not converted (undefined behaviour).
  for (double tiny : {1e-300, 4.9e-324}) {
    spec = test::referenceGrid(model, tiny);
    EXPECT_NE(message_of(spec).find("too fine for its bounds"), std::string::npos) << message_of(spec);
  }
  // Bounds so far from the origin that lattice indices overflow (found by
  // fuzz_workspace_state): refused, not converted.
  spec = test::referenceGrid(model, 0.001);
  spec.start.position.x() = 1e16;
  spec.bounds = {{1e16 - 4, 1e16 + 4}, {-1, 1}, {-1, 1}};  // index 1e19 at 1 mm
  EXPECT_NE(message_of(spec).find("too far from the origin"), std::string::npos) << message_of(spec);
  // A box whose cells no index can number.
  spec = test::referenceGrid(model, 1e-6);
  EXPECT_NE(message_of(spec).find("more than a grid can index"), std::string::npos) << message_of(spec);
  spec = test::referenceGrid(model, 0.01);
  spec.variables = {OutputVariable::X, OutputVariable::Psi};
  spec.steps = {0.01, 2.5};
  EXPECT_NE(message_of(spec).find("under pi/2 for a grid over a full turn"), std::string::npos) << message_of(spec);
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
  GridSpec spec = test::referenceGrid(model, 0.02);
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

// Cancellation (issue 17): asked to stop in any stage, the analysis throws Cancelled from
// that stage; never asked, it finishes.
TEST(WorkspaceAnalysis, CancelledInAnyStageStopsThere) {
  const GridSpec spec = test::referenceGrid(test::deltaLike(), 0.02);
  const std::vector<std::string> stages = {"classification", "regions", "singularities", "transitions", "summary"};
  for (int target = 0; target < static_cast<int>(stages.size()); ++target) {
    // The stage the progress last named (-1 before any): written by the progress calls,
    // read by the worker threads' cancellation checks.
    std::atomic<int> current{-1};
    int last_seen = -1;
    AnalysisOptions options;
    options.threads = 2;
    options.progress = [&](const AnalysisProgress& progress) {
      const int index = static_cast<int>(std::find(stages.begin(), stages.end(), progress.stage) - stages.begin());
      current = index;
      last_seen = std::max(last_seen, index);
    };
    options.cancelled = [&, target] { return current.load() == target; };
    EXPECT_THROW(analyseWorkspace(test::deltaLike(), spec, options), Cancelled) << stages[target];
    EXPECT_EQ(last_seen, target) << "went on past " << stages[target];
  }
  AnalysisOptions never;
  never.cancelled = [] { return false; };
  EXPECT_GT(analyseWorkspace(test::deltaLike(), spec, never).voxelCount(), 0u);
}

// Asked often inside every stage (issue 28: Ctrl-C at 1 mm took 10 s in the regions stage,
// which asked only between rounds of working modes, and the singularities stage not at all
// inside its scans): at 5 mm every stage asks dozens of times, the more the finer the grid.
TEST(WorkspaceAnalysis, CancellationIsAskedThroughoutEveryStage) {
  const std::vector<std::string> stages = {"classification", "regions", "singularities", "transitions", "summary"};
  std::atomic<int> current{0};
  std::vector<std::atomic<int>> asked(stages.size());
  AnalysisOptions options;
  options.threads = 2;
  options.progress = [&](const AnalysisProgress& progress) {
    current = static_cast<int>(std::find(stages.begin(), stages.end(), progress.stage) - stages.begin());
  };
  options.cancelled = [&] {
    ++asked[current.load()];
    return false;
  };
  analyseWorkspace(test::deltaLike(), test::referenceGrid(test::deltaLike(), 0.005), options);
  for (std::size_t s = 0; s < stages.size(); ++s) EXPECT_GE(asked[s].load(), 20) << stages[s];
}

}  // namespace
}  // namespace maximal_workspace
