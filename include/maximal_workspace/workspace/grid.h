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

struct GridSpec {
  std::vector<OutputVariable> variables;  // distinct; sorted into canonical order
  std::vector<double> steps;              // one per variable, or one for all (m, rad)
  Pose start;                             // wave-front start; fixes the other variables
  // [lower, upper] per variable; empty: the robot's safety box (translations: the
  // intersection of every chain's reach box, at any orientation the grid turns to, one
  // step wider on each side; rotations: start +/- pi, a full turn). The grid holds the
  // cells whose centres lie within.
  std::vector<std::array<double, 2>> bounds;
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

 private:
  std::array<double, 2> resolveAxis(int d, std::array<double, 2> box);

  GridSpec spec_;
  std::array<double, kMaxGridDims> anchor_{};      // value of lattice index 0
  std::array<std::int64_t, kMaxGridDims> first_{};  // lattice index of cell 0
  std::array<std::int64_t, kMaxGridDims> size_{};
  std::array<std::uint64_t, kMaxGridDims> stride_{};
  std::array<bool, kMaxGridDims> periodic_{};
  std::uint64_t cell_count_ = 0;
};

// The default safety box of a variable (see GridSpec::bounds); +/-infinity where the
// chains leave it unbounded. Translations at the start's orientation, or, when
// `orientation_varies` (a grid with a rotational variable), at any orientation.
std::array<double, 2> safetyBounds(const RobotModel& model, const Pose& start, OutputVariable variable,
                                   bool orientation_varies = false);

}  // namespace maximal_workspace
