#pragma once
// Surface meshes (surfaces/surface_mesh.h) as files: binary STL and Wavefront OBJ (no
// material file) through assimp, binary PLY (with the vertex colours when the mesh has
// them) written here.

#include <cstdint>
#include <string>
#include <vector>

#include "maximal_workspace/regions/workspace_analysis.h"
#include "maximal_workspace/surfaces/surface_mesh.h"

namespace maximal_workspace {

enum class MeshFormat { Stl, Ply, Obj };

// "stl", "ply" or "obj"; InputError starting with `what` otherwise.
MeshFormat parseMeshFormat(const std::string& name, const std::string& what);
// "stl", "ply" or "obj".
std::string meshExtension(MeshFormat format);

// Written atomically (writeFileAtomically); InputError naming the path when it cannot be.
void writeMeshFile(const SurfaceMesh& mesh, MeshFormat format, const std::string& path);

// True when writeWorkspaceMeshes takes the analysis: a grid over x y z, or over x y z and an
// orientation set.
bool workspaceMeshable(const Grid& grid);

struct MeshFile {
  std::string name;
  std::uint64_t triangles = 0;
  double volume = 0.0;  // enclosed, m^3
  // Coloured by the conditioning index on the scale [0, top] (vertex_conditioning.h); 0: no colours.
  double conditioning_top = 0.0;
};

// The workspaces of an analysis as meshes in `directory`, named as the octrees are: over
// x y z, per assembly mode, maximal_<positive|negative>.<ext> (the maximal operational
// workspace) and traditional_<positive|negative>.<ext>; over an orientation set,
// total_orientation_<sign>.<ext> (the positions reaching every orientation in the maximal
// workspace reachable from the start) and total_orientation_traditional_<sign>.<ext>. A set
// without a cell gets no file. InputError for another grid. In PLY, over x y z, when the
// analysis has conditioning figures and `model` is given: the maximal workspaces' vertices
// carry the conditioning index as colour and as quality (vertexConditioning).
std::vector<MeshFile> writeWorkspaceMeshes(const WorkspaceAnalysis& analysis, MeshFormat format,
                                           const MeshOptions& options, const std::string& directory,
                                           const RobotModel* model = nullptr);

}  // namespace maximal_workspace
