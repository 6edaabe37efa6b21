#include "maximal_workspace/workspace/grid.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

namespace {

constexpr double kMaxCellsPerAxis = 4294967296.0;
constexpr double kMaxCells = 4503599627370496.0;  // 2^52: grid and block indices stay exact in every type used

// Phi and psi turn the platform about an axis: a full turn of either comes back to the
// same pose. Theta does not (ZYZ angles), nor does a translation.
bool fullTurn(OutputVariable variable, const std::array<double, 2>& box) {
  return (variable == OutputVariable::Phi || variable == OutputVariable::Psi) && box[1] - box[0] >= 2.0 * M_PI - 1e-9;
}

}  // namespace

void addOrientationSet(const RobotModel& model, const OrientationSet& set, GridSpec* spec) {
  auto fail = [](const std::string& reason) { throw InputError("orientation set: " + reason); };
  const std::vector<OutputVariable> xyz = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
  if (spec->variables != xyz) fail("the grid must be over x y z, the positions it adds orientations to");
  if (!(set.tilt_max > 0.0 && set.tilt_max <= M_PI)) fail("tilt_max must be in (0, pi], got " + numberText(set.tilt_max));
  if (!(set.torsion[0] < set.torsion[1] && set.torsion[0] >= -M_PI - 1e-9 && set.torsion[1] <= M_PI + 1e-9)) {
    fail("torsion must be [min, max] with -pi <= min < max <= pi, got [" + numberText(set.torsion[0]) + ", " +
         numberText(set.torsion[1]) + "]");
  }
  if (!(set.angle_step > 0.0 && set.angle_step <= set.tilt_max)) {
    fail("angle_step must be in (0, tilt_max], got " + numberText(set.angle_step));
  }
  if (spec->steps.size() != 1 && spec->steps.size() != 3) fail("the positions need one step, or one per variable");
  if (spec->steps.size() == 1) spec->steps.assign(3, spec->steps[0]);
  if (spec->bounds.empty()) {
    // The positions' safety box at any orientation, a cell wider on each side as Grid makes it.
    for (int d = 0; d < 3; ++d) {
      std::array<double, 2> box = safetyBounds(model, spec->start, xyz[d], true);
      spec->bounds.push_back({box[0] - spec->steps[d], box[1] + spec->steps[d]});
    }
  }
  spec->variables.insert(spec->variables.end(), {OutputVariable::Phi, OutputVariable::Theta, OutputVariable::Psi});
  // Steps cut each range into whole cells, as a full turn is cut (the azimuth's).
  const auto cut = [&](double range) { return range / std::ceil(range / set.angle_step - 1e-9); };
  spec->steps.insert(spec->steps.end(), {set.angle_step, cut(set.tilt_max), cut(set.torsion[1] - set.torsion[0])});
  spec->bounds.push_back({-M_PI, M_PI});
  spec->bounds.push_back({0.0, set.tilt_max});
  spec->bounds.push_back(set.torsion);
  spec->orientation = OrientationCoordinates::TiltTorsion;
}

std::array<double, 2> safetyBounds(const RobotModel& model, const Pose& start, OutputVariable variable,
                                   bool orientation_varies) {
  const int v = static_cast<int>(variable);
  if (isRotational(variable)) return {start.value(variable) - M_PI, start.value(variable) + M_PI};
  std::array<double, 2> bounds = {-INFINITY, INFINITY};
  const Eigen::Matrix3d rotation = start.rotation();
  for (int c = 0; c < model.chainCount(); ++c) {
    const ChainPtr& chain = model.chains[c];
    // Where the TCP can be for this chain: its node's reach box (within its input's
    // limits) moved by the node offset, whatever that offset turns to when the
    // orientation varies.
    const double offset = (rotation * chain->platformNode())[v];
    const double spread = orientation_varies ? chain->platformNode().norm() : 0.0;
    const Eigen::Vector2d reach = chain->reachBox(model.inputs[model.chain_input[c]].limits)[v];
    bounds[0] = std::max(bounds[0], reach[0] - (orientation_varies ? spread : offset));
    bounds[1] = std::min(bounds[1], reach[1] + (orientation_varies ? spread : -offset));
  }
  return bounds;
}

