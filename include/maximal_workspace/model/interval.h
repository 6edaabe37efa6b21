#pragma once
// Interval arithmetic for enclosures (docs/kinematics.md, "What the enclosures prove"):
// Boost.Interval with bounds rounded outward, and the few vector operations the chains
// and the certificate need.

#include <array>

#include <boost/numeric/interval.hpp>

namespace maximal_workspace {

namespace interval_detail {
// Each bound is the round-to-nearest result moved one ulp outward. IEEE operations and
// sqrt are correctly rounded (within half an ulp of the exact value), so the bound holds
// without switching the FPU's rounding mode per operation.
struct OutwardRounding : boost::numeric::interval_lib::rounded_arith_exact<double> {
  static double down(double x);
  static double up(double x);
  double add_down(double x, double y) { return down(x + y); }
  double add_up(double x, double y) { return up(x + y); }
  double sub_down(double x, double y) { return down(x - y); }
  double sub_up(double x, double y) { return up(x - y); }
  double mul_down(double x, double y) { return down(x * y); }
  double mul_up(double x, double y) { return up(x * y); }
  double div_down(double x, double y) { return down(x / y); }
  double div_up(double x, double y) { return up(x / y); }
  double sqrt_down(double x);
  double sqrt_up(double x);
};
}  // namespace interval_detail

using Interval = boost::numeric::interval<
    double, boost::numeric::interval_lib::policies<
                boost::numeric::interval_lib::save_state_nothing<interval_detail::OutwardRounding>,
                boost::numeric::interval_lib::checking_base<double>>>;

// A point of R^3 known to lie in a box.
using IntervalPoint = std::array<Interval, 3>;

IntervalPoint operator+(const IntervalPoint& a, const IntervalPoint& b);
IntervalPoint operator-(const IntervalPoint& a, const IntervalPoint& b);
IntervalPoint operator*(const Interval& s, const IntervalPoint& a);
Interval dot(const IntervalPoint& a, const IntervalPoint& b);
IntervalPoint cross(const IntervalPoint& a, const IntervalPoint& b);
// |a|^2 with each coordinate squared as one operation (tighter than a . a).
Interval squaredNorm(const IntervalPoint& a);
// The degenerate box of a double point, and a double point's coordinates as intervals.
template <class Vector>
IntervalPoint pointInterval(const Vector& v) {
  return {Interval(v[0]), Interval(v[1]), Interval(v[2])};
}
// cos and sin over an interval of angles, enclosing the libm result's rounding.
Interval intervalCos(const Interval& angle);
Interval intervalSin(const Interval& angle);

}  // namespace maximal_workspace
