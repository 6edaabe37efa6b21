#include "maximal_workspace/io/workspace_state.h"

#include <cstring>
#include <istream>
#include <ostream>
#include <type_traits>

#include "maximal_workspace/model/input_error.h"

namespace maximal_workspace {

namespace {

constexpr char kMagic[8] = {'M', 'O', 'W', 'S', 'T', 'A', 'T', 'E'};
constexpr std::uint32_t kVersion = 1;

class Writer {
 public:
  explicit Writer(std::ostream& out) : out_(out) {}
  template <class T>
  void value(const T& v) {
    static_assert(std::is_arithmetic<T>::value, "plain numbers only: no padding bytes in the file");
    out_.write(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <class T>
  void values(const std::vector<T>& v) {
    value<std::uint64_t>(v.size());
    static_assert(std::is_arithmetic<T>::value, "plain numbers only");
    out_.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
  }
  void text(const std::string& s) {
    value<std::uint64_t>(s.size());
    out_.write(s.data(), static_cast<std::streamsize>(s.size()));
  }
  void pose(const Pose& p) {
    for (int v = 0; v < kOutputVariableCount; ++v) value(p.value(static_cast<OutputVariable>(v)));
  }

 private:
  std::ostream& out_;
};

class Reader {
 public:
  Reader(std::istream& in, std::string source) : in_(in), source_(std::move(source)) {}
  [[noreturn]] void fail(const std::string& reason) const {
    throw InputError(source_ + ": not a usable workspace state file: " + reason);
  }
  template <class T>
  T value() {
    T v{};
    if (!in_.read(reinterpret_cast<char*>(&v), sizeof v)) fail("truncated");
    return v;
  }
  // A count of items of `item_bytes` each, refused when larger than the bytes left.
  std::uint64_t count(std::size_t item_bytes) {
    const std::uint64_t n = value<std::uint64_t>();
    const std::streampos here = in_.tellg();
    in_.seekg(0, std::ios::end);
    const std::uint64_t left = static_cast<std::uint64_t>(in_.tellg() - here);
    in_.seekg(here);
    if (item_bytes > 0 && n > left / item_bytes) fail("a length runs past the end of the file");
    return n;
  }
  template <class T>
  std::vector<T> values() {
    std::vector<T> v(count(sizeof(T)));
    if (!in_.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)))) fail("truncated");
    return v;
  }
  std::string text() {
    std::string s(count(1), '\0');
    if (!in_.read(s.data(), static_cast<std::streamsize>(s.size()))) fail("truncated");
    return s;
  }
  Pose pose() {
    Pose p;
    for (int v = 0; v < kOutputVariableCount; ++v) p.setValue(static_cast<OutputVariable>(v), value<double>());
    return p;
  }

 private:
  std::istream& in_;
  std::string source_;
};

}  // namespace