Grid::Grid(const RobotModel& model, GridSpec spec) : spec_(std::move(spec)) {
  auto fail = [](const std::string& reason) { throw InputError("grid: " + reason); };
  const int n = static_cast<int>(spec_.variables.size());
  if (n < 1 || n > kMaxGridDims) fail("needs 1 to 6 variables, got " + std::to_string(n));
  if (spec_.steps.size() == 1) spec_.steps.assign(n, spec_.steps[0]);
  if (static_cast<int>(spec_.steps.size()) != n) fail("needs one step, or one per variable");
  if (!spec_.bounds.empty() && static_cast<int>(spec_.bounds.size()) != n) fail("needs bounds for every variable");
  // Canonical order, steps and bounds following their variable.
  std::vector<int> order(n);
  for (int d = 0; d < n; ++d) order[d] = d;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return spec_.variables[a] < spec_.variables[b]; });
  GridSpec sorted = spec_;
  for (int d = 0; d < n; ++d) {
    sorted.variables[d] = spec_.variables[order[d]];
    sorted.steps[d] = spec_.steps[order[d]];
    if (!spec_.bounds.empty()) sorted.bounds[d] = spec_.bounds[order[d]];
  }
  spec_ = sorted;
  for (int d = 0; d < n; ++d) {
    const std::string name = outputVariableName(spec_.variables[d]);
    if (d > 0 && spec_.variables[d] == spec_.variables[d - 1]) fail("variable " + name + " is listed twice");
    const double step = spec_.steps[d];
    if (!std::isfinite(step) || step <= 0.0) fail("step of " + name + " must be a finite number > 0, got " + numberText(step));
  }
  if (!spec_.start.position.allFinite() || !spec_.start.euler_zyz.allFinite()) fail("start pose must be finite");
  setOrientationCoordinates(model);

  double cells = 1.0;
  std::string shape;
  const bool user_bounds = !spec_.bounds.empty();
  const bool orientation_varies = std::any_of(spec_.variables.begin(), spec_.variables.end(), isRotational);
  std::vector<std::array<double, 2>> boxes(n);
  for (int d = 0; d < n; ++d) {
    const OutputVariable variable = spec_.variables[d];
    const std::string name = variableName(d);
    std::array<double, 2> box = user_bounds ? spec_.bounds[d] : safetyBounds(model, spec_.start, variable, orientation_varies);
    if (!user_bounds && tiltTorsion() && isRotational(variable)) {
      box = d == tilt_dim_ ? std::array<double, 2>{0.0, M_PI}
                           : std::array<double, 2>{coordinate(spec_.start, d) - M_PI, coordinate(spec_.start, d) + M_PI};
    }
    if (d == tilt_dim_ && box[0] < 0.0) fail("bounds of the tilt must be >= 0, got " + numberText(box[0]));
    if (!user_bounds && !isRotational(variable)) {
      // The reach box is tight: the workspace touches it. One more cell on each side is
      // surely outside, so every IKP boundary face of the workspace is tested and found.
      box[0] -= spec_.steps[d];
      box[1] += spec_.steps[d];
    }
    if (user_bounds && !(std::isfinite(box[0]) && std::isfinite(box[1]) && box[0] < box[1])) {
      fail("bounds of " + name + " must be finite with lower < upper, got [" + numberText(box[0]) + ", " +
           numberText(box[1]) + "]");
    }
    if (!std::isfinite(box[0]) || !std::isfinite(box[1])) {
      fail("the safety box is unbounded along " + name + " for this robot; give bounds");
    }
    const double value = coordinate(spec_.start, d);
    if (value < box[0] || value > box[1]) {
      fail("start " + name + " = " + numberText(value) + " is outside the bounds [" + numberText(box[0]) + ", " +
           numberText(box[1]) + "]");
    }
    box = resolveAxis(d, box);
    boxes[d] = box;
    cells *= static_cast<double>(size_[d]);
    shape += (d ? " x " : "") + std::to_string(size_[d]);
  }
  spec_.bounds = boxes;
  // Checked in floating point first: the product may not fit 64 bits. Memory, not this,
  // bounds what an analysis takes on (AnalysisOptions::memory_budget).
  if (!(cells <= kMaxCells)) {
    char count[32];
    std::snprintf(count, sizeof count, "%.0f", cells);
    fail("the box needs " + shape + " = " + count + " cells, more than a grid can index; use a larger step or smaller bounds");
  }
  cell_count_ = 1;
  for (int d = n - 1; d >= 0; --d) {
    stride_[d] = cell_count_;
    cell_count_ *= static_cast<std::uint64_t>(size_[d]);
  }
}

