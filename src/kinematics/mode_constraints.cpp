#include "kinematics/mode_constraints.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "kinematics/segment_distance.h"
#include "maximal_workspace/kinematics/constraints.h"
#include "model/vector_kernel.h"

namespace maximal_workspace {

namespace {

// ok[i] becomes 0 where normal . a + offset < 0.
MOW_VECTOR_KERNEL void halfSpaceTest(std::size_t count, const double* __restrict ax, const double* __restrict ay,
                                     const double* __restrict az, const double normal[3], double offset,
                                     double* __restrict ok) {
  const double nx = normal[0], ny = normal[1], nz = normal[2];
  for (std::size_t i = 0; i < count; ++i) ok[i] = nx * ax[i] + ny * ay[i] + nz * az[i] + offset >= 0.0 ? ok[i] : 0.0;
}

// The fixed end: (p - a) . (linear a + offset) >= R cos(half_angle), |p - a| being R.
MOW_VECTOR_KERNEL void fixedConeTest(std::size_t count, const double* __restrict px, const double* __restrict py,
                                     const double* __restrict pz, const double* __restrict ax,
                                     const double* __restrict ay, const double* __restrict az, const double m[9],
                                     const double k[3], double minimum, double* __restrict ok) {
  for (std::size_t i = 0; i < count; ++i) {
    const double x = ax[i], y = ay[i], z = az[i];
    const double wx = m[0] * x + m[1] * y + m[2] * z + k[0];
    const double wy = m[3] * x + m[4] * y + m[5] * z + k[1];
    const double wz = m[6] * x + m[7] * y + m[8] * z + k[2];
    const double along = (px[i] - x) * wx + (py[i] - y) * wy + (pz[i] - z) * wz;
    ok[i] = along >= minimum ? ok[i] : 0.0;
  }
}

// The same for an axis that does not turn with a (a slider's): (p - a) . w >= minimum.
MOW_VECTOR_KERNEL void constantConeTest(std::size_t count, const double* __restrict px, const double* __restrict py,
                                        const double* __restrict pz, const double* __restrict ax,
                                        const double* __restrict ay, const double* __restrict az, const double w[3],
                                        double minimum, double* __restrict ok) {
  const double wx = w[0], wy = w[1], wz = w[2];
  for (std::size_t i = 0; i < count; ++i) {
    const double along = (px[i] - ax[i]) * wx + (py[i] - ay[i]) * wy + (pz[i] - az[i]) * wz;
    ok[i] = along >= minimum ? ok[i] : 0.0;
  }
}

// The platform end: (a - p) . w >= R cos(half_angle), w the cone's axis in the base frame.
MOW_VECTOR_KERNEL void platformConeTest(std::size_t count, const double* __restrict px, const double* __restrict py,
                                        const double* __restrict pz, const double* __restrict ax,
                                        const double* __restrict ay, const double* __restrict az,
                                        const double* __restrict wx, const double* __restrict wy,
                                        const double* __restrict wz, double minimum, double* __restrict ok) {
  for (std::size_t i = 0; i < count; ++i) {
    const double along = (ax[i] - px[i]) * wx[i] + (ay[i] - py[i]) * wy[i] + (az[i] - pz[i]) * wz[i];
    ok[i] = along >= minimum ? ok[i] : 0.0;
  }
}

// The rods of a couple in one branch are translates by o = p2 - p1: their distance is
// min over tau in [-1, 1] of |o + tau g|, g = p1 - a1. The second rod's arrays are moved
// by `shift`.
MOW_VECTOR_KERNEL void translateDistances(std::size_t count, const double* __restrict px, const double* __restrict py,
                                          const double* __restrict pz, const double* __restrict ax,
                                          const double* __restrict ay, const double* __restrict az,
                                          const double* __restrict qx, const double* __restrict qy,
                                          const double* __restrict qz, const double shift[3],
                                          double* __restrict distance2) {
  const double sx = shift[0], sy = shift[1], sz = shift[2];
  for (std::size_t i = 0; i < count; ++i) {
    const double gx = px[i] - ax[i], gy = py[i] - ay[i], gz = pz[i] - az[i];
    const double ox = qx[i] + sx - px[i], oy = qy[i] + sy - py[i], oz = qz[i] + sz - pz[i];
    const double g2 = gx * gx + gy * gy + gz * gz;
    double tau = -(ox * gx + oy * gy + oz * gz) / (g2 > 0.0 ? g2 : 1.0);
    tau = tau > -1.0 ? tau : -1.0;
    tau = tau < 1.0 ? tau : 1.0;
    const double dx = ox + tau * gx, dy = oy + tau * gy, dz = oz + tau * gz;
    distance2[i] = dx * dx + dy * dy + dz * dz;
  }
}

// Two lower bounds of the distance of two segments, without a division: the gap between
// their bounding boxes along an axis, and the distance of their lines, |w . n| / |n| with
// n = u x v (0 for parallel lines). clear[i] is 1 where either already keeps `minimum`
// (squared): rods of different legs are mostly told apart by one or the other. The second
// rod's arrays are moved by `shift`.
MOW_VECTOR_KERNEL void cheapClears(std::size_t count, const double* __restrict ax, const double* __restrict ay,
                                   const double* __restrict az, const double* __restrict px,
                                   const double* __restrict py, const double* __restrict pz,
                                   const double* __restrict bx, const double* __restrict by,
                                   const double* __restrict bz, const double* __restrict qx,
                                   const double* __restrict qy, const double* __restrict qz, const double shift[3],
                                   double minimum, double* __restrict clear) {
  const double sx = shift[0], sy = shift[1], sz = shift[2];
  const auto gap = [](double a0, double a1, double b0, double b1) {
    const double a_low = a0 < a1 ? a0 : a1, a_high = a0 < a1 ? a1 : a0;
    const double b_low = b0 < b1 ? b0 : b1, b_high = b0 < b1 ? b1 : b0;
    const double first = b_low - a_high, second = a_low - b_high;
    const double larger = first > second ? first : second;
    return larger > 0.0 ? larger : 0.0;
  };
  for (std::size_t i = 0; i < count; ++i) {
    const double b0x = bx[i] + sx, b0y = by[i] + sy, b0z = bz[i] + sz;
    const double b1x = qx[i] + sx, b1y = qy[i] + sy, b1z = qz[i] + sz;
    const double gx = gap(ax[i], px[i], b0x, b1x), gy = gap(ay[i], py[i], b0y, b1y), gz = gap(az[i], pz[i], b0z, b1z);
    const double box = (gx > gy ? gx : gy) > gz ? (gx > gy ? gx : gy) : gz;
    const double ux = px[i] - ax[i], uy = py[i] - ay[i], uz = pz[i] - az[i];
    const double vx = b1x - b0x, vy = b1y - b0y, vz = b1z - b0z;
    const double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    const double along = (b0x - ax[i]) * nx + (b0y - ay[i]) * ny + (b0z - az[i]) * nz;
    const bool lines_apart = along * along >= minimum * (nx * nx + ny * ny + nz * nz);
    clear[i] = box * box >= minimum || lines_apart ? 1.0 : 0.0;
  }
}

// The box holding a rod (a to p) at every pose of the block: pairs of rods whose boxes are
// apart by the distance they must keep need no pose-by-pose check. Blocks are runs of
// neighbouring cells, so their boxes are tight.
struct RodBox {
  double low[3], high[3];
};

// The box of a rod over a run, in one pass over its six arrays; eight running minima and
// maxima per coordinate, not one: a reduction the compiler keeps in vector registers
// without reordering floating-point operations.
MOW_VECTOR_KERNEL void rodExtent(std::size_t count, const double* __restrict ax, const double* __restrict ay,
                                 const double* __restrict az, const double* __restrict px,
                                 const double* __restrict py, const double* __restrict pz, double* low, double* high) {
  constexpr std::size_t kLanes = 8;
  const double* const a[3] = {ax, ay, az};
  const double* const p[3] = {px, py, pz};
  for (int k = 0; k < 3; ++k) {
    double lows[kLanes], highs[kLanes];
    for (std::size_t j = 0; j < kLanes; ++j) lows[j] = INFINITY, highs[j] = -INFINITY;
    std::size_t i = 0;
    for (; i + kLanes <= count; i += kLanes) {
      for (std::size_t j = 0; j < kLanes; ++j) {
        const double u = a[k][i + j], v = p[k][i + j];
        const double smaller = u < v ? u : v, larger = u < v ? v : u;
        lows[j] = smaller < lows[j] ? smaller : lows[j];
        highs[j] = larger > highs[j] ? larger : highs[j];
      }
    }
    for (; i < count; ++i) {
      lows[0] = std::min({lows[0], a[k][i], p[k][i]});
      highs[0] = std::max({highs[0], a[k][i], p[k][i]});
    }
    low[k] = *std::min_element(lows, lows + kLanes);
    high[k] = *std::max_element(highs, highs + kLanes);
  }
}

RodBox rodBox(std::size_t count, const double* const* a, const double* const* p) {
  RodBox box;
  rodExtent(count, a[0], a[1], a[2], p[0], p[1], p[2], box.low, box.high);
  return box;
}

double boxGap(const RodBox& first, const RodBox& second) {
  double gap = 0.0;
  for (int k = 0; k < 3; ++k) gap = std::max({gap, second.low[k] - first.high[k], first.low[k] - second.high[k]});
  return gap;
}

// Clears `modes` from admissible[i] where ok[i] is 0; returns the modes still possible
// somewhere in the block, so checks no pose needs any more are skipped.
MOW_VECTOR_KERNEL std::uint64_t clearModes(std::size_t count, const double* __restrict ok, std::uint64_t modes,
                                           std::uint64_t* __restrict admissible) {
  std::uint64_t possible = 0;
  for (std::size_t i = 0; i < count; ++i) {
    admissible[i] &= ok[i] != 0.0 ? ~std::uint64_t{0} : ~modes;
    possible |= admissible[i];
  }
  return possible;
}

// What the proofs over a box leave to rounding: a check is decided only beyond this (m;
// the cones' products are in m too, their axes being unit vectors), so that the classifier's
// double-precision checks at the poses of the box agree with it.
constexpr double kLimitSlack = 1e-9;

// +1 where x >= minimum at every pose of the box, -1 where at none, 0 undecided.
int verdict(const Interval& x, double minimum) {
  if (x.lower() > minimum + kLimitSlack) return 1;
  if (x.upper() < minimum - kLimitSlack) return -1;
  return 0;
}

// How far a point of the box can be from `centre` (a point of it), rounded up.
double farthest(const IntervalPoint& box, const Eigen::Vector3d& centre) {
  double squared = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double away = std::max(centre[k] - box[k].lower(), box[k].upper() - centre[k]);
    squared += away * away;
  }
  return std::sqrt(squared) * (1.0 + 1e-12);
}

}  // namespace

