#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "analysis_request.h"
#include "arguments.h"
#include "commands.h"
#include "maximal_workspace/io/mesh_files.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_files.h"
#include "maximal_workspace/workspace/cancellation.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/regions/workspace_analysis.h"

namespace maximal_workspace::cli {

namespace {

// A mesh's triangles by default: 50 MB as binary STL.
constexpr std::uint64_t kDefaultMeshTriangles = 1000000;
constexpr std::uint64_t kMaxMeshSmoothing = 1000;

std::string percent(double fraction) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f %%", 100.0 * fraction);
  return buffer;
}

// Six significant digits, rounded outward (`up` for an upper bound): the printed interval
// still holds the exact volume. Shares of cells make the bounds' last digits noise. A
// value within 1e-9 of a digit (a whole number of cells times the cell's volume) is
// taken as it: its rounding error is far smaller than that.
std::string boundText(double value, bool up) {
  if (value == 0.0 || !std::isfinite(value)) return numberText(value);
  const double scale = std::pow(10.0, 5.0 - std::floor(std::log10(std::abs(value))));
  const double digits = up ? std::ceil(value * scale - 1e-9) : std::floor(value * scale + 1e-9);
  return numberText(digits / scale);
}

// "[inner, inner + boundary]"
std::string boundsText(const nlohmann::json& bounds) {
  const double inner = bounds["inner_volume"].get<double>();
  return "[" + boundText(inner, false) + ", " + boundText(inner + bounds["boundary_volume"].get<double>(), true) + "]";
}

// The conditioning figures, when the analysis was asked for them.
void printConditioning(const nlohmann::json& summary, const std::string& unit) {
  const auto found = summary.find("conditioning");
  if (found == summary.end() || !found->is_object()) return;
  const nlohmann::json& conditioning = *found;
  const int stride = conditioning["sampling_stride"].get<int>();
  std::cout << "conditioning (index >= " << numberText(conditioning["threshold"].get<double>()) << "; "
            << (stride == 1 ? std::string("every cell") : "1 cell in " + std::to_string(stride) + " along each variable")
            << " sampled, ";
  std::printf("%.3f s):\n", conditioning["seconds"].get<double>());
  std::fflush(stdout);
  for (const nlohmann::json& am : conditioning["assembly_modes"]) {
    std::cout << "  assembly mode " << (am["sign"].get<int>() > 0 ? "+" : "-") << ": well-conditioned maximal "
              << numberText(am["well_conditioned_volume"].get<double>()) << unit << " ("
              << percent(am["well_conditioned_fraction"].get<double>()) << " of the maximal), global conditioning index "
              << numberText(am["global_conditioning_index"].get<double>()) << " (" << am["sampled_cells"].get<unsigned long long>()
              << " cells)\n";
  }
}

// The total-orientation and inclusion volumes, for an analysis over an orientation set.
void printOrientationSet(const nlohmann::json& summary) {
  const nlohmann::json& set = summary["orientation_set"];
  if (!set.is_object()) return;
  std::cout << "orientation set: tilt [" << numberText(set["tilt"][0].get<double>()) << ", "
            << numberText(set["tilt"][1].get<double>()) << "] rad, torsion [" << numberText(set["torsion"][0].get<double>())
            << ", " << numberText(set["torsion"][1].get<double>()) << "] rad, every azimuth\n";
  for (const nlohmann::json& am : set["assembly_modes"]) {
    const nlohmann::json &maximal = am["maximal"], &traditional = am["traditional"];
    std::cout << "  assembly mode " << (am["sign"].get<int>() > 0 ? "+" : "-")
              << ": total-orientation workspace, maximal (reachable from the start) "
              << numberText(maximal["total_orientation_volume"].get<double>()) << " m^3, traditional "
              << numberText(traditional["total_orientation_volume"].get<double>())
              << " m^3; inclusion workspace, maximal " << numberText(maximal["inclusion_volume"].get<double>())
              << " m^3, traditional " << numberText(traditional["inclusion_volume"].get<double>()) << " m^3\n";
  }
}

// Printed from summary.json, so a cached and a fresh result read the same.
void printSummary(const nlohmann::json& summary) {
  const nlohmann::json& grid = summary["grid"];
  const std::string unit = " " + grid["volume_unit"].get<std::string>();
  std::cout << "robot: " << summary["robot"]["name"].get<std::string>() << " (" << summary["robot"]["file"].get<std::string>()
            << ")\ngrid:";
  for (const auto& variable : grid["variables"]) std::cout << " " << variable.get<std::string>();
  std::cout << ", step";
  for (const auto& step : grid["steps"]) std::cout << " " << numberText(step.get<double>());
  std::cout << ", box";
  for (std::size_t d = 0; d < grid["box_cells"].size(); ++d) std::cout << (d ? " x " : " ") << grid["box_cells"][d].get<long long>();
  std::cout << " = " << grid["cells"].get<unsigned long long>() << " cells\n";
  std::cout << "working modes: " << summary["working_modes"].size() << ", start in "
            << summary["start_mode"].get<std::string>() << " (det J_DKP by " << summary["det_method"].get<std::string>()
            << "); signs " << marginText(summary["options"]["margin"].get<double>()) << "\n";
  const nlohmann::json& workspace = summary["workspace"];
  std::cout << "workspace: " << workspace["voxels"].get<unsigned long long>() << " voxels, volume "
            << numberText(workspace["volume"].get<double>()) << unit << " (" << workspace["poses_tested"].get<unsigned long long>()
            << " poses tested, " << workspace["boxes_proven"].get<unsigned long long>() << " boxes given to interval proofs)\n";
  const nlohmann::json& singularities = summary["singularity_map"];
  std::cout << "singularity map: " << singularities["dkp_voxel_entries"].get<unsigned long long>()
            << " DKP-singular voxel entries, " << singularities["ikp_boundary_faces"].get<unsigned long long>()
            << " IKP boundary faces (" << singularities["ikp_chain_entries"].get<unsigned long long>()
            << " with each limiting chain)";
  const unsigned long long walls[3] = {singularities.value("actuator_limit_entries", 0ull),
                                       singularities.value("joint_cone_entries", 0ull),
                                       singularities.value("interference_entries", 0ull)};
  if (walls[0] + walls[1] + walls[2] > 0) {
    std::cout << ", walls of the robot's limits (face, working mode): " << walls[0] << " actuator limit, " << walls[1]
              << " joint cone, " << walls[2] << " interference";
  }
  std::cout << "; " << singularities.value("thin_layer_faces", 0ull) << " faces across a layer thinner than the step\n";
  std::cout << "regions per working mode and sign: count [debris count] and volume (" << grid["volume_unit"].get<std::string>()
            << ") of the non-debris ones:\n";
  std::printf("  %-8s %22s %22s\n", "mode", "sign +", "sign -");
  for (const nlohmann::json& mode : summary["volumes_per_mode"]) {
    const nlohmann::json &plus = mode["positive"], &minus = mode["negative"];
    std::printf("  %-8s %4d [%3d] %12.6f %4d [%3d] %12.6f\n", mode["mode"].get<std::string>().c_str(), plus["regions"].get<int>(),
                plus["debris"].get<int>(), plus["volume"].get<double>(), minus["regions"].get<int>(),
                minus["debris"].get<int>(), minus["volume"].get<double>());
  }
  std::fflush(stdout);
  for (const nlohmann::json& am : summary["assembly_modes"]) {
    std::cout << "assembly mode " << (am["sign"].get<int>() > 0 ? "+" : "-") << ": maximal "
              << numberText(am["maximal_volume"].get<double>()) << unit << " (" << percent(am["maximal_fraction"].get<double>())
              << " of the workspace), traditional " << numberText(am["traditional_volume"].get<double>()) << unit << " ("
              << percent(am["traditional_fraction"].get<double>()) << "), reachable from the start "
              << numberText(am["reachable_volume"].get<double>()) << unit << " ("
              << percent(am["reachable_fraction"].get<double>()) << "); " << countText(am["regions"].get<int>(), "region")
              << ", " << am["debris_regions"].get<int>() << " debris, " << countText(am["transitions"].get<int>(), "transition")
              << ", " << countText(am["components"].get<int>(), "connected group") << "\n";
  }
  std::cout << "certified volumes (" << grid["volume_unit"].get<std::string>()
            << "; the exact volume lies in [inner, inner + boundary]): workspace " << boundsText(workspace["bounds"]);
  for (const char* set : {"maximal", "traditional", "reachable"}) {
    std::cout << "; " << set;
    for (const nlohmann::json& am : summary["assembly_modes"]) {
      std::cout << " " << (am["sign"].get<int>() > 0 ? "+" : "-") << " " << boundsText(am[std::string(set) + "_bounds"]);
    }
  }
  std::cout << "\n";
  printConditioning(summary, unit);
  printOrientationSet(summary);
  std::cout << "transition points: " << summary["transition_points"].get<unsigned long long>() << "\n";
  std::cout << "octrees: " << summary["octrees"].get<std::string>() << "\n";
  const nlohmann::json& s = summary["seconds"];
  std::printf("seconds: classification %.3f, regions %.3f, singularities %.3f, transitions %.3f, summary %.3f, total %.3f\n",
              s["classification"].get<double>(), s["regions"].get<double>(), s["singularities"].get<double>(),
              s["transitions"].get<double>(), s["summary"].get<double>(), s["total"].get<double>());
  std::fflush(stdout);
}

// What --mesh asks for, checked before anything is computed; no format: no meshes.
struct MeshRequest {
  std::optional<MeshFormat> format;
  MeshOptions options;
};

MeshRequest meshRequest(const Arguments& arguments, const AnalysisRequest& request) {
  MeshRequest meshes;
  if (!arguments.has("--mesh")) {
    for (const char* option : {"--mesh-triangles", "--mesh-smoothing"}) {
      if (arguments.has(option)) throw InputError(std::string("option ") + option + ": needs --mesh FORMAT");
    }
    return meshes;
  }
  meshes.format = parseMeshFormat(arguments.required("--mesh"), "option --mesh");
  if (!arguments.has("--out")) throw InputError("option --mesh: the meshes are written with the other files: give --out DIR");
  if (!workspaceMeshable(Grid(request.model, request.spec))) {
    throw InputError("option --mesh: meshes need a grid over x y z, or x y z and an orientation set");
  }
  meshes.options.max_triangles = arguments.count("--mesh-triangles", kDefaultMeshTriangles, 0);
  meshes.options.smoothing = static_cast<int>(arguments.count("--mesh-smoothing", 0, 0, kMaxMeshSmoothing));
  return meshes;
}

// Writes the meshes into `directory` and says what each is.
void writeMeshes(const MeshRequest& meshes, const RobotModel& model, const WorkspaceAnalysis& analysis,
                 const std::string& directory) {
  for (const MeshFile& file : writeWorkspaceMeshes(analysis, *meshes.format, meshes.options, directory, &model)) {
    std::cout << "mesh " << file.name << ": " << file.triangles << " triangles, enclosing " << numberText(file.volume)
              << " m^3";
    if (file.conditioning_top > 0.0) std::cout << ", coloured by the conditioning index on [0, " << numberText(file.conditioning_top) << "]";
    std::cout << "\n";
  }
}

// Copies the entry's files (not its manifest) into `out`, all or none, with what `more`
// writes beside them.
std::vector<std::string> copyFiles(const std::string& from, const std::string& out,
                                   const std::function<void(const std::string& staging)>& more) {
  return writeFilesInto(out, [&](const std::string& staging) {
    for (const auto& file : std::filesystem::directory_iterator(from)) {
      const std::string name = file.path().filename().string();
      if (name == "manifest.json") continue;
      // Streamed: workspace.bin and transitions.csv are hundreds of megabytes at fine steps.
      std::ifstream in = openRegularFile(file.path().string(), "cache file");
      writeFileAtomically(staging + "/" + name, [&in](std::ostream& copy) {
        char chunk[1 << 16];
        while (copy && (in.read(chunk, sizeof chunk), in.gcount() > 0)) copy.write(chunk, in.gcount());
      });
      if (in.bad()) throw InputError(file.path().string() + ": cannot read cache file: read error");
    }
    more(staging);
  });
}

}  // namespace