// Cells of variable d over `box`: a full turn of phi or psi is cut into equal cells about
// the start; otherwise the cells whose centres lie within. Returns the box the cells span.
std::array<double, 2> Grid::resolveAxis(int d, std::array<double, 2> box) {
  auto fail = [](const std::string& reason) { throw InputError("grid: " + reason); };
  const OutputVariable variable = spec_.variables[d];
  const std::string name = variableName(d);
  const double value = coordinate(spec_.start, d);
  if (fullTurn(variable, box)) {
    // One cell per 1/n turn, centred on the start: a full turn has no first cell.
    const double turns = std::ceil(2.0 * M_PI / spec_.steps[d] - 1e-9);
    if (turns < 4) fail("step of " + name + " must be under pi/2 for a grid over a full turn");
    if (!(turns < kMaxCellsPerAxis)) fail("step of " + name + " is too fine for a full turn");
    spec_.steps[d] = 2.0 * M_PI / turns;
    periodic_[d] = true;
    anchor_[d] = value;
    size_[d] = static_cast<std::int64_t>(turns);
    first_[d] = -size_[d] / 2;
    box = {centre(d, 0) - 0.5 * spec_.steps[d], centre(d, size_[d] - 1) + 0.5 * spec_.steps[d]};
  } else {
    const double step = spec_.steps[d];
    // Tilt and torsion cells start at their lower bound (the tilt's at the pole), as
    // translational ones start at the origin.
    anchor_[d] = !isRotational(variable) ? 0.5 * step : tiltTorsion() ? box[0] + 0.5 * step : value;
    // The cells whose centres lie within the box (a hair of slack for rounding).
    const double first = std::ceil((box[0] - anchor_[d]) / step - 1e-9);
    const double last = std::floor((box[1] - anchor_[d]) / step + 1e-9);
    // Checked as doubles: a tiny step makes indices no integer type holds (fuzz_workspace_request).
    if (!(last - first < kMaxCellsPerAxis)) {
      fail("step of " + name + " " + numberText(step) + " is too fine for its bounds [" + numberText(box[0]) + ", " +
           numberText(box[1]) + "]: over " + std::to_string(static_cast<std::uint64_t>(kMaxCellsPerAxis)) +
           " cells along it");
    }
    if (last < first) fail("the bounds of " + name + " hold no cell centre at step " + numberText(step));
    // Lattice indices count steps from the origin: bounds far from it at a fine step give
    // indices no integer type holds (fuzz_workspace_state).
    if (!(std::abs(first) < kMaxCells && std::abs(last) < kMaxCells)) {
      fail("the bounds of " + name + " [" + numberText(box[0]) + ", " + numberText(box[1]) +
           "] are too far from the origin for step " + numberText(step));
    }
    first_[d] = static_cast<std::int64_t>(first);
    size_[d] = static_cast<std::int64_t>(last - first) + 1;
  }
  return box;
}

double Grid::cellVolume() const {
  double volume = 1.0;
  for (double step : spec_.steps) volume *= step;
  return volume;
}