ModeConstraints::ModeConstraints(const RobotModel& model, const std::vector<WorkingMode>& modes,
                                 bool couples_translate)
    : platform_cone_(model.chainCount(), false) {
  all_modes_ = modes.size() >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << modes.size()) - 1;
  const auto modesTaking = [&modes](int chain, int branch) {
    std::uint64_t mask = 0;
    for (std::size_t m = 0; m < modes.size(); ++m) {
      if (static_cast<int>(modes[m].branch(chain)) == branch) mask |= std::uint64_t{1} << m;
    }
    return mask;
  };
  for (int c = 0; c < model.chainCount(); ++c) {
    const Chain& chain = *model.chains[c];
    const auto& range = model.inputs[model.chain_input[c]].limits;
    const ChainLimits& limits = chain.limits();
    platform_cone_[c] = limits.platform_end.has_value();
    for (int b = 0; b < 2; ++b) {
      BranchCheck check;
      check.chain = c;
      check.branch = b;
      if (range) check.input_range = chain.inputRange(*range);
      if (limits.fixed_end) {
        check.fixed_cone = true;
        check.fixed_axis = chain.fixedEndAxis(limits.fixed_end->axis);
        check.fixed_cos = chain.rodLength() * std::cos(limits.fixed_end->half_angle);
      }
      if (limits.platform_end) {
        check.platform_cone = true;
        check.platform_cos = chain.rodLength() * std::cos(limits.platform_end->half_angle);
      }
      check.modes = modesTaking(c, b);
      if (check.modes != 0 && (!check.input_range.empty() || check.fixed_cone || check.platform_cone)) {
        branch_checks_.push_back(std::move(check));
      }
    }
  }
  const RobotConstraints constraints(model);
  for (int c = 0; c < model.chainCount(); ++c) {
    for (int d = c + 1; d < model.chainCount(); ++d) {
      if (!constraints.checksPair(c, d)) continue;
      for (int bc = 0; bc < 2; ++bc) {
        for (int bd = 0; bd < 2; ++bd) {
          const double distance = constraints.pairDistance(c, d);
          const bool translates = couples_translate && bc == bd && model.chain_input[c] == model.chain_input[d];
          PairCheck check{{c, d}, {bc, bd}, distance * distance, modesTaking(c, bc) & modesTaking(d, bd), translates};
          if (check.modes != 0) pair_checks_.push_back(check);
        }
      }
    }
  }
}

