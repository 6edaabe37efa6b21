#pragma once
// The boundary of a set of cells of a grid over x y z as a closed triangle mesh in metres,
// for CAD and viewers: every edge shared by two triangles, counter-clockwise seen from
// outside (normals point out). Cells are read in blocks of 8 x 8 x 8 aligned on lattice
// indices that are multiples of 8: a WorkspaceAnalysis's blocks over x y z
// (block_layout.h), so a block wholly inside is taken at once.

#include <array>
#include <bitset>
#include <cstdint>
#include <functional>
#include <vector>

#include "maximal_workspace/regions/orientation_coverage.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace {

constexpr int kCellBlockSide = 8;

struct CellBlock {
  std::array<std::int64_t, 3> origin{};  // lattice indices of its first cell, multiples of 8
  bool full = false;                     // every cell is in the set; `cells` is not read
  // Cell (a, b, c) of the block at a * 64 + b * 8 + c: z fastest, as in a BlockLayout.
  std::bitset<kCellBlockSide * kCellBlockSide * kCellBlockSide> cells;
};

// Lattice cell (i, j, k) is the box [i, i + 1] step_x x [j, j + 1] step_y x [k, k + 1] step_z
// (centres at (i + 1/2) step, as on a Grid).
struct CellSet {
  std::array<double, 3> steps{};  // m
  std::array<double, 3> origin{};  // m: where lattice index 0 begins (a display lattice's box corner)
  std::uint64_t blocks = 0;
  // Fills `block` for index b in [0, blocks); false when none of its cells is in the set.
  // Called from several threads at once.
  std::function<bool(std::uint64_t b, CellBlock* block)> read;
};

// Sets of an analysis over x y z (others: InputError). The set keeps a copy of the
// analysis (cheap, shared).
CellSet workspaceCells(const WorkspaceAnalysis& analysis);
// The maximal operational workspace of assembly mode `sign` (inMaximalWorkspace).
CellSet maximalWorkspaceCells(const WorkspaceAnalysis& analysis, std::int8_t sign);
// One region (label(block, cell, its mode) == region).
CellSet regionCells(const WorkspaceAnalysis& analysis, std::int32_t region);
// Over an orientation set (orientation_coverage.h): the positions reaching every
// orientation of the set, for assembly mode index `assembly` (0: +, 1: -), in the maximal
// workspace reachable from the start, or in the traditional one.
CellSet totalOrientationCells(const Grid& grid, const OrientationCoverage& coverage, int assembly, bool traditional);

struct SurfaceMesh {
  std::vector<std::array<float, 3>> vertices;           // m
  std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise from outside
  std::vector<std::array<std::uint8_t, 3>> colours;     // RGB per vertex, or empty
  std::vector<float> quality;  // a value per vertex (the conditioning index), or empty
};

struct MeshOptions {
  // Iterations of Taubin smoothing of the vertices (volume-preserving; 0: the cells'
  // boundary with its corners cut, which encloses their volume).
  int smoothing = 0;
  // At most this many triangles (0: no limit): flat parts are merged into larger triangles
  // until the mesh fits. InputError when even the coarsest mesh does not.
  std::uint64_t max_triangles = 0;
};

// The boundary of the set's cells (empty for an empty set).
SurfaceMesh surfaceMesh(const CellSet& cells, const MeshOptions& options = {});

// Per vertex, the unit outward normal: the sum of its triangles' area-weighted normals.
std::vector<std::array<float, 3>> vertexNormals(const SurfaceMesh& mesh);

// Volume enclosed by a closed, outward-oriented mesh (m^3), by the divergence theorem.
double enclosedVolume(const SurfaceMesh& mesh);

}  // namespace maximal_workspace
