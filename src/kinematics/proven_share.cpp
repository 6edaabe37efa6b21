#include "kinematics/proven_share.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace maximal_workspace {

namespace {

// Slopes below this share of their sum are raised to it: a larger slope only shrinks the
// set counted, and the closed form's terms then stay within 1/kSlopeFloor^2 of the result,
// so its rounding stays far below kRoundingSlack.
constexpr double kSlopeFloor = 1.0 / 1024.0;
constexpr double kRoundingSlack = 1e-8;

// The volume of {t in [0, 1]^n : sum a_i t_i < budget}, a_i >= 0, by inclusion and
// exclusion over the corners the plane cuts off.
double unitCubeBelowPlane(double budget, std::array<double, 3> slopes, int n) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += slopes[i];
  if (budget <= 0.0) return 0.0;
  if (budget >= sum) return 1.0;
  double product = 1.0, factorial = 1.0;
  for (int i = 0; i < n; ++i) {
    slopes[i] = std::max(slopes[i], kSlopeFloor * sum);
    product *= slopes[i];
    factorial *= i + 1;
  }
  double volume = 0.0;
  for (int corner = 0; corner < (1 << n); ++corner) {
    double rest = budget;
    int sign = 1;
    for (int i = 0; i < n; ++i) {
      if (corner >> i & 1) rest -= slopes[i], sign = -sign;
    }
    if (rest <= 0.0) continue;
    double power = rest;
    for (int i = 1; i < n; ++i) power *= rest;
    volume += sign * power;
  }
  return std::clamp(volume / (factorial * product) - kRoundingSlack, 0.0, 1.0);
}

}  // namespace

double provenPositiveShare(double value, const IntervalPoint& gradient, const Eigen::Vector3d& half_width) {
  std::array<int, 3> axes{};
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    if (half_width[i] > 0.0) axes[n++] = i;
  }
  if (!std::isfinite(value)) return 0.0;
  if (n == 0) return value > 0.0 ? 1.0 : 0.0;
  double share = 0.0;
  for (int orthant = 0; orthant < (1 << n); ++orthant) {
    // Along an axis of this orthant, with t in [0, 1] the normalised distance from the
    // centre, f falls by at most slope * t: the gradient's lower end going up the axis,
    // its upper end going down.
    double budget = value;
    std::array<double, 3> slopes{};
    bool finite = true;
    for (int j = 0; j < n; ++j) {
      const Interval& g = gradient[axes[j]];
      const double fall = (orthant >> j & 1 ? -g.lower() : g.upper()) * half_width[axes[j]];
      finite = finite && std::isfinite(fall);
      // A rise along an axis: measured from the far face instead, where it is all gained.
      if (fall < 0.0) budget -= fall;
      slopes[j] = std::abs(fall);
    }
    if (finite) share += unitCubeBelowPlane(budget, slopes, n);
  }
  return share / (1 << n);
}

}  // namespace maximal_workspace