int runWorkspace(const std::vector<std::string>& args) {
  const Arguments arguments(
      args, analysisValueOptions({"--out", "--mesh", "--mesh-triangles", "--mesh-smoothing", "--conditioning-threshold"}),
      analysisFlags({"--conditioning"}));
  AnalysisRequest request = analysisRequest(arguments);
  const MeshRequest meshes = meshRequest(arguments, request);
  ProgressBar bar;
  if (!arguments.flag("--quiet")) request.options.progress = [&bar](const AnalysisProgress& p) { bar.update(p); };
  const std::string out = arguments.optional("--out", "");
  std::error_code ignored;  // a path that cannot be examined is reported when written
  if (!out.empty() && std::filesystem::exists(out, ignored) && !std::filesystem::is_directory(out, ignored)) {
    throw InputError("option --out: " + out + " is not a directory");
  }

  if (arguments.flag("--no-cache")) {
    const WorkspaceAnalysis analysis = analyseWorkspace(request.model, request.spec, request.options);
    bar.finish();
    if (!out.empty()) {
      writeFilesInto(out, [&](const std::string& staging) {
        writeWorkspaceFiles(request.model, request.source, analysis, staging);
        if (meshes.format) writeMeshes(meshes, request.model, analysis, staging);
      });
    }
    printSummary(workspaceSummary(request.model, request.source, analysis));
    return 0;
  }
  WorkspaceStore::Options options;
  // Without --out only the summary is read: check just that file.
  if (out.empty()) options.files = {"summary.json"};
  options.load = meshes.format.has_value();  // the meshes are made from the analysis
  // Ctrl-C while the files are written: they are dropped, nothing is cached.
  options.storing = [&request](double fraction) {
    if (fraction < 1.0) throwIfCancelled(request.options.cancelled);
  };
  const WorkspaceStore::Entry workspace = storedWorkspace(arguments, request, options, "workspace");
  bar.finish();
  printSummary(readWorkspaceSummary(workspace.path));
  const bool computed = workspace.origin == WorkspaceStore::Origin::Computed;
  std::cout << (computed ? "cached in: " : "from cache: ") << workspace.path << "\n";
  if (!out.empty()) {
    const std::vector<std::string> names = copyFiles(workspace.path, out, [&](const std::string& staging) {
      if (meshes.format) writeMeshes(meshes, request.model, *workspace.analysis, staging);
    });
    std::cout << "written to " << out << ":";
    for (const std::string& name : names) std::cout << " " << name;
    std::cout << "\n";
  }
  return 0;
}

}  // namespace maximal_workspace::cli
