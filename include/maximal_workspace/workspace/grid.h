#pragma once
// The wave front's lattice: chosen output variables (1 to 6), a step per variable, the
// others fixed at the start pose, inside a safety box. Translational cell centres sit at
// (k + 1/2) step, the centres of OctoMap cells of resolution `step`, so a grid over x y z
// maps voxel for voxel onto an octree; rotational ones are anchored at the start value.
// A grid over phi or psi whose box spans a full turn is periodic along it: it holds
// n = ceil(2 pi / step) cells of step 2 pi / n, and the first and last are neighbours.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

constexpr int kMaxGridDims = kOutputVariableCount;
using GridCell = std::array<std::int64_t, kMaxGridDims>;

// How a grid reads its rotational variables.
// - EulerZyz: phi, theta, psi of the pose (R = Rz(phi) Ry(theta) Rz(psi)).
// - TiltTorsion (Bonev and Ryu): phi holds the azimuth a, theta the tilt t, psi the
//   torsion s of R = R_ref Rz(a) Ry(t) Rz(s - a), R_ref the robot's reference orientation,
//   which must be level (theta 0) so that the pose's ZYZ angles are (a + phi_ref + psi_ref,
//   t, s - a), a linear map: a box of cells is enclosed by a box of ZYZ angles. The grid
//   needs all three angles; a full turn of a is periodic, and tilt cells are [k, k + 1]
//   steps from t = 0, where every azimuth is one orientation (the pole).
enum class OrientationCoordinates : std::uint8_t { EulerZyz = 0, TiltTorsion = 1 };

struct GridSpec {
  std::vector<OutputVariable> variables;  // distinct; sorted into canonical order
  std::vector<double> steps;              // one per variable, or one for all (m, rad)
  Pose start;                             // wave-front start; fixes the other variables
  // [lower, upper] per variable; empty: the robot's safety box (translations: the
  // intersection of every chain's reach box, at any orientation the grid turns to, one
  // step wider on each side; rotations: start +/- pi, a full turn). The grid holds the
  // cells whose centres lie within.
  std::vector<std::array<double, 2>> bounds;
  OrientationCoordinates orientation = OrientationCoordinates::EulerZyz;
};

class Grid {
 public:
  // Throws InputError for a bad spec or an unbounded box; allocates nothing.
  Grid(const RobotModel& model, GridSpec spec);

  const GridSpec& spec() const { return spec_; }
  int dims() const { return static_cast<int>(spec_.variables.size()); }
  OutputVariable variable(int d) const { return spec_.variables[d]; }
  double step(int d) const { return spec_.steps[d]; }
  std::int64_t size(int d) const { return size_[d]; }
  std::uint64_t cellCount() const { return cell_count_; }
  // True along a rotational variable whose box is a full turn: cell 0 and cell size - 1
  // are neighbours.
  bool periodic(int d) const { return periodic_[d]; }
  // Product of the steps, in volumeUnit(): m^3 for x y z, m^2 for x y, ...
  double cellVolume() const;
  std::string volumeUnit() const;

  // Lattice index of cell 0 along d: cell i is [(first + i) step, (first + i + 1) step]
  // for a translational variable, so lattice indices are octree keys up to a constant.
  std::int64_t firstLatticeIndex(int d) const { return first_[d]; }
  double centre(int d, std::int64_t i) const { return anchor_[d] + static_cast<double>(first_[d] + i) * spec_.steps[d]; }
  std::uint64_t index(const GridCell& cell) const;
  GridCell cell(std::uint64_t index) const;
  // The neighbour one step along d (direction +1 or -1); false when it leaves the box
  // (never along a periodic variable).
  bool neighbour(std::uint64_t index, int d, int direction, std::uint64_t* result) const;
  // The start pose with the grid variables at the cell centre.
  Pose pose(std::uint64_t index) const;
  // The start pose with grid variable d at values[d] (m or rad).
  Pose poseAt(const double* values) const;
  // Moves `pose` by `offset` along grid variable d.
  void move(Pose* pose, int d, double offset) const;
  // The poses `start` moved along d by `offset` +/- `half` (m or rad).
  PoseBox segmentBox(const Pose& start, int d, double offset, double half) const;
  // The value of grid variable d at `pose` (a periodic one within a turn of the box).
  double coordinate(const Pose& pose, int d) const;
  // x .. psi, or azimuth, tilt and torsion for a TiltTorsion grid's angles.
  std::string variableName(int d) const;
  bool tiltTorsion() const { return spec_.orientation == OrientationCoordinates::TiltTorsion; }
  // The grid dimensions of the tilt and the azimuth of a TiltTorsion grid, else -1.
  int tiltDim() const { return tilt_dim_; }
  int azimuthDim() const { return azimuth_dim_; }
  // The poses of the cell: its centre, and half a step along each grid variable.
  PoseBox cellBox(std::uint64_t index) const;
  // The poses of the cells from `first` to `last` (inclusive along every variable).
  PoseBox cellsBox(const GridCell& first, const GridCell& last) const;
  // The cell holding a pose; false outside the box. A periodic variable's value is taken
  // modulo a full turn.
  bool cellOf(const Pose& pose, std::uint64_t* index) const;
  // True when the grid variables are x y z, or x y (for a planar robot): the grid then
  // maps onto an octree.
  bool isSpatial() const;
  // True when no grid variable turns the platform: every cell has the start's orientation.
  bool orientationFixed() const;

 private:
  std::array<double, 2> resolveAxis(int d, std::array<double, 2> box);
  void setOrientationCoordinates(const RobotModel& model);
  // Widens `box` by `half` on each side along grid variable d.
  void widen(PoseBox* box, int d, double half) const;

  GridSpec spec_;
  std::array<double, kMaxGridDims> anchor_{};      // value of lattice index 0
  std::array<std::int64_t, kMaxGridDims> first_{};  // lattice index of cell 0
  std::array<std::int64_t, kMaxGridDims> size_{};
  std::array<std::uint64_t, kMaxGridDims> stride_{};
  std::array<bool, kMaxGridDims> periodic_{};
  std::uint64_t cell_count_ = 0;
  Pose base_;  // the pose at grid coordinates 0
  int azimuth_dim_ = -1, tilt_dim_ = -1;
  double reference_yaw_ = 0.0;  // phi + psi of the reference orientation (TiltTorsion)
};

// An orientation set in tilt-and-torsion angles (rad): every azimuth, tilt in
// [0, tilt_max], torsion in [torsion[0], torsion[1]], cut at angle_step.
struct OrientationSet {
  double tilt_max = 0.0;
  std::array<double, 2> torsion{};
  double angle_step = 0.0;
};

// Makes `spec`, a grid over the robot's positions x y z (its steps and bounds, or none),
// a grid over those positions and every orientation of `set` (OrientationCoordinates::
// TiltTorsion). Throws InputError for a bad set or a grid over other variables.
void addOrientationSet(const RobotModel& model, const OrientationSet& set, GridSpec* spec);

// The default safety box of a variable (see GridSpec::bounds); +/-infinity where the
// chains leave it unbounded. Translations at the start's orientation, or, when
// `orientation_varies` (a grid with a rotational variable), at any orientation.
std::array<double, 2> safetyBounds(const RobotModel& model, const Pose& start, OutputVariable variable,
                                   bool orientation_varies = false);

}  // namespace maximal_workspace
