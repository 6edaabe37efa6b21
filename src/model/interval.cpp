#include "maximal_workspace/model/interval.h"

#include <cmath>
#include <limits>

namespace maximal_workspace {

namespace {

// glibc's cos and sin are within one ulp; four ulps of 1 cover that and the argument's
// own rounding to a double.
constexpr double kTrigSlack = 4.0 * std::numeric_limits<double>::epsilon();

// cos over [lo, hi]: the ends, and +/-1 where a multiple of pi lies inside.
Interval cosOver(double lo, double hi) {
  if (hi - lo >= 2.0 * M_PI) return Interval(-1.0, 1.0);
  double low = std::min(std::cos(lo), std::cos(hi)), high = std::max(std::cos(lo), std::cos(hi));
  const double first = std::ceil(lo / M_PI), last = std::floor(hi / M_PI);
  for (double k = first; k <= last; k += 1.0) {
    if (std::fmod(std::abs(k), 2.0) == 0.0) high = 1.0;
    else low = -1.0;
  }
  // k pi rounded may miss an extremum just outside [lo, hi]: the slack covers it too, since
  // cos is flat there.
  return Interval(std::max(-1.0, low - kTrigSlack), std::min(1.0, high + kTrigSlack));
}

}  // namespace

Interval intervalCos(const Interval& angle) { return cosOver(angle.lower(), angle.upper()); }
Interval intervalSin(const Interval& angle) {
  // sin x = cos(x - pi/2); the subtraction's rounding is within the slack.
  return cosOver(angle.lower() - M_PI_2, angle.upper() - M_PI_2);
}

}  // namespace maximal_workspace