void writeWorkspaceState(const WorkspaceAnalysis& analysis, const AnalysisOptions& options, std::ostream& out) {
  Writer w(out);
  out.write(kMagic, sizeof kMagic);
  w.value(kVersion);
  // The grid as resolved, bounds included, so it is rebuilt identical.
  const GridSpec& spec = analysis.grid.spec();
  w.value<std::uint64_t>(spec.variables.size());
  for (std::size_t d = 0; d < spec.variables.size(); ++d) {
    w.value<std::int32_t>(static_cast<std::int32_t>(spec.variables[d]));
    w.value(spec.steps[d]);
    w.value(spec.bounds[d][0]);
    w.value(spec.bounds[d][1]);
  }
  w.pose(spec.start);
  w.value(spec.voxel_budget);
  w.value(options.debris.min_voxels);
  w.value(options.debris.min_fraction);
  w.value<std::uint64_t>(analysis.modes.size());
  for (const WorkingMode& mode : analysis.modes) {
    w.text(mode.name);
    w.value(mode.negative_chains);
  }
  w.value<std::int32_t>(analysis.start_mode);
  w.value<std::uint8_t>(analysis.factorised);
  // Map: voxels, signs, and the cells tested outside (the IKP faces' far side).
  w.value<std::int32_t>(analysis.map.mode_count);
  w.values(analysis.map.voxel_cell);
  w.values(analysis.map.signs);
  w.value(analysis.map.evaluated);
  std::vector<std::uint32_t> outside;
  for (std::size_t cell = 0; cell < analysis.map.cell_voxel.size(); ++cell) {
    if (analysis.map.cell_voxel[cell] == kCellOutside) outside.push_back(static_cast<std::uint32_t>(cell));
  }
  w.values(outside);
  w.value<std::uint64_t>(analysis.singularities.dkp.size());
  for (const DkpSingularVoxel& s : analysis.singularities.dkp) {
    w.value(s.voxel);
    w.value(s.mode);
    w.value(s.measure);
  }
  w.value<std::uint64_t>(analysis.singularities.ikp.size());
  for (const IkpBoundaryFace& f : analysis.singularities.ikp) {
    w.value(f.voxel);
    w.value(f.dim);
    w.value(f.direction);
    w.value(f.input);
    w.value(f.chain);
  }
  // Region table, to check the recomputed labels against.
  w.value<std::uint64_t>(analysis.regions.regions.size());
  for (const Region& r : analysis.regions.regions) {
    w.value<std::int32_t>(r.mode);
    w.value(r.sign);
    w.value(r.voxels);
    w.value<std::uint8_t>(r.debris);
  }
  w.value<std::uint64_t>(analysis.transitions.points.size());
  for (const TransitionPoint& p : analysis.transitions.points) {
    w.pose(p.pose);
    w.value(p.voxel);
    w.value(p.input);
    w.value(p.chain);
  }
  w.value<std::uint64_t>(analysis.transitions.transitions.size());
  for (const Transition& t : analysis.transitions.transitions) {
    w.value(t.from_region);
    w.value(t.to_region);
    w.value(t.input);
    w.value(t.sign);
    w.values(t.points);
  }
  w.values(analysis.transitions.component);
  for (const AssemblyModeSummary& am : analysis.assembly_modes) {
    w.value(am.sign);
    for (int n : {am.regions, am.debris_regions, am.transitions, am.components}) w.value<std::int32_t>(n);
    w.value(am.maximal_voxels);
    w.value(am.maximal_volume);
    w.value(am.traditional_region);
    w.value(am.traditional_volume);
    w.value(am.reachable_voxels);
    w.value(am.reachable_volume);
  }
  const StageSeconds& s = analysis.seconds;
  for (double t : {s.wave_front, s.singularities, s.regions, s.transitions, s.summary, s.total}) w.value(t);
}