std::string Grid::volumeUnit() const {
  int lengths = 0, angles = 0;
  for (OutputVariable variable : spec_.variables) (isRotational(variable) ? angles : lengths)++;
  auto power = [](const char* unit, int n) {
    return n == 0 ? std::string() : n == 1 ? std::string(unit) : std::string(unit) + "^" + std::to_string(n);
  };
  const std::string length = power("m", lengths), angle = power("rad", angles);
  return length.empty() ? angle : angle.empty() ? length : length + " " + angle;
}

std::uint64_t Grid::index(const GridCell& cell) const {
  std::uint64_t result = 0;
  for (int d = 0; d < dims(); ++d) result += static_cast<std::uint64_t>(cell[d]) * stride_[d];
  return result;
}

GridCell Grid::cell(std::uint64_t index) const {
  GridCell result{};
  for (int d = 0; d < dims(); ++d) {
    result[d] = static_cast<std::int64_t>(index / stride_[d]);
    index %= stride_[d];
  }
  return result;
}

bool Grid::neighbour(std::uint64_t index, int d, int direction, std::uint64_t* result) const {
  const std::int64_t i = static_cast<std::int64_t>((index / stride_[d]) % static_cast<std::uint64_t>(size_[d]));
  std::int64_t j = i + direction;
  if (j < 0 || j >= size_[d]) {
    if (!periodic_[d]) return false;
    j = j < 0 ? size_[d] - 1 : 0;
  }
  *result = index + static_cast<std::uint64_t>(j - i) * stride_[d];
  return true;
}

void Grid::setOrientationCoordinates(const RobotModel& model) {
  base_ = spec_.start;
  for (OutputVariable variable : spec_.variables) base_.setValue(variable, 0.0);
  if (!tiltTorsion()) return;
  const std::vector<OutputVariable> angles = {OutputVariable::Phi, OutputVariable::Theta, OutputVariable::Psi};
  if (!std::includes(spec_.variables.begin(), spec_.variables.end(), angles.begin(), angles.end())) {
    throw InputError("grid: tilt and torsion need all three angles (phi, theta, psi) as grid variables");
  }
  const Eigen::Vector3d reference = model.reference.pose.euler_zyz;
  if (std::abs(std::remainder(reference[1], 2.0 * M_PI)) > 1e-12) {
    throw InputError("grid: tilt and torsion are measured from a level reference orientation (theta = 0); this robot's is " +
                     numberText(reference[1]) + " rad");
  }
  reference_yaw_ = reference[0] + reference[2];
  base_.euler_zyz = Eigen::Vector3d(reference_yaw_, 0.0, 0.0);
  for (int d = 0; d < dims(); ++d) {
    if (spec_.variables[d] == OutputVariable::Phi) azimuth_dim_ = d;
    if (spec_.variables[d] == OutputVariable::Theta) tilt_dim_ = d;
  }
}

std::string Grid::variableName(int d) const {
  static const char* const kTiltTorsion[] = {"azimuth", "tilt", "torsion"};
  const int v = static_cast<int>(spec_.variables[d]);
  return tiltTorsion() && v >= 3 ? kTiltTorsion[v - 3] : outputVariableName(spec_.variables[d]);
}

Pose Grid::pose(std::uint64_t index) const {
  const GridCell c = cell(index);
  double values[kMaxGridDims];
  for (int d = 0; d < dims(); ++d) values[d] = centre(d, c[d]);
  return poseAt(values);
}

Pose Grid::poseAt(const double* values) const {
  Pose result = base_;
  for (int d = 0; d < dims(); ++d) move(&result, d, values[d]);
  return result;
}

void Grid::move(Pose* pose, int d, double offset) const {
  const int v = static_cast<int>(spec_.variables[d]);
  if (v < 3) {
    pose->position[v] += offset;
    return;
  }
  pose->euler_zyz[v - 3] += offset;
  if (d == azimuth_dim_) pose->euler_zyz[2] -= offset;  // psi = s - a
}

