#include "kinematics/segment_distance.h"

#include "model/vector_kernel.h"

namespace maximal_workspace {

namespace {

// Lines within ~1e-15 rad of parallel (sin^2 of the angle below 1e-30, about the angular
// resolution of a double) are taken as parallel: the fallback below is then off by at most
// ~1e-15 of the segments' length. Any smaller positive threshold would do as well.
constexpr double kParallel = 1e-30;
// Squared lengths at or below this are points. Any positive threshold keeps 1/a finite;
// this one is far below any rod and far above the subnormals.
constexpr double kPoint = 1e-200;

// Ternaries, not std::min/max: those are not inlined into the AVX2 clone (another target),
// and a call in the loop stops vectorisation. GCC turns these into max/min instructions.
[[gnu::always_inline]] inline double clamp01(double x) {
  const double y = x > 0.0 ? x : 0.0;
  return y < 1.0 ? y : 1.0;
}

// Minimises |w + s u - t v|^2 over s, t in [0, 1], with u = a1 - a0, v = b1 - b0 and
// w = a0 - b0. Both the scalar and the batch entry points call this, so they agree.
// Branch-free: every choice is a select, and divisors are made safe before dividing, so
// the lanes not selected never make NaN either.
[[gnu::always_inline]] inline double distanceSquared(double ax0, double ay0, double az0, double ax1, double ay1,
                                                     double az1, double bx0, double by0, double bz0, double bx1,
                                                     double by1, double bz1) {
  const double ux = ax1 - ax0, uy = ay1 - ay0, uz = az1 - az0;
  const double vx = bx1 - bx0, vy = by1 - by0, vz = bz1 - bz0;
  const double wx = ax0 - bx0, wy = ay0 - by0, wz = az0 - bz0;
  const double a = ux * ux + uy * uy + uz * uz;
  const double b = ux * vx + uy * vy + uz * vz;
  const double e = vx * vx + vy * vy + vz * vz;
  const double c = ux * wx + uy * wy + uz * wz;
  const double f = vx * wx + vy * wy + vz * wz;
  // A point segment contributes no term: its parameter stays 0.
  const double inv_a = a > kPoint ? 1.0 / a : 0.0;
  const double inv_e = e > kPoint ? 1.0 / e : 0.0;
  // Pass 1: s of the closest points of the two lines, (bf - ce) / (ae - b^2), clamped. Both
  // are written with n = u x v: ae - b^2 = |n|^2 and bf - ce = n.(v x w). For nearly
  // parallel lines the dot-product forms lose their digits to cancellation (relative error
  // ~eps/angle^2), the cross products far fewer: against exact rational arithmetic, FCL's
  // dot-product form was off by up to 1.4e-9 m at angles near 1e-9 rad, this by 2e-16.
  const double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
  const double px = vy * wz - vz * wy, py = vz * wx - vx * wz, pz = vx * wy - vy * wx;
  const double denom = nx * nx + ny * ny + nz * nz;
  // (Near-)parallel lines, including any point segment (n = 0): every s is then about as
  // good, as pass 2 finds the nearest points of the two segments from any s; take s = 0.
  const bool skew = denom > kParallel * a * e;
  const double s0 = skew ? clamp01((nx * px + ny * py + nz * pz) / (skew ? denom : 1.0)) : 0.0;
  // Pass 2: the best t for that s, clamped; then the best s for that t, clamped. Where t
  // needed no clamp, s is already that best s (the minimum is a stationary point in s),
  // so recomputing it unconditionally changes nothing and saves a branch.
  const double t = clamp01((b * s0 + f) * inv_e);
  const double s = clamp01((b * t - c) * inv_a);
  const double dx = wx + s * ux - t * vx, dy = wy + s * uy - t * vy, dz = wz + s * uz - t * vz;
  return dx * dx + dy * dy + dz * dz;
}

MOW_VECTOR_KERNEL void distancesSquared(std::size_t count, const double* __restrict ax0, const double* __restrict ay0,
                                        const double* __restrict az0, const double* __restrict ax1,
                                        const double* __restrict ay1, const double* __restrict az1,
                                        const double* __restrict bx0, const double* __restrict by0,
                                        const double* __restrict bz0, const double* __restrict bx1,
                                        const double* __restrict by1, const double* __restrict bz1,
                                        const double shift[3], double* __restrict out) {
  const double sx = shift[0], sy = shift[1], sz = shift[2];
  for (std::size_t i = 0; i < count; ++i) {
    out[i] = distanceSquared(ax0[i], ay0[i], az0[i], ax1[i], ay1[i], az1[i], bx0[i] + sx, by0[i] + sy, bz0[i] + sz,
                             bx1[i] + sx, by1[i] + sy, bz1[i] + sz);
  }
}

}  // namespace

double segmentDistanceSquared(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& b0,
                              const Eigen::Vector3d& b1) {
  return distanceSquared(a0.x(), a0.y(), a0.z(), a1.x(), a1.y(), a1.z(), b0.x(), b0.y(), b0.z(), b1.x(), b1.y(),
                         b1.z());
}

void segmentDistancesSquared(std::size_t count, const SegmentBatch& a, const SegmentBatch& b, double* out,
                             const Eigen::Vector3d& b_shift) {
  distancesSquared(count, a.x0, a.y0, a.z0, a.x1, a.y1, a.z1, b.x0, b.y0, b.z0, b.x1, b.y1, b.z1, b_shift.data(), out);
}

}  // namespace maximal_workspace