bool ModeConstraints::hasPlatformCone(int chain) const { return platform_cone_[chain]; }

void ModeConstraints::admissible(std::size_t count, const ChainBlock* chains, const std::uint8_t* assembled,
                                 std::uint64_t* admissible) const {
  std::uint64_t possible = 0;
  for (std::size_t i = 0; i < count; ++i) {
    admissible[i] = assembled[i] ? all_modes_ : 0;
    possible |= admissible[i];
  }
  double ok[kConstraintBlock];
  for (const BranchCheck& check : branch_checks_) {
    if ((possible & check.modes) == 0) continue;
    const ChainBlock& chain = chains[check.chain];
    const double* const* a = chain.a[check.branch];
    for (std::size_t i = 0; i < count; ++i) ok[i] = 1.0;
    // The arrays hold a - shift: the tests' constants take the shift instead (p - a, which
    // the cones read, is the same).
    for (const NodeHalfSpace& half : check.input_range) {
      halfSpaceTest(count, a[0], a[1], a[2], half.normal.data(), half.offset + half.normal.dot(chain.shift), ok);
    }
    if (check.fixed_cone && check.fixed_axis.linear.isZero()) {
      constantConeTest(count, chain.p[0], chain.p[1], chain.p[2], a[0], a[1], a[2], check.fixed_axis.offset.data(),
                       check.fixed_cos, ok);
    } else if (check.fixed_cone) {
      double m[9];
      for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k) m[3 * r + k] = check.fixed_axis.linear(r, k);
      }
      const Eigen::Vector3d offset = check.fixed_axis.offset + check.fixed_axis.linear * chain.shift;
      fixedConeTest(count, chain.p[0], chain.p[1], chain.p[2], a[0], a[1], a[2], m, offset.data(), check.fixed_cos, ok);
    }
    if (check.platform_cone) {
      platformConeTest(count, chain.p[0], chain.p[1], chain.p[2], a[0], a[1], a[2], chain.platform_axis[0],
                       chain.platform_axis[1], chain.platform_axis[2], check.platform_cos, ok);
    }
    possible = clearModes(count, ok, check.modes, admissible);
  }
  // Rods are checked over runs of poses: along a run of neighbouring cells a rod moves
  // little, so the boxes of most pairs of rods are apart.
  for (std::size_t begin = 0; begin < count && possible != 0; begin += kRodRun) {
    checkRods(begin, std::min(kRodRun, count - begin), chains, admissible + begin);
  }
}

