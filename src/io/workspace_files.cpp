#include "maximal_workspace/io/workspace_files.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <random>

#include <ext/stdio_filebuf.h>
#include <fcntl.h>
#include <unistd.h>

#include "maximal_workspace/io/octree_export.h"
#include "maximal_workspace/io/text_file.h"
#include "maximal_workspace/io/workspace_state.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"
#include "maximal_workspace/regions/orientation_coverage.h"

namespace maximal_workspace {

namespace fs = std::filesystem;

namespace {

using nlohmann::json;

json poseJson(const Pose& pose) {
  return json{{"x", pose.position.x()},   {"y", pose.position.y()},         {"z", pose.position.z()},
              {"phi", pose.euler_zyz[0]}, {"theta", pose.euler_zyz[1]}, {"psi", pose.euler_zyz[2]}};
}

json gridJson(const Grid& grid) {
  json variables = json::array(), steps = json::array(), bounds = json::array(), cells = json::array();
  for (int d = 0; d < grid.dims(); ++d) {
    variables.push_back(outputVariableName(grid.variable(d)));
    steps.push_back(grid.step(d));
    bounds.push_back({grid.spec().bounds[d][0], grid.spec().bounds[d][1]});
    cells.push_back(grid.size(d));
  }
  return json{{"variables", variables}, {"steps", steps},       {"start", poseJson(grid.spec().start)},
              {"bounds", bounds},       {"box_cells", cells},   {"cells", grid.cellCount()},
              {"cell_volume", grid.cellVolume()}, {"volume_unit", grid.volumeUnit()},
              {"orientation_coordinates", grid.tiltTorsion() ? "tilt_torsion" : "euler_zyz"}};
}

json coverageJson(const CoverageVolumes& volumes) {
  return json{{"total_orientation_volume", volumes.total_orientation_volume},
              {"total_orientation_positions", volumes.total_orientation_positions},
              {"inclusion_volume", volumes.inclusion_volume},
              {"inclusion_positions", volumes.inclusion_positions}};
}

// The orientation set and, per assembly mode, the volumes of positions that reach all of
// it or some of it (orientation_coverage.h); null for another grid.
json orientationSetJson(const WorkspaceAnalysis& analysis, const OrientationCoverage* known) {
  const Grid& grid = analysis.grid();
  if (!hasOrientationSet(grid)) return nullptr;
  std::optional<OrientationCoverage> computed;
  const OrientationCoverage& coverage = known != nullptr ? *known : computed.emplace(orientationCoverage(analysis));
  json modes = json::array();
  for (const AssemblyModeCoverage& mode : coverage.assemblyModes()) {
    modes.push_back({{"sign", mode.sign}, {"maximal", coverageJson(mode.reachable)}, {"traditional", coverageJson(mode.traditional)}});
  }
  const auto extent = [&](int d) {
    return json{grid.centre(d, 0) - 0.5 * grid.step(d), grid.centre(d, grid.size(d) - 1) + 0.5 * grid.step(d)};
  };
  return json{{"tilt", extent(4)}, {"torsion", extent(5)}, {"angle_steps", {grid.step(3), grid.step(4), grid.step(5)}},
              {"volume_unit", "m^3"}, {"assembly_modes", modes}};
}

json modeVolumes(const WorkspaceAnalysis& analysis) {
  json per_mode = json::array();
  for (std::size_t m = 0; m < analysis.modes().size(); ++m) {
    json entry{{"mode", analysis.modes()[m].name}};
    for (std::int8_t sign : {1, -1}) {
      int regions = 0, debris = 0;
      double volume = 0.0;
      for (const Region& region : analysis.regions()) {
        if (region.mode != static_cast<int>(m) || region.sign != sign) continue;
        (region.debris ? debris : regions)++;
        if (!region.debris) volume += region.volume;
      }
      entry[sign > 0 ? "positive" : "negative"] = json{{"regions", regions}, {"debris", debris}, {"volume", volume}};
    }
    per_mode.push_back(entry);
  }
  return per_mode;
}

json boundsJson(const VolumeBounds& bounds) {
  return json{{"inner_volume", bounds.inner},
              {"boundary_volume", bounds.boundary},
              {"inner_voxels", bounds.inner_voxels},
              {"boundary_voxels", bounds.boundary_voxels}};
}

json assemblyModesJson(const WorkspaceAnalysis& analysis) {
  const double total = analysis.workspaceVolume();
  json result = json::array();
  for (const AssemblyModeSummary& am : analysis.assemblyModes()) {
    result.push_back(json{{"sign", am.sign},
                          {"regions", am.regions},
                          {"debris_regions", am.debris_regions},
                          {"transitions", am.transitions},
                          {"components", am.components},
                          {"maximal_voxels", am.maximal_voxels},
                          {"maximal_volume", am.maximal_volume},
                          {"maximal_fraction", am.maximal_volume / total},
                          {"traditional_region", am.traditional_region},
                          {"traditional_volume", am.traditional_volume},
                          {"traditional_fraction", am.traditional_volume / total},
                          {"reachable_voxels", am.reachable_voxels},
                          {"reachable_volume", am.reachable_volume},
                          {"reachable_fraction", am.reachable_volume / total},
                          {"maximal_bounds", boundsJson(am.maximal_bounds)},
                          {"traditional_bounds", boundsJson(am.traditional_bounds)},
                          {"reachable_bounds", boundsJson(am.reachable_bounds)}});
  }
  return result;
}

// The conditioning figures per assembly mode (docs/kinematics.md, "Conditioning index");
// null when the analysis was not asked for them.
json conditioningJson(const WorkspaceAnalysis& analysis) {
  if (!analysis.conditioning()) return nullptr;
  const ConditioningSummary& conditioning = *analysis.conditioning();
  json modes = json::array();
  for (int a = 0; a < 2; ++a) {
    const ConditioningFigures& figures = conditioning.assembly_modes[a];
    const double maximal = analysis.assemblyModes()[a].maximal_volume;
    modes.push_back(json{{"sign", analysis.assemblyModes()[a].sign},
                         {"sampled_cells", figures.samples},
                         {"well_conditioned_cells", figures.well_conditioned},
                         {"well_conditioned_volume", figures.well_conditioned_volume},
                         {"well_conditioned_fraction", maximal > 0.0 ? figures.well_conditioned_volume / maximal : 0.0},
                         {"global_conditioning_index", figures.global_index}});
  }
  return json{{"threshold", conditioning.request.threshold},
              {"sampling_stride", conditioning.stride},
              {"evaluations_asked", conditioning.request.evaluations},
              {"seconds", conditioning.seconds},
              {"assembly_modes", modes}};
}

json regionsJson(const WorkspaceAnalysis& analysis) {
  json result = json::array();
  for (const Region& region : analysis.regions()) {
    result.push_back(json{{"id", region.id},
                          {"mode", analysis.modes()[region.mode].name},
                          {"sign", region.sign},
                          {"voxels", region.voxels},
                          {"volume", region.volume},
                          {"debris", region.debris},
                          {"component", analysis.transitions().component[region.id]}});
  }
  return result;
}

json transitionsJson(const RobotModel& model, const WorkspaceAnalysis& analysis) {
  json result = json::array();
  for (const Transition& transition : analysis.transitions().transitions) {
    const Region& from = analysis.regions()[transition.from_region];
    const Region& to = analysis.regions()[transition.to_region];
    result.push_back(json{{"from_region", transition.from_region},
                          {"to_region", transition.to_region},
                          {"from_mode", analysis.modes()[from.mode].name},
                          {"to_mode", analysis.modes()[to.mode].name},
                          {"input", model.inputs[transition.input].name},
                          {"sign", transition.sign},
                          {"between_debris", from.debris || to.debris},
                          {"points", transition.points.size()},
                          {"first_point", poseJson(analysis.transitions().pose(transition.points.front()))}});
  }
  return result;
}

// A new file beside `path` under a random name, created exclusively (O_EXCL): whatever
// sits at a name tried, a symlink planted there included, is neither followed nor
// overwritten. Its mode is 0666 less the umask, as for a file opened the usual way.
// Returns the descriptor, or -1 with errno set.
int createTemporaryBeside(const std::string& path, std::string& temporary) {
  std::random_device random;
  for (int attempt = 0;; ++attempt) {
    char suffix[32];
    std::snprintf(suffix, sizeof suffix, ".tmp-%08x%08x", random(), random());
    temporary = path + suffix;
    const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST || attempt == 15) return fd;
  }
}

// A stream buffer that passes everything on to `target` and calls `tick` after every
// kTickBytes: a file of hundreds of megabytes reports (and may be cancelled) as it goes.
class TickingBuffer : public std::streambuf {
 public:
  static constexpr std::uint64_t kTickBytes = std::uint64_t{16} << 20;
  TickingBuffer(std::streambuf* target, std::function<void()> tick) : target_(target), tick_(std::move(tick)) {}

