#pragma once
// How far apart two poses of one grid are, for the planner's costs and heuristics, and the
// straight segment between them. Only the grid's variables differ between the poses of a
// plan; a rotation counts as the distance the platform nodes move, so radians are scaled
// by the robot's characteristic length (docs/kinematics.md). Along a periodic variable
// (a full turn of phi or psi, or of the azimuth) the segment takes the short way round.
// Internal to the library.

#include <algorithm>
#include <array>
#include <cmath>

#include "maximal_workspace/workspace/grid.h"

namespace maximal_workspace {

class PlannerMetric {
 public:
  PlannerMetric(const Grid& grid, double characteristic_length) : grid_(grid) {
    for (int d = 0; d < grid.dims(); ++d) {
      scale_[d] = isRotational(grid.variable(d)) ? characteristic_length : 1.0;
    }
  }

  // `to` with each periodic variable moved by whole turns to within half a turn of `from`:
  // the same pose, and a linear interpolation of the angles from `from` then takes the short
  // way. On a tilt-and-torsion grid the angles are `from`'s moved by the change of azimuth,
  // tilt and torsion (a linear map of the ZYZ angles, Grid::move), so that interpolating
  // them is interpolating the grid's own coordinates, whichever ZYZ triple `to` holds.
  Pose nearestTurn(const Pose& from, const Pose& to) const {
    Pose result = to;
    if (grid_.tiltTorsion()) {
      result.euler_zyz = from.euler_zyz;
      for (int d = 0; d < grid_.dims(); ++d) {
        if (isRotational(grid_.variable(d))) grid_.move(&result, d, change(from, to, d));
      }
      return result;
    }
    for (int d = 0; d < grid_.dims(); ++d) {
      if (!grid_.periodic(d)) continue;
      const OutputVariable v = grid_.variable(d);
      result.setValue(v, from.value(v) + std::remainder(to.value(v) - from.value(v), 2.0 * M_PI));
    }
    return result;
  }

  double distance(const Pose& from, const Pose& to) const {
    double squared = 0.0;
    for (int d = 0; d < grid_.dims(); ++d) {
      const double delta = change(from, to, d) * scale_[d];
      squared += delta * delta;
    }
    return std::sqrt(squared);
  }

  // The pose a fraction t of the way along the straight segment.
  Pose interpolate(const Pose& from, const Pose& to, double t) const { return along(from, nearestTurn(from, to), t); }

  // The same with `near`, nearestTurn(from, to), already known: a segment sampled many
  // times turns its end once.
  static Pose along(const Pose& from, const Pose& near, double t) {
    Pose result;
    result.position = from.position + t * (near.position - from.position);
    result.euler_zyz = from.euler_zyz + t * (near.euler_zyz - from.euler_zyz);
    return result;
  }

  // The fraction t in [0, 1] of the segment from `from` to `to` nearest to `point`.
  double nearestFraction(const Pose& from, const Pose& to, const Pose& point) const {
    double along = 0.0, squared = 0.0;
    for (int d = 0; d < grid_.dims(); ++d) {
      const double segment = change(from, to, d) * scale_[d];
      along += segment * change(from, point, d) * scale_[d];
      squared += segment * segment;
    }
    return squared > 0.0 ? std::clamp(along / squared, 0.0, 1.0) : 0.0;
  }

  // The length of one step along grid variable d (m).
  double stepLength(int d) const { return grid_.step(d) * scale_[d]; }

 private:
  // How far grid variable d goes from `from` to `to`, the short way round a periodic one.
  double change(const Pose& from, const Pose& to, int d) const {
    const double delta = grid_.coordinate(to, d) - grid_.coordinate(from, d);
    return grid_.periodic(d) ? std::remainder(delta, 2.0 * M_PI) : delta;
  }

  const Grid& grid_;
  std::array<double, kMaxGridDims> scale_{};
};

}  // namespace maximal_workspace
