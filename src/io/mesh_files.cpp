#include "maximal_workspace/io/mesh_files.h"

#include <memory>
#include <ostream>
#include <stdexcept>
#include <utility>

#include <assimp/Exporter.hpp>
#include <assimp/scene.h>

#include "maximal_workspace/io/workspace_files.h"  // writeFileAtomically
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/regions/orientation_coverage.h"
#include "maximal_workspace/surfaces/vertex_conditioning.h"

namespace maximal_workspace {

namespace {

struct FormatName {
  MeshFormat format;
  const char* extension;
  const char* assimp_id;  // Assimp::Exporter's format id; none: written here
};
// PLY is written here: Debian 12's assimp (5.2) writes a binary PLY's colours as floats
// under a header that says bytes, a corrupt file (assimp issue 3827, fixed in 2024).
constexpr FormatName kFormats[] = {{MeshFormat::Stl, "stl", "stlb"}, {MeshFormat::Ply, "ply", nullptr},
                                   {MeshFormat::Obj, "obj", "objnomtl"}};

const FormatName& formatName(MeshFormat format) {
  for (const FormatName& name : kFormats) {
    if (name.format == format) return name;
  }
  throw std::logic_error("unknown mesh format");
}

// One mesh, one (default) material, one node: what every exporter expects. The scene
// owns and frees all of it.
std::unique_ptr<aiScene> sceneOf(const SurfaceMesh& surface) {
  auto scene = std::make_unique<aiScene>();
  auto* mesh = new aiMesh();
  scene->mMeshes = new aiMesh*[1]{mesh};
  scene->mNumMeshes = 1;
  scene->mMaterials = new aiMaterial*[1]{new aiMaterial()};
  scene->mNumMaterials = 1;
  scene->mRootNode = new aiNode();
  scene->mRootNode->mMeshes = new unsigned[1]{0};
  scene->mRootNode->mNumMeshes = 1;
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mNumVertices = static_cast<unsigned>(surface.vertices.size());
  mesh->mVertices = new aiVector3D[mesh->mNumVertices];
  for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
    mesh->mVertices[v] = aiVector3D(surface.vertices[v][0], surface.vertices[v][1], surface.vertices[v][2]);
  }
  mesh->mNumFaces = static_cast<unsigned>(surface.triangles.size());
  mesh->mFaces = new aiFace[mesh->mNumFaces];
  for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
    mesh->mFaces[f].mNumIndices = 3;
    mesh->mFaces[f].mIndices = new unsigned[3]{surface.triangles[f][0], surface.triangles[f][1], surface.triangles[f][2]};
  }
  return scene;
}

// Binary PLY in the machine's byte order (the header says which): float x y z, with
// uchar red green blue when the mesh has colours and float quality (the name MeshLab and
// CloudCompare read as a scalar field) when it has one, then the triangles.
void writePly(const SurfaceMesh& mesh, std::ostream& out) {
  const std::uint16_t one = 1;
  const bool little = *reinterpret_cast<const std::uint8_t*>(&one) == 1;
  const bool coloured = !mesh.colours.empty();
  const bool rated = !mesh.quality.empty();
  out << "ply\nformat " << (little ? "binary_little_endian" : "binary_big_endian")
      << " 1.0\ncomment maximal_workspace boundary mesh, metres\nelement vertex " << mesh.vertices.size()
      << "\nproperty float x\nproperty float y\nproperty float z\n"
      << (coloured ? "property uchar red\nproperty uchar green\nproperty uchar blue\n" : "")
      << (rated ? "property float quality\n" : "") << "element face "
      << mesh.triangles.size() << "\nproperty list uchar uint vertex_indices\nend_header\n";
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    out.write(reinterpret_cast<const char*>(mesh.vertices[v].data()), sizeof(mesh.vertices[v]));
    if (coloured) out.write(reinterpret_cast<const char*>(mesh.colours[v].data()), sizeof(mesh.colours[v]));
    if (rated) out.write(reinterpret_cast<const char*>(&mesh.quality[v]), sizeof(float));
  }
  for (const auto& triangle : mesh.triangles) {
    out.put(3);
    out.write(reinterpret_cast<const char*>(triangle.data()), sizeof(triangle));
  }
}