 protected:
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    count(1);
    return target_->sputc(traits_type::to_char_type(c));
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    count(static_cast<std::uint64_t>(n));
    return target_->sputn(s, n);
  }
  int sync() override { return target_->pubsync(); }

 private:
  void count(std::uint64_t bytes) {
    written_ += bytes;
    if (written_ / kTickBytes != (written_ - bytes) / kTickBytes) tick_();
  }
  std::streambuf* target_;
  std::function<void()> tick_;
  std::uint64_t written_ = 0;
};

// Writes `path` as writeFileAtomically does, through `write`, calling `tick` as it goes.
// What `tick` throws (Cancelled) passes on: the stream rethrows it rather than only
// marking itself bad.
void writeTicking(const std::string& path, const std::function<void(std::ostream&)>& write,
                  const std::function<void()>& tick) {
  writeFileAtomically(path, [&](std::ostream& out) {
    TickingBuffer buffer(out.rdbuf(), tick);
    std::ostream ticking(&buffer);
    ticking.exceptions(std::ios::badbit);
    try {
      write(ticking);
      ticking.flush();
    } catch (const std::ios_base::failure&) {
      out.setstate(std::ios::badbit);  // a write the file refused (a full disk): reported with its errno
    }
  });
}

}  // namespace

json workspaceSummary(const RobotModel& model, const RobotSource& source, const WorkspaceAnalysis& analysis,
                      const OrientationCoverage* coverage) {
  const AnalysisSettings& settings = analysis.settings();
  json modes = json::array();
  for (const WorkingMode& mode : analysis.modes()) modes.push_back(mode.name);
  std::string why_not;
  const StageSeconds& s = analysis.seconds();
  const SingularityCounts& singularities = analysis.singularityCounts();
  return json{
      {"format", kSummaryFormat},
      {"robot", {{"name", model.name}, {"file", source.path}, {"hash", source.hash}}},
      {"grid", gridJson(analysis.grid())},
      {"options",
       {{"margin", settings.margin},
        {"measure_tolerance", kMeasureTolerance},
        {"debris_min_voxels", settings.debris.min_voxels},
        {"debris_min_fraction", settings.debris.min_fraction},
        {"working_modes", settings.uncoupled ? "uncoupled" : "coupled"},
        {"transition_tolerance", settings.transition_tolerance}}},
      {"working_modes", modes},
      {"start_mode", analysis.modes()[analysis.startMode()].name},
      {"det_method", analysis.factorised() ? "couple factorisation" : "shared minors"},
      {"workspace",
       {{"voxels", analysis.voxelCount()},
        {"volume", analysis.workspaceVolume()},
        {"bounds", boundsJson(analysis.workspaceBounds())},
        {"poses_tested", analysis.posesEvaluated()},
        {"boxes_proven", analysis.boxesProven()}}},
      {"singularity_map",
       {{"dkp_voxel_entries", singularities.dkp_entries},
        {"ikp_boundary_faces", singularities.ikp_faces},
        {"ikp_chain_entries", singularities.ikp_entries},
        {"actuator_limit_entries", singularities.limit_entries},
        {"joint_cone_entries", singularities.cone_entries},
        {"interference_entries", singularities.interference_entries},
        {"thin_layer_faces", singularities.thin_layer_faces}}},
      {"volumes_per_mode", modeVolumes(analysis)},
      {"assembly_modes", assemblyModesJson(analysis)},
      {"orientation_set", orientationSetJson(analysis, coverage)},
      {"conditioning", conditioningJson(analysis)},
      {"regions", regionsJson(analysis)},
      {"transitions", transitionsJson(model, analysis)},
      {"transition_points", analysis.transitions().points.size()},
      {"octrees", octreeExportable(analysis.grid(), &why_not) ? json("exported")
                  : hasOrientationSet(analysis.grid()) ? json("exported: total-orientation workspaces and coverage")
                                                        : json("not exported: " + why_not)},
      {"seconds",
       {{"classification", s.classification}, {"regions", s.regions}, {"singularities", s.singularities},
        {"transitions", s.transitions}, {"summary", s.summary}, {"total", s.total}}}};
}