WorkspaceAnalysis readWorkspaceState(const RobotModel& model, std::istream& in, const std::string& source, int threads,
                                     std::uint64_t max_cells) {
  Reader r(in, source);
  char magic[sizeof kMagic];
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof kMagic) != 0) r.fail("wrong magic");
  if (r.value<std::uint32_t>() != kVersion) r.fail("another version");
  GridSpec spec;
  const std::uint64_t dims = r.value<std::uint64_t>();
  if (dims < 1 || dims > kMaxGridDims) r.fail("bad grid");
  for (std::uint64_t d = 0; d < dims; ++d) {
    const std::int32_t variable = r.value<std::int32_t>();
    if (variable < 0 || variable >= kOutputVariableCount) r.fail("bad grid variable");
    spec.variables.push_back(static_cast<OutputVariable>(variable));
    spec.steps.push_back(r.value<double>());
    const double lower = r.value<double>();
    spec.bounds.push_back({lower, r.value<double>()});
  }
  spec.start = r.pose();
  spec.voxel_budget = r.value<std::uint64_t>();
  DebrisThreshold debris;
  debris.min_voxels = r.value<std::uint64_t>();
  debris.min_fraction = r.value<double>();
  WorkspaceAnalysis analysis{[&] {
    try {
      return Grid(model, spec);
    } catch (const InputError& error) {
      r.fail(error.what());
    }
  }()};
  const Grid& grid = analysis.grid;
  if (grid.cellCount() > max_cells) {
    r.fail("its box holds " + std::to_string(grid.cellCount()) + " cells, over the reader's limit of " +
           std::to_string(max_cells));
  }
  const std::uint64_t modes = r.count(12);
  if (modes < 1 || modes > 64) r.fail("bad working-mode count");
  for (std::uint64_t m = 0; m < modes; ++m) {
    WorkingMode mode;
    mode.name = r.text();
    mode.negative_chains = r.value<std::uint32_t>();
    analysis.modes.push_back(mode);
  }
  analysis.start_mode = r.value<std::int32_t>();
  if (analysis.start_mode < 0 || analysis.start_mode >= static_cast<int>(modes)) r.fail("bad start mode");
  analysis.factorised = r.value<std::uint8_t>() != 0;

  WorkspaceMap& map = analysis.map;
  map.mode_count = r.value<std::int32_t>();
  if (map.mode_count != static_cast<int>(modes)) r.fail("working-mode count mismatch");
  map.voxel_cell = r.values<std::uint32_t>();
  map.signs = r.values<std::int8_t>();
  map.evaluated = r.value<std::uint64_t>();
  if (map.voxel_cell.empty() || map.signs.size() != map.voxel_cell.size() * modes) r.fail("map sizes disagree");
  map.cell_voxel.assign(grid.cellCount(), kCellNotVisited);
  for (std::size_t v = 0; v < map.voxel_cell.size(); ++v) {
    if (map.voxel_cell[v] >= grid.cellCount() || map.cell_voxel[map.voxel_cell[v]] != kCellNotVisited) r.fail("bad voxel cell");
    map.cell_voxel[map.voxel_cell[v]] = static_cast<std::uint32_t>(v);
  }
  for (std::uint32_t cell : r.values<std::uint32_t>()) {
    if (cell >= grid.cellCount() || map.cell_voxel[cell] != kCellNotVisited) r.fail("bad outside cell");
    map.cell_voxel[cell] = kCellOutside;
  }
  const std::uint64_t voxels = map.voxelCount();
  const std::uint64_t dkp = r.count(9);
  for (std::uint64_t i = 0; i < dkp; ++i) {
    DkpSingularVoxel s{r.value<std::uint32_t>(), r.value<std::uint8_t>(), r.value<float>()};
    if (s.voxel >= voxels || s.mode >= modes) r.fail("bad singular voxel");
    analysis.singularities.dkp.push_back(s);
  }
  const std::uint64_t ikp = r.count(8);
  for (std::uint64_t i = 0; i < ikp; ++i) {
    IkpBoundaryFace f{r.value<std::uint32_t>(), r.value<std::uint8_t>(), r.value<std::int8_t>(), r.value<std::uint8_t>(),
                      r.value<std::uint8_t>()};
    if (f.voxel >= voxels || f.dim >= dims || f.input >= model.inputCount() || f.chain >= model.chainCount()) {
      r.fail("bad boundary face");
    }
    analysis.singularities.ikp.push_back(f);
  }
  analysis.regions = labelRegions(grid, map, debris, threads);
  const std::uint64_t regions = r.count(14);
  if (regions != analysis.regions.regions.size()) r.fail("the region table does not match the map");
  for (const Region& region : analysis.regions.regions) {
    const std::int32_t mode = r.value<std::int32_t>();
    const std::int8_t sign = r.value<std::int8_t>();
    const std::uint64_t count = r.value<std::uint64_t>();
    const bool is_debris = r.value<std::uint8_t>() != 0;
    if (mode != region.mode || sign != region.sign || count != region.voxels || is_debris != region.debris) {
      r.fail("the region table does not match the map");
    }
  }
  const std::uint64_t points = r.count(6 * sizeof(double) + 6);
  for (std::uint64_t i = 0; i < points; ++i) {
    TransitionPoint p;
    p.pose = r.pose();
    p.voxel = r.value<std::uint32_t>();
    p.input = r.value<std::uint8_t>();
    p.chain = r.value<std::uint8_t>();
    if (p.voxel >= voxels || p.input >= model.inputCount() || p.chain >= model.chainCount()) r.fail("bad transition point");
    analysis.transitions.points.push_back(p);
  }
  const std::uint64_t transitions = r.count(18);
  for (std::uint64_t i = 0; i < transitions; ++i) {
    Transition t;
    t.from_region = r.value<std::uint32_t>();
    t.to_region = r.value<std::uint32_t>();
    t.input = r.value<std::uint8_t>();
    t.sign = r.value<std::int8_t>();
    t.points = r.values<std::uint32_t>();
    if (t.from_region >= regions || t.to_region >= regions) r.fail("bad transition");
    for (std::uint32_t p : t.points) {
      if (p >= points) r.fail("bad transition point index");
    }
    analysis.transitions.transitions.push_back(std::move(t));
  }
  analysis.transitions.component = r.values<std::int32_t>();
  if (analysis.transitions.component.size() != regions) r.fail("bad component table");
  for (AssemblyModeSummary& am : analysis.assembly_modes) {
    am.sign = r.value<std::int8_t>();
    for (int* n : {&am.regions, &am.debris_regions, &am.transitions, &am.components}) *n = r.value<std::int32_t>();
    am.maximal_voxels = r.value<std::uint64_t>();
    am.maximal_volume = r.value<double>();
    am.traditional_region = r.value<std::int32_t>();
    am.traditional_volume = r.value<double>();
    am.reachable_voxels = r.value<std::uint64_t>();
    am.reachable_volume = r.value<double>();
    if (am.traditional_region >= static_cast<std::int32_t>(regions)) r.fail("bad traditional region");
  }
  StageSeconds& s = analysis.seconds;
  for (double* t : {&s.wave_front, &s.singularities, &s.regions, &s.transitions, &s.summary, &s.total}) *t = r.value<double>();
  if (in.peek() != std::char_traits<char>::eof()) r.fail("bytes after the end");
  return analysis;
}

}  // namespace maximal_workspace