void ModeConstraints::checkRods(std::size_t begin, std::size_t count, const ChainBlock* chains,
                                std::uint64_t* admissible) const {
  std::uint64_t possible = 0;
  for (std::size_t i = 0; i < count; ++i) possible |= admissible[i];
  // The run's arrays: a chain's p, and its a in either branch, from `begin` on.
  const auto run = [begin](const double* const* xyz, std::array<const double*, 3>& out) {
    for (int k = 0; k < 3; ++k) out[k] = xyz[k] + begin;
  };
  // The box of each chain and branch over the run, made once per array: a couple's two
  // chains share theirs, shifted.
  std::array<std::array<RodBox, 2>, kMaxChains> boxes;
  std::array<std::array<bool, 2>, kMaxChains> boxed{};
  const auto boxOf = [&](int chain, int branch) -> RodBox {
    const ChainBlock& block = chains[chain];
    int source = chain;
    for (int other = 0; other < chain; ++other) {
      if (chains[other].p[0] == block.p[0] && chains[other].a[branch][0] == block.a[branch][0]) source = other;
    }
    if (!boxed[source][branch]) {
      std::array<const double*, 3> p, a;
      run(block.p, p);
      run(block.a[branch], a);
      boxes[source][branch] = rodBox(count, a.data(), p.data());
      boxed[source][branch] = true;
    }
    RodBox box = boxes[source][branch];
    for (int k = 0; k < 3; ++k) box.low[k] += block.shift[k], box.high[k] += block.shift[k];
    return box;
  };
  double ok[kRodRun], distance2[kRodRun];
  for (const PairCheck& check : pair_checks_) {
    if ((possible & check.modes) == 0) continue;
    std::array<const double*, 3> p0, a0, p1, a1;
    run(chains[check.chains[0]].p, p0);
    run(chains[check.chains[0]].a[check.branches[0]], a0);
    run(chains[check.chains[1]].p, p1);
    run(chains[check.chains[1]].a[check.branches[1]], a1);
    const double gap = boxGap(boxOf(check.chains[0], check.branches[0]), boxOf(check.chains[1], check.branches[1]));
    if (gap * gap >= check.distance2) continue;
    // Distances do not change under a common translation: the second rod moves by the
    // difference of the shifts.
    const Eigen::Vector3d shift = chains[check.chains[1]].shift - chains[check.chains[0]].shift;
    if (check.translates) {
      translateDistances(count, p0[0], p0[1], p0[2], a0[0], a0[1], a0[2], p1[0], p1[1], p1[2], shift.data(), distance2);
    } else {
      cheapClears(count, a0[0], a0[1], a0[2], p0[0], p0[1], p0[2], a1[0], a1[1], a1[2], p1[0], p1[1], p1[2],
                  shift.data(), check.distance2, ok);
      bool all_clear = true;
      for (std::size_t i = 0; i < count; ++i) all_clear = all_clear && (ok[i] != 0.0 || (admissible[i] & check.modes) == 0);
      if (all_clear) continue;
      segmentDistancesSquared(count, SegmentBatch{a0[0], a0[1], a0[2], p0[0], p0[1], p0[2]},
                              SegmentBatch{a1[0], a1[1], a1[2], p1[0], p1[1], p1[2]}, distance2, shift);
    }
    for (std::size_t i = 0; i < count; ++i) ok[i] = distance2[i] >= check.distance2 ? 1.0 : 0.0;
    possible = clearModes(count, ok, check.modes, admissible);
  }
}