void writeCoverageCsv(const Grid& grid, const OrientationCoverage& coverage, std::ostream& out) {
  out << "x,y,z,maximal_positive,traditional_positive,maximal_negative,traditional_negative\n";
  for (std::int64_t i = 0; i < coverage.size(0); ++i) {
    for (std::int64_t j = 0; j < coverage.size(1); ++j) {
      for (std::int64_t k = 0; k < coverage.size(2); ++k) {
        const std::uint64_t p = coverage.position(i, j, k);
        if (!(coverage.reachable(0, p) > 0.0f || coverage.reachable(1, p) > 0.0f)) continue;
        out << exactText(grid.centre(0, i)) << ',' << exactText(grid.centre(1, j)) << ',' << exactText(grid.centre(2, k));
        for (int a = 0; a < 2; ++a) out << ',' << coverage.reachable(a, p) << ',' << coverage.traditional(a, p);
        out << '\n';
      }
    }
  }
}

void writeTransitionsCsv(const WorkspaceAnalysis& analysis, std::ostream& out) {
  // The transitions each point serves, leaving out those that touch debris: point p's are
  // served[first[p] .. first[p + 1]), in increasing order (a string a point held each
  // point's list twice over at 1 mm, 6.7 M of them).
  const TransitionGraph& graph = analysis.transitions();
  const auto counts = [&](std::size_t t) {
    const Transition& transition = graph.transitions[t];
    return !analysis.regions()[transition.from_region].debris && !analysis.regions()[transition.to_region].debris;
  };
  std::vector<std::uint32_t> first(graph.points.size() + 1, 0);
  for (std::size_t t = 0; t < graph.transitions.size(); ++t) {
    if (counts(t)) {
      for (std::uint32_t p : graph.transitions[t].points) ++first[p + 1];
    }
  }
  for (std::size_t p = 0; p < graph.points.size(); ++p) first[p + 1] += first[p];
  std::vector<std::uint32_t> served(first.back()), filled(first.begin(), first.end() - 1);
  for (std::size_t t = 0; t < graph.transitions.size(); ++t) {
    if (counts(t)) {
      for (std::uint32_t p : graph.transitions[t].points) served[filled[p]++] = static_cast<std::uint32_t>(t);
    }
  }
  out << "point,input,chain,cell,x,y,z,phi,theta,psi,transitions\n";
  for (std::size_t p = 0; p < graph.points.size(); ++p) {
    if (first[p] == first[p + 1]) continue;
    const TransitionPoint& point = graph.points[p];
    const Pose pose = graph.pose(p);
    out << p << ',' << int(point.input) << ',' << int(point.chain) << ',' << point.cell;
    for (int v = 0; v < kOutputVariableCount; ++v) out << ',' << csvNumber(pose.value(static_cast<OutputVariable>(v)));
    for (std::uint32_t i = first[p]; i < first[p + 1]; ++i) out << (i == first[p] ? ',' : ';') << served[i];
    out << '\n';
  }
}

