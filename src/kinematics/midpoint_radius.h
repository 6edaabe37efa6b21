#pragma once
// Intervals in midpoint-radius form for the certificate's inner loop, the gradients of
// det(G) and det(D) of every working mode (kinematics/measure_certificate.cpp): sums of
// products with no branch on the bounds' signs, where Boost.Interval's product tests
// them. The bounds follow Rump ("Fast and parallel interval arithmetic", BIT 39, 1999):
// for x in <a, alpha> and y in <b, beta>, |x y - a b| <= |a| beta + alpha (|b| + beta), and
// a sum of n products computed in round-to-nearest is within gamma_n of the exact one,
// gamma_n = n u / (1 - n u) (u = 2^-53) times the sum of the products' magnitudes. Every
// radius is computed in round-to-nearest from non-negative terms and then enlarged by a
// relative 2^-46, more than the rounding of the few dozen operations it took, plus the
// smallest denormal per product for underflow.

#include <algorithm>
#include <cmath>
#include <limits>

#include "maximal_workspace/model/interval.h"

namespace maximal_workspace {

struct Ball {
  double mid = 0.0, rad = 0.0;
};

// <mid, rad> holding the interval.
inline Ball toBall(const Interval& x) {
  const double mid = 0.5 * (x.lower() + x.upper());
  const double rad = std::max(mid - x.lower(), x.upper() - mid);
  return {mid, rad * (1.0 + 0x1p-50) + std::numeric_limits<double>::denorm_min()};
}

inline Interval toInterval(const Ball& x) {
  return Interval(interval_detail::OutwardRounding::down(x.mid - x.rad),
                  interval_detail::OutwardRounding::up(x.mid + x.rad));
}

// Accumulates sum_i a_i b_i over balls; `result` encloses the exact sum over every
// x_i in a_i, y_i in b_i. Up to 64 products: the 2^-46 enlargement covers the rounding of
// that many.
class BallDot {
 public:
  void add(const Ball& a, const Ball& b) {
    const double product = a.mid * b.mid;
    mid_ += product;
    magnitudes_ += std::abs(product);
    rad_ += std::abs(a.mid) * b.rad + a.rad * (std::abs(b.mid) + b.rad);
    ++terms_;
  }
  Ball result() const {
    // gamma_n < (n + 1) u for n u < 1/64; the products' own rounding is another u each.
    const double rounding = (terms_ + 2) * 0x1p-53 * magnitudes_;
    return {mid_, (rad_ + rounding) * (1.0 + 0x1p-46) + terms_ * std::numeric_limits<double>::denorm_min()};
  }

 private:
  double mid_ = 0.0, magnitudes_ = 0.0, rad_ = 0.0;
  int terms_ = 0;
};

// a x b of two 3-vectors of balls.
inline void cross(const Ball* a, const Ball* b, Ball* out) {
  for (int c = 0; c < 3; ++c) {
    const int i = (c + 1) % 3, j = (c + 2) % 3;
    BallDot sum;
    sum.add(a[i], b[j]);
    sum.add(a[j], Ball{-b[i].mid, b[i].rad});
    out[c] = sum.result();
  }
}

// The largest |x| over the ball, rounded up, and the smallest, rounded down (0 when it
// holds 0).
inline double magnitude(const Ball& x) { return interval_detail::OutwardRounding::up(std::abs(x.mid) + x.rad); }
inline double mignitude(const Ball& x) {
  return std::max(0.0, interval_detail::OutwardRounding::down(std::abs(x.mid) - x.rad));
}

}  // namespace maximal_workspace