std::string signName(int assembly) { return assembly == 0 ? "positive" : "negative"; }

}  // namespace

MeshFormat parseMeshFormat(const std::string& name, const std::string& what) {
  for (const FormatName& format : kFormats) {
    if (name == format.extension) return format.format;
  }
  throw InputError(what + ": unknown mesh format '" + name + "' (expected stl, ply or obj)");
}

std::string meshExtension(MeshFormat format) { return formatName(format).extension; }

void writeMeshFile(const SurfaceMesh& mesh, MeshFormat format, const std::string& path) {
  for (const std::size_t values : {mesh.colours.size(), mesh.quality.size()}) {
    if (values != 0 && values != mesh.vertices.size()) {
      throw InputError(path + ": cannot write (" + std::to_string(values) + " vertex values for " +
                       std::to_string(mesh.vertices.size()) + " vertices)");
    }
  }
  if (format == MeshFormat::Ply) {
    writeFileAtomically(path, [&mesh](std::ostream& out) { writePly(mesh, out); });
    return;
  }
  const std::unique_ptr<aiScene> scene = sceneOf(mesh);
  // In memory first, then written as every other file here: atomically, a failed write
  // named with its reason.
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(scene.get(), formatName(format).assimp_id);
  if (blob == nullptr) throw InputError(path + ": cannot write (assimp: " + exporter.GetErrorString() + ")");
  writeFileAtomically(path, [blob](std::ostream& out) {
    out.write(static_cast<const char*>(blob->data), static_cast<std::streamsize>(blob->size));
  });
}

bool workspaceMeshable(const Grid& grid) { return (grid.dims() == 3 && grid.isSpatial()) || hasOrientationSet(grid); }

std::vector<MeshFile> writeWorkspaceMeshes(const WorkspaceAnalysis& analysis, MeshFormat format,
                                           const MeshOptions& options, const std::string& directory,
                                           const RobotModel* model) {
  const Grid& grid = analysis.grid();
  if (!workspaceMeshable(grid)) {
    throw InputError("surface mesh: the grid must be over x y z, or x y z and an orientation set");
  }
  struct MeshedSet {
    std::string stem;
    CellSet cells;
    std::int8_t conditioning_sign;  // colour by the conditioning index of this assembly mode; 0: no colours
  };
  const bool conditioning = model != nullptr && format == MeshFormat::Ply && analysis.conditioning().has_value();
  std::vector<MeshedSet> sets;
  if (hasOrientationSet(grid)) {
    const OrientationCoverage coverage = orientationCoverage(analysis);
    for (int a = 0; a < 2; ++a) {
      sets.push_back({"total_orientation_" + signName(a), totalOrientationCells(grid, coverage, a, false), 0});
      sets.push_back({"total_orientation_traditional_" + signName(a), totalOrientationCells(grid, coverage, a, true), 0});
    }
  } else {
    for (int a = 0; a < 2; ++a) {
      const AssemblyModeSummary& mode = analysis.assemblyModes()[a];
      sets.push_back({"maximal_" + signName(a), maximalWorkspaceCells(analysis, mode.sign),
                      conditioning ? mode.sign : std::int8_t{0}});
      if (mode.traditional_region >= 0) {
        sets.push_back({"traditional_" + signName(a), regionCells(analysis, mode.traditional_region), 0});
      }
    }
  }
  std::vector<MeshFile> written;
  for (const MeshedSet& set : sets) {
    SurfaceMesh mesh = surfaceMesh(set.cells, options);
    if (mesh.triangles.empty()) continue;
    double top = 0.0;
    if (set.conditioning_sign != 0) {
      const std::vector<float> indices =
          vertexConditioning(*model, analysis, mesh, set.conditioning_sign, analysis.grid().step(0));
      top = conditioningScaleTop(indices);
      colourByConditioning(indices, top, &mesh);
    }
    const std::string name = set.stem + "." + meshExtension(format);
    writeMeshFile(mesh, format, directory + "/" + name);
    written.push_back({name, mesh.triangles.size(), enclosedVolume(mesh), top});
  }
  return written;
}

}  // namespace maximal_workspace