void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  checkOutputTarget(path);
  std::string temporary;
  const int fd = createTemporaryBeside(path, temporary);
  if (fd < 0) throw InputError(path + ": cannot write (cannot create " + temporary + ": " + std::strerror(errno) + ")");
  try {
    __gnu_cxx::stdio_filebuf<char> file(fd, std::ios::out | std::ios::binary, std::size_t{1} << 16);
    std::ostream out(&file);
    write(out);
    out.flush();
    // errno still holds the reason of the write(2) that failed (ENOSPC, EFBIG).
    if (!out || file.close() == nullptr) throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
  } catch (...) {
    ::unlink(temporary.c_str());
    throw;
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(temporary.c_str());
    throw InputError(path + ": cannot write (rename failed: " + reason + ")");
  }
}

void writeFileAtomically(const std::string& path, const std::string& content) {
  writeFileAtomically(path, [&content](std::ostream& out) { out << content; });
}

std::vector<std::string> writeFilesInto(const std::string& directory,
                                        const std::function<void(const std::string& staging)>& write) {
  std::error_code error;
  // The outermost directory made here, removed again when writing fails.
  fs::path created;
  for (fs::path at = fs::absolute(directory).lexically_normal(); !fs::exists(at, error) && !error; at = at.parent_path()) {
    created = at;
  }
  fs::create_directories(directory, error);
  if (error || !fs::is_directory(directory, error)) {
    throw InputError(directory + ": cannot create output directory" + (error ? ": " + error.message() : ""));
  }
  const auto remove_created = [&created] {
    std::error_code ignored;
    if (!created.empty()) fs::remove_all(created, ignored);
  };
  std::string staging = directory + "/.mow-staging-XXXXXX";
  if (::mkdtemp(staging.data()) == nullptr) {
    const std::string reason = std::strerror(errno);
    remove_created();
    throw InputError(directory + ": cannot write (cannot create a staging directory: " + reason + ")");
  }
  const auto remove_written = [&] {
    std::error_code ignored;
    fs::remove_all(staging, ignored);
    remove_created();
  };
  try {
    write(staging);
    std::vector<std::string> names;
    for (const fs::directory_entry& file : fs::directory_iterator(staging)) names.push_back(file.path().filename().string());
    std::sort(names.begin(), names.end());
    for (const std::string& name : names) {
      fs::rename(staging + "/" + name, directory + "/" + name, error);
      if (error) throw InputError(directory + "/" + name + ": cannot write (rename failed: " + error.message() + ")");
    }
    fs::remove(staging, error);  // empty now; should it stay, the files are in place all the same
    return names;
  } catch (const InputError& failure) {
    remove_written();
    // Named where the file was to go: the staging directory is gone.
    std::string message = failure.what();
    for (std::size_t at; (at = message.find(staging)) != std::string::npos;) message.replace(at, staging.size(), directory);
    throw InputError(message);
  } catch (...) {
    remove_written();
    throw;
  }
}

