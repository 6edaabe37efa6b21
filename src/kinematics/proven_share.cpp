#include "kinematics/proven_share.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace maximal_workspace {

namespace {

// Slopes below this share of their sum are raised to it: a larger slope only shrinks the
// set counted, and the closed form's terms then stay within 1/kSlopeFloor^2 of the result,
// so its rounding stays far below kRoundingSlack.
constexpr double kSlopeFloor = 1.0 / 4096.0;
constexpr double kRoundingSlack = 1e-6;

// The volume of {t in [0, 1]^n : sum a_i t_i < budget}, a_i >= 0, by inclusion and
// exclusion over the corners the plane cuts off.
double unitCubeBelowPlane(double budget, std::array<double, 3> slopes, int n) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += slopes[i];
  if (!(budget > 0.0)) return 0.0;
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
  // With m and r the gradient's midpoint and radius, f(centre + u) >= value + m . u -
  // r . |u| >= value - r . h + m . u over the box |u| <= h: one plane. Against the
  // tighter bound (one plane per orthant) it leaves out a layer r . h thick, small where
  // the gradient varies little over the box, and it is one closed form instead of 2^n.
  // With t = (u + h) / 2h in [0, 1]^n, and t_i -> 1 - t_i where m_i > 0, f > 0 where
  // sum 2 |m_i| h_i t_i < value + sum (|m_i| - r_i) h_i.
  std::array<double, 3> slopes{};
  double budget = value;
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    if (!(half_width[i] > 0.0)) continue;
    const double lower = gradient[i].lower(), upper = gradient[i].upper();
    const double middle = 0.5 * (lower + upper);
    // Rounded up past both ends.
    const double radius = std::max(upper - middle, middle - lower) * (1.0 + 4.0 * std::numeric_limits<double>::epsilon());
    budget += (std::abs(middle) - radius) * half_width[i];
    slopes[n++] = 2.0 * std::abs(middle) * half_width[i];
  }
  if (!std::isfinite(budget)) return 0.0;
  for (int j = 0; j < n; ++j) {
    if (!std::isfinite(slopes[j])) return 0.0;
  }
  if (n == 0) return value > 0.0 ? 1.0 : 0.0;
  return unitCubeBelowPlane(budget, slopes, n);
}

}  // namespace maximal_workspace
