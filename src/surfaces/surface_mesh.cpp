#include "maximal_workspace/surfaces/surface_mesh.h"

#include <algorithm>
#include <memory>
#include <mutex>

#include <Eigen/Geometry>
#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>

#include "maximal_workspace/model/input_error.h"
#include "workspace/parallel.h"

namespace maximal_workspace {

namespace {

constexpr int kCellsPerBlock = kCellBlockSide * kCellBlockSide * kCellBlockSide;

// Which of a block's first `cells` cells are in the set: all of them, or only the first
// for a uniform block, whose first cell answers for all.
using BlockMembers = std::function<void(std::uint64_t block, int cells, bool* members)>;

void requireSpatial(const Grid& grid) {
  if (grid.dims() != 3 || !grid.isSpatial()) throw InputError("surface mesh: the grid must be over x y z");
}

// The cells of an analysis over x y z that `members` says are in the set, block by block.
CellSet analysisCells(const WorkspaceAnalysis& analysis, BlockMembers members) {
  const Grid& grid = analysis.grid();
  requireSpatial(grid);
  CellSet set;
  for (int d = 0; d < 3; ++d) set.steps[d] = grid.step(d);
  set.blocks = analysis.blocks().blockCount();
  set.read = [analysis, members = std::move(members)](std::uint64_t b, CellBlock* block) {
    const BlockLayout& layout = analysis.blocks();
    const GridCell first = layout.cellCoords(b, 0);
    for (int d = 0; d < 3; ++d) block->origin[d] = first[d] + analysis.grid().firstLatticeIndex(d);
    // Blocks on the box's edge hold cells beyond it, which are never in the set.
    const bool in_box = layout.inBox(first) && layout.inBox(layout.cellCoords(b, kCellsPerBlock - 1));
    bool in[kCellsPerBlock];
    if (in_box && analysis.blockUniform(b)) {
      members(b, 1, in);
      block->full = in[0];
      return in[0];
    }
    members(b, kCellsPerBlock, in);
    block->full = false;
    block->cells.reset();
    for (int c = 0; c < kCellsPerBlock; ++c) {
      if (in[c] && (in_box || layout.inBox(layout.cellCoords(b, c)))) block->cells.set(c);
    }
    return block->cells.any();
  };
  return set;
}

// In a region of one of `modes` that `wanted` accepts, for each of the block's first
// `cells` cells.
template <class Wanted>
void labelledMembers(const WorkspaceAnalysis& analysis, std::uint64_t block, int cells, const std::vector<int>& modes,
                     const Wanted& wanted, bool* members) {
  std::fill_n(members, cells, false);
  std::int32_t labels[kCellsPerBlock];
  for (int mode : modes) {
    if (cells == 1) {
      labels[0] = analysis.label(block, 0, mode);
    } else {
      analysis.blockLabels(block, mode, labels);
    }
    for (int c = 0; c < cells; ++c) members[c] = members[c] || (labels[c] >= 0 && wanted(labels[c]));
  }
}

std::int64_t floorDivide(std::int64_t value, std::int64_t by) { return value / by - (value % by < 0 ? 1 : 0); }

using BoolGridPtr = openvdb::BoolGrid::Ptr;

// The set as an OpenVDB grid (index space: voxel (i, j, k) is lattice cell (i, j, k)), true
// inside. A full block is one tile, a mixed one a leaf: both are 8^3 voxels. The blocks
// are read in parallel; the tree is the same whatever the order they are inserted in.
BoolGridPtr cellGrid(const CellSet& cells) {
  std::vector<CellBlock> read;
  std::mutex mutex;
  parallelFor(cells.blocks, 0, [&](std::size_t begin, std::size_t end) {
    std::vector<CellBlock> found;
    CellBlock block;
    for (std::size_t b = begin; b < end; ++b) {
      if (cells.read(b, &block)) found.push_back(block);
    }
    const std::lock_guard<std::mutex> lock(mutex);
    read.insert(read.end(), found.begin(), found.end());
  }, 4096);
  BoolGridPtr grid = openvdb::BoolGrid::create(false);
  openvdb::BoolTree& tree = grid->tree();
  for (const CellBlock& block : read) {
    const openvdb::Coord origin(static_cast<openvdb::Int32>(block.origin[0]), static_cast<openvdb::Int32>(block.origin[1]),
                                static_cast<openvdb::Int32>(block.origin[2]));
    if (block.full) {
      tree.addTile(1, origin, true, true);
      continue;
    }
    // OpenVDB's leaf offsets are x * 64 + y * 8 + z, the block's own order.
    auto* leaf = new openvdb::BoolTree::LeafNodeType(origin, false);
    for (int c = 0; c < kCellsPerBlock; ++c) {
      if (block.cells[c]) leaf->setValueOn(static_cast<openvdb::Index>(c), true);
    }
    tree.addLeaf(leaf);
  }
  return grid;
}

struct Polygons {
  std::vector<openvdb::Vec3s> points;  // index space
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  std::uint64_t triangleCount() const { return triangles.size() + 2 * quads.size(); }
};

Polygons polygons(const openvdb::BoolGrid& grid, double adaptivity) {
  Polygons result;
  // Voxel values read as 0 and 1: the surface crosses halfway between centres, on the
  // cells' faces.
  openvdb::tools::volumeToMesh(grid, result.points, result.triangles, result.quads, 0.5, adaptivity);
  return result;
}

// The least adaptivity of a few, from 0 (a polygon per voxel face crossed) to 1, whose mesh
// fits the budget: higher ones merge the voxels of flat parts into larger polygons.
Polygons fittingPolygons(const openvdb::BoolGrid& grid, std::uint64_t max_triangles) {
  Polygons result = polygons(grid, 0.0);
  for (double adaptivity : {0.05, 0.1, 0.2, 0.4, 0.7, 1.0}) {
    if (max_triangles == 0 || result.triangleCount() <= max_triangles) return result;
    result = polygons(grid, adaptivity);
  }
  if (max_triangles > 0 && result.triangleCount() > max_triangles) {
    throw InputError("surface mesh: " + std::to_string(result.triangleCount()) + " triangles at the coarsest, over the " +
                     std::to_string(max_triangles) + " asked for");
  }
  return result;
}

// OpenVDB winds the polygons of a solid clockwise seen from outside: each is reversed. A
// quad is cut along its shorter diagonal, which gives the better triangles.
SurfaceMesh toMesh(const Polygons& polygons, const CellSet& cells) {
  SurfaceMesh mesh;
  mesh.vertices.reserve(polygons.points.size());
  for (const openvdb::Vec3s& p : polygons.points) {
    // Voxel (i, j, k) is centred on index point (i, j, k), lattice cell i on (i + 1/2) step.
    std::array<float, 3> vertex;
    for (int d = 0; d < 3; ++d) vertex[d] = static_cast<float>(cells.origin[d] + (p[d] + 0.5) * cells.steps[d]);
    mesh.vertices.push_back(vertex);
  }
  mesh.triangles.reserve(polygons.triangleCount());
  for (const openvdb::Vec3I& t : polygons.triangles) mesh.triangles.push_back({t[0], t[2], t[1]});
  const auto squared = [&mesh](std::uint32_t a, std::uint32_t b) {
    double sum = 0.0;
    for (int d = 0; d < 3; ++d) {
      const double difference = double(mesh.vertices[a][d]) - mesh.vertices[b][d];
      sum += difference * difference;
    }
    return sum;
  };
  for (const openvdb::Vec4I& q : polygons.quads) {
    // Reversed: a d c b.
    if (squared(q[0], q[2]) <= squared(q[1], q[3])) {
      mesh.triangles.push_back({q[0], q[3], q[2]});
      mesh.triangles.push_back({q[0], q[2], q[1]});
    } else {
      mesh.triangles.push_back({q[0], q[3], q[1]});
      mesh.triangles.push_back({q[3], q[2], q[1]});
    }
  }
  return mesh;
}

// Taubin's lambda | mu smoothing: a shrinking step towards the neighbours' mean, then an
// inflating one, so that the volume is kept (plain Laplacian smoothing shrinks the mesh).
void smooth(SurfaceMesh* mesh, int iterations) {
  const std::size_t n = mesh->vertices.size();
  // Neighbours of each vertex, from the edges (each shared by two triangles: taken once).
  std::vector<std::uint32_t> first(n + 1, 0), neighbours;
  for (const auto& t : mesh->triangles) {
    for (int e = 0; e < 3; ++e) ++first[t[e] + 1];
  }
  for (std::size_t v = 0; v < n; ++v) first[v + 1] += first[v];
  neighbours.resize(first[n]);
  std::vector<std::uint32_t> filled(first.begin(), first.end() - 1);
  for (const auto& t : mesh->triangles) {
    for (int e = 0; e < 3; ++e) neighbours[filled[t[e]]++] = t[(e + 1) % 3];
  }
  std::vector<std::array<float, 3>> moved(n);
  for (int pass = 0; pass < 2 * iterations; ++pass) {
    const float factor = pass % 2 == 0 ? 0.5f : -0.53f;
    parallelFor(n, 0, [&](std::size_t begin, std::size_t end) {
      for (std::size_t v = begin; v < end; ++v) {
        std::array<float, 3> mean{};
        for (std::uint32_t k = first[v]; k < first[v + 1]; ++k) {
          for (int d = 0; d < 3; ++d) mean[d] += mesh->vertices[neighbours[k]][d];
        }
        const float count = static_cast<float>(first[v + 1] - first[v]);
        for (int d = 0; d < 3; ++d) moved[v][d] = mesh->vertices[v][d] + factor * (mean[d] / count - mesh->vertices[v][d]);
      }
    });
    mesh->vertices.swap(moved);
  }
}

}  // namespace

CellSet workspaceCells(const WorkspaceAnalysis& analysis) {
  return analysisCells(analysis, [analysis](std::uint64_t block, int cells, bool* members) {
    for (int c = 0; c < cells; ++c) members[c] = analysis.inside(block, c);
  });
}

CellSet maximalWorkspaceCells(const WorkspaceAnalysis& analysis, std::int8_t sign) {
  std::vector<int> modes(analysis.modes().size());
  for (std::size_t m = 0; m < modes.size(); ++m) modes[m] = static_cast<int>(m);
  return analysisCells(analysis, [analysis, modes, sign](std::uint64_t block, int cells, bool* members) {
    const std::vector<Region>& regions = analysis.regions();
    labelledMembers(analysis, block, cells, modes,
                    [&](std::int32_t label) { return regions[label].sign == sign && !regions[label].debris; }, members);
  });
}

CellSet regionCells(const WorkspaceAnalysis& analysis, std::int32_t region) {
  if (region < 0 || region >= static_cast<std::int32_t>(analysis.regions().size())) {
    throw InputError("surface mesh: no region " + std::to_string(region));
  }
  const std::vector<int> modes = {analysis.regions()[region].mode};
  return analysisCells(analysis, [analysis, modes, region](std::uint64_t block, int cells, bool* members) {
    labelledMembers(analysis, block, cells, modes, [region](std::int32_t label) { return label == region; }, members);
  });
}

CellSet totalOrientationCells(const Grid& grid, const OrientationCoverage& coverage, int assembly, bool traditional) {
  if (!hasOrientationSet(grid)) throw InputError("surface mesh: the grid has no orientation set");
  CellSet set;
  std::array<std::int64_t, 3> first{}, first_block{}, blocks{};
  for (int d = 0; d < 3; ++d) {
    set.steps[d] = grid.step(d);
    first[d] = grid.firstLatticeIndex(d);
    first_block[d] = floorDivide(first[d], kCellBlockSide);
    blocks[d] = floorDivide(first[d] + coverage.size(d) - 1, kCellBlockSide) - first_block[d] + 1;
  }
  set.blocks = static_cast<std::uint64_t>(blocks[0] * blocks[1] * blocks[2]);
  const auto shared = std::make_shared<const OrientationCoverage>(coverage);
  set.read = [shared, first, first_block, blocks, assembly, traditional](std::uint64_t b, CellBlock* block) {
    const OrientationCoverage& coverage = *shared;
    const std::array<std::int64_t, 3> at = {static_cast<std::int64_t>(b) / (blocks[1] * blocks[2]),
                                            static_cast<std::int64_t>(b) / blocks[2] % blocks[1],
                                            static_cast<std::int64_t>(b) % blocks[2]};
    for (int d = 0; d < 3; ++d) block->origin[d] = (first_block[d] + at[d]) * kCellBlockSide;
    block->full = false;
    block->cells.reset();
    for (int c = 0; c < kCellsPerBlock; ++c) {
      std::array<std::int64_t, 3> position{};
      bool in_box = true;
      for (int d = 0; d < 3; ++d) {
        position[d] = block->origin[d] + (c >> (3 * (2 - d)) & (kCellBlockSide - 1)) - first[d];
        in_box = in_box && position[d] >= 0 && position[d] < coverage.size(d);
      }
      if (!in_box) continue;
      const std::uint64_t p = coverage.position(position[0], position[1], position[2]);
      // Every orientation: the share is 1 up to the rounding of its float sum.
      const float share = traditional ? coverage.traditional(assembly, p) : coverage.reachable(assembly, p);
      if (share >= 1.0f - 1e-6f) block->cells.set(c);
    }
    return block->cells.any();
  };
  return set;
}

SurfaceMesh surfaceMesh(const CellSet& cells, const MeshOptions& options) {
  const BoolGridPtr grid = cellGrid(cells);
  if (grid->tree().empty()) return SurfaceMesh();
  SurfaceMesh mesh = toMesh(fittingPolygons(*grid, options.max_triangles), cells);
  if (options.smoothing > 0) smooth(&mesh, options.smoothing);
  return mesh;
}

std::vector<std::array<float, 3>> vertexNormals(const SurfaceMesh& mesh) {
  std::vector<Eigen::Vector3d> sums(mesh.vertices.size(), Eigen::Vector3d::Zero());
  const auto at = [&mesh](std::uint32_t v) {
    return Eigen::Vector3d(mesh.vertices[v][0], mesh.vertices[v][1], mesh.vertices[v][2]);
  };
  for (const auto& t : mesh.triangles) {
    // Twice the area, along the normal of a counter-clockwise triangle.
    const Eigen::Vector3d weighted = (at(t[1]) - at(t[0])).cross(at(t[2]) - at(t[0]));
    for (std::uint32_t v : t) sums[v] += weighted;
  }
  std::vector<std::array<float, 3>> normals(sums.size(), {0.0f, 0.0f, 0.0f});
  for (std::size_t v = 0; v < sums.size(); ++v) {
    const double length = sums[v].norm();
    if (length > 0.0) {
      for (int d = 0; d < 3; ++d) normals[v][d] = static_cast<float>(sums[v][d] / length);
    }
  }
  return normals;
}

double enclosedVolume(const SurfaceMesh& mesh) {
  if (mesh.vertices.empty()) return 0.0;
  // About a vertex of the mesh rather than the origin: smaller terms, less cancellation.
  const std::array<float, 3>& o = mesh.vertices[0];
  double six_times = 0.0;
  for (const auto& t : mesh.triangles) {
    double p[3][3];
    for (int k = 0; k < 3; ++k) {
      for (int d = 0; d < 3; ++d) p[k][d] = double(mesh.vertices[t[k]][d]) - o[d];
    }
    six_times += p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) - p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
                 p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0]);
  }
  return six_times / 6.0;
}

}  // namespace maximal_workspace