double Grid::coordinate(const Pose& pose, int d) const {
  const OutputVariable variable = spec_.variables[d];
  if (!tiltTorsion() || !isRotational(variable)) return pose.value(variable);
  // R_ref^T R = Rz(a) Ry(t) Rz(s - a), read from the matrix: the pose's ZYZ angles may
  // be any of the triples that give its rotation.
  const Eigen::Matrix3d r = Eigen::AngleAxisd(-reference_yaw_, Eigen::Vector3d::UnitZ()) * pose.rotation();
  const double sine = std::hypot(r(0, 2), r(1, 2));
  const double tilt = std::atan2(sine, r(2, 2));
  if (variable == OutputVariable::Theta) return tilt;
  // At the pole every azimuth is the same orientation: 0 is taken, and s is the yaw.
  const double azimuth = sine > 1e-12 ? std::atan2(r(1, 2), r(0, 2)) : 0.0;
  if (variable == OutputVariable::Phi) return azimuth;
  const double torsion = sine > 1e-12 ? azimuth + std::atan2(r(2, 1), -r(2, 0)) : std::atan2(r(1, 0), r(0, 0));
  return std::remainder(torsion, 2.0 * M_PI);
}

PoseBox Grid::cellBox(std::uint64_t index) const {
  const GridCell c = cell(index);
  return cellsBox(c, c);
}

PoseBox Grid::cellsBox(const GridCell& first, const GridCell& last) const {
  PoseBox box;
  double middle[kMaxGridDims];
  for (int d = 0; d < dims(); ++d) {
    middle[d] = 0.5 * (centre(d, first[d]) + centre(d, last[d]));
    widen(&box, d, 0.5 * static_cast<double>(last[d] - first[d] + 1) * spec_.steps[d]);
  }
  box.centre = poseAt(middle);
  return box;
}

PoseBox Grid::segmentBox(const Pose& start, int d, double offset, double half) const {
  PoseBox box;
  box.centre = start;
  move(&box.centre, d, offset);
  widen(&box, d, half);
  return box;
}

void Grid::widen(PoseBox* box, int d, double half) const {
  const int v = static_cast<int>(spec_.variables[d]);
  (v < 3 ? box->position_half_width[v] : box->angle_half_width[v - 3]) += half;
  if (!tiltTorsion() || v < 3) return;
  if (d == azimuth_dim_) box->angle_half_width[2] += half;  // psi = s - a moves with a too
  if (!box->angle_sum_half_width) box->angle_sum_half_width = 0.0;
  if (spec_.variables[d] == OutputVariable::Psi) *box->angle_sum_half_width += half;  // phi + psi = yaw + s
}

bool Grid::cellOf(const Pose& pose, std::uint64_t* index) const {
  GridCell c{};
  for (int d = 0; d < dims(); ++d) {
    double offset = coordinate(pose, d) - anchor_[d];
    if (periodic_[d]) offset = std::remainder(offset, 2.0 * M_PI);
    const double lattice = std::floor(offset / spec_.steps[d] + 0.5);
    if (!(std::abs(lattice) < 1e18)) return false;  // far outside, or not a number
    c[d] = static_cast<std::int64_t>(lattice) - first_[d];
    if (periodic_[d]) c[d] = (c[d] % size_[d] + size_[d]) % size_[d];
    if (c[d] < 0 || c[d] >= size_[d]) return false;
  }
  *index = this->index(c);
  return true;
}

bool Grid::isSpatial() const {
  const std::vector<OutputVariable> xyz = {OutputVariable::X, OutputVariable::Y, OutputVariable::Z};
  const std::vector<OutputVariable> xy = {OutputVariable::X, OutputVariable::Y};
  return spec_.variables == xyz || spec_.variables == xy;
}

bool Grid::orientationFixed() const {
  return std::none_of(spec_.variables.begin(), spec_.variables.end(), isRotational);
}

}  // namespace maximal_workspace
