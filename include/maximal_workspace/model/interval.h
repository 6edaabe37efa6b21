#pragma once
// Interval arithmetic for enclosures (docs/kinematics.md, "What the enclosures prove"):
// Boost.Interval with bounds rounded outward, and the few vector operations the chains
// and the certificate need.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <boost/numeric/interval.hpp>

namespace maximal_workspace {

namespace interval_detail {
// Each bound is the round-to-nearest result moved outward by at least one ulp:
// |x| 2^-52 is at least ulp(x), and the denormal minimum covers results near zero. IEEE
// operations and sqrt are correctly rounded (within half an ulp of the exact value), so
// the bound holds without switching the FPU's rounding mode per operation. (A fused
// multiply-add the compiler forms only makes the moved result closer to the exact one.)
struct OutwardRounding : boost::numeric::interval_lib::rounded_arith_exact<double> {
  static double down(double x) { return x - (std::abs(x) * 0x1p-52 + std::numeric_limits<double>::denorm_min()); }
  static double up(double x) { return x + (std::abs(x) * 0x1p-52 + std::numeric_limits<double>::denorm_min()); }
  double add_down(double x, double y) { return down(x + y); }
  double add_up(double x, double y) { return up(x + y); }
  double sub_down(double x, double y) { return down(x - y); }
  double sub_up(double x, double y) { return up(x - y); }
  double mul_down(double x, double y) { return down(x * y); }
  double mul_up(double x, double y) { return up(x * y); }
  double div_down(double x, double y) { return down(x / y); }
  double div_up(double x, double y) { return up(x / y); }
  double sqrt_down(double x) { return x <= 0.0 ? 0.0 : std::max(0.0, down(std::sqrt(x))); }
  double sqrt_up(double x) { return x <= 0.0 ? 0.0 : up(std::sqrt(x)); }
};
}  // namespace interval_detail

using Interval = boost::numeric::interval<
    double, boost::numeric::interval_lib::policies<
                boost::numeric::interval_lib::save_state_nothing<interval_detail::OutwardRounding>,
                boost::numeric::interval_lib::checking_base<double>>>;

// A point of R^3 known to lie in a box.
using IntervalPoint = std::array<Interval, 3>;

inline IntervalPoint operator+(const IntervalPoint& a, const IntervalPoint& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline IntervalPoint operator-(const IntervalPoint& a, const IntervalPoint& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline IntervalPoint operator*(const Interval& s, const IntervalPoint& a) { return {s * a[0], s * a[1], s * a[2]}; }
inline Interval dot(const IntervalPoint& a, const IntervalPoint& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline IntervalPoint cross(const IntervalPoint& a, const IntervalPoint& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
// |a|^2 with each coordinate squared as one operation (tighter than a . a).
inline Interval squaredNorm(const IntervalPoint& a) {
  using boost::numeric::square;
  return square(a[0]) + square(a[1]) + square(a[2]);
}
// The degenerate box of a double point, and a double point's coordinates as intervals.
template <class Vector>
IntervalPoint pointInterval(const Vector& v) {
  return {Interval(v[0]), Interval(v[1]), Interval(v[2])};
}
// cos and sin over an interval of angles, enclosing the libm result's rounding.
Interval intervalCos(const Interval& angle);
Interval intervalSin(const Interval& angle);

}  // namespace maximal_workspace