BoxLimits ModeConstraints::overBox(const ChainBox* chains, bool couples_translate) const {
  BoxLimits result{all_modes_, 0};
  const auto apply = [&result](int checked, std::uint64_t modes) {
    if (checked <= 0) result.kept &= ~modes;
    if (checked < 0) result.broken |= modes;
  };
  for (const BranchCheck& check : branch_checks_) {
    const ChainBox& chain = chains[check.chain];
    const IntervalPoint& a = chain.a[check.branch];
    // Every check must hold; one failing at every pose breaks the branch there.
    int checked = 1;
    for (const NodeHalfSpace& half : check.input_range) {
      checked = std::min(checked, verdict(dot(pointInterval(half.normal), a) + Interval(half.offset), 0.0));
    }
    if (check.fixed_cone) {
      IntervalPoint axis;
      for (int r = 0; r < 3; ++r) {
        axis[r] = Interval(check.fixed_axis.offset[r]) + dot(pointInterval(check.fixed_axis.linear.row(r)), a);
      }
      checked = std::min(checked, verdict(dot(chain.p - a, axis), check.fixed_cos));
    }
    if (check.platform_cone) checked = std::min(checked, verdict(dot(a - chain.p, chain.platform_axis), check.platform_cos));
    apply(checked, check.modes);
  }
  for (const PairCheck& check : pair_checks_) {
    const ChainBox &first = chains[check.chains[0]], &second = chains[check.chains[1]];
    const int b0 = check.branches[0], b1 = check.branches[1];
    const double required = std::sqrt(check.distance2);
    if (check.translates && couples_translate) {
      // Parallel rods g a constant o apart: their distance is at least |o x g| / |g|.
      const IntervalPoint offset = pointInterval(Eigen::Vector3d(second.p_centre - first.p_centre));
      const Interval apart = sqrt(squaredNorm(cross(offset, first.p - first.a[b0]))) / Interval(first.rod_length);
      if (apart.lower() > required + kLimitSlack) continue;
    }
    // Moving a segment's ends by at most e moves each of its points by at most e, so the
    // distance of two rods changes by at most the sum of their ends' largest moves. Where
    // the orientation is fixed, both rods seen from the platform (moved back by the TCP's
    // move, which leaves their distance) keep their platform end: only a moves, by the
    // rod's turn.
    const double at_centre = std::sqrt(
        segmentDistanceSquared(first.a_centre[b0], first.p_centre, second.a_centre[b1], second.p_centre));
    const double moves =
        std::isfinite(first.rod_moves[b0]) && std::isfinite(second.rod_moves[b1])
            ? first.rod_moves[b0] + second.rod_moves[b1]
            : std::max(farthest(first.a[b0], first.a_centre[b0]), farthest(first.p, first.p_centre)) +
                  std::max(farthest(second.a[b1], second.a_centre[b1]), farthest(second.p, second.p_centre));
    apply(at_centre - moves > required + kLimitSlack ? 1 : at_centre + moves < required - kLimitSlack ? -1 : 0,
          check.modes);
  }
  return result;
}

}  // namespace maximal_workspace