nlohmann::json readWorkspaceSummary(const std::string& directory) {
  return json::parse(readTextFile(directory + "/summary.json", "workspace summary", kMaxSummaryFileBytes));
}

std::vector<std::string> writeWorkspaceFiles(const RobotModel& model, const RobotSource& source,
                                             const WorkspaceAnalysis& analysis, const std::string& directory,
                                             const std::function<void(double)>& progress) {
  // Shares of the writing time, the delta-like robot at 2 mm on 2 cores: octrees 5.5 s,
  // transitions.csv 0.96 s, workspace.bin 0.43 s, summary.json 0.02 s (at 3 mm the octrees
  // took 3.5 of 4.0 s).
  const auto done = [&progress](double fraction) {
    if (progress) progress(fraction);
  };
  done(0.0);  // storing has begun: a listener hears of it before the first file is done
  std::vector<std::string> written;
  std::string why_not;
  std::optional<OrientationCoverage> coverage;  // computed once, for its files and the summary
  if (octreeExportable(analysis.grid(), &why_not)) {
    written = writeOctrees(analysis, directory, [&](std::size_t trees, std::size_t of) { done(0.8 * trees / of); });
  } else if (hasOrientationSet(analysis.grid())) {
    coverage.emplace(orientationCoverage(analysis));
    written = writeCoverageOctrees(analysis, *coverage, directory);
    writeFileAtomically(directory + "/coverage.csv", [&](std::ostream& out) { writeCoverageCsv(analysis.grid(), *coverage, out); });
    written.push_back("coverage.csv");
  }
  done(0.8);
  // Streamed to their files: at fine steps they are hundreds of megabytes; `progress`
  // hears of them every 16 MiB (it may stop the writing there).
  writeTicking(directory + "/transitions.csv", [&](std::ostream& out) { writeTransitionsCsv(analysis, out); },
               [&] { done(0.8); });
  written.push_back("transitions.csv");
  done(0.93);
  writeTicking(directory + "/" + kStateFileName, [&](std::ostream& out) { writeWorkspaceState(analysis, out); },
               [&] { done(0.93); });
  written.push_back(kStateFileName);
  done(0.99);
  // JSON is UTF-8: a robot file's path need not be (names and text in it are checked on
  // load), so bytes that are not are written as U+FFFD rather than failing the write.
  writeFileAtomically(directory + "/summary.json",
                      workspaceSummary(model, source, analysis, coverage ? &*coverage : nullptr)
                              .dump(1, ' ', false, nlohmann::json::error_handler_t::replace) +
                          "\n");
  written.push_back("summary.json");
  done(1.0);
  return written;
}

}  // namespace maximal_workspace
