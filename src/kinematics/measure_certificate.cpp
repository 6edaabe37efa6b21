#include "maximal_workspace/kinematics/measure_certificate.h"

#include <cmath>
#include <atomic>
#include <cstring>
#include <limits>
#include <optional>

#include <Eigen/LU>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/jacobian.h"
#include "maximal_workspace/model/interval.h"
#include "kinematics/midpoint_radius.h"
#include "kinematics/mode_constraints.h"
#include "kinematics/proven_share.h"

namespace maximal_workspace {

namespace {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
using IntervalMatrix3 = std::array<IntervalPoint, 3>;  // rows

IntervalMatrix3 product(const IntervalMatrix3& a, const IntervalMatrix3& b) {
  IntervalMatrix3 result;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) result[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
  }
  return result;
}

IntervalMatrix3 aboutZ(const Interval& angle) {
  const Interval c = intervalCos(angle), s = intervalSin(angle), zero(0.0), one(1.0);
  return {{{c, -s, zero}, {s, c, zero}, {zero, zero, one}}};
}

Interval around(double centre, double half_width) { return Interval(centre) + Interval(-half_width, half_width); }

// The TCP positions of a box.
IntervalPoint positionEnclosure(const PoseBox& box) {
  IntervalPoint position;
  for (int k = 0; k < 3; ++k) position[k] = around(box.centre.position[k], box.position_half_width[k]);
  return position;
}

// A chain's discriminant over a box of translations (platform nodes `node`, `centre_node`
// at its centre): where its natural enclosure holds zero, narrowed by the mean-value form,
// the centre's value plus the gradient's reach over the box, whose excess over the true
// range is second order in the box's size (the natural form's is first order).
Interval narrowedDiscriminant(const Chain& chain, const Interval& natural, const IntervalPoint& node,
                              const IntervalPoint& centre_node, const Eigen::Vector3d& half_width) {
  if (natural.lower() > 0.0 || natural.upper() < 0.0) return natural;
  const IntervalPoint gradient = chain.discriminantGradientEnclosure(node);
  Interval mean_value = chain.discriminantEnclosure(centre_node);
  for (int k = 0; k < 3; ++k) mean_value += gradient[k] * Interval(-half_width[k], half_width[k]);
  return intersect(natural, mean_value);
}

// R = Rz(phi) Ry(theta) Rz(-phi) Rz(phi + psi): the tilt by theta about the horizontal axis
// at azimuth phi + 90 deg, then the turn phi + psi. The tilt's entries carry 1 - cos theta
// or sin theta, so near theta = 0 they hardly depend on phi; and over a tilt-and-torsion box
// phi + psi moves with the torsion alone. There the ZYZ product's excess was wide enough
// that most of a hexaglide's 6-D cells deep inside its workspace were left undecided.
IntervalMatrix3 tiltThenTurn(const Interval& phi, const Interval& theta, const Interval& phi_plus_psi) {
  using boost::numeric::square;
  const Interval c = intervalCos(phi), s = intervalSin(phi), ct = intervalCos(theta), st = intervalSin(theta), one(1.0);
  const Interval versine = Interval(2.0) * square(intervalSin(theta / 2.0));  // 1 - cos theta, no cancellation
  const Interval sine_cosine = Interval(0.5) * intervalSin(Interval(2.0) * phi);
  const IntervalMatrix3 tilt = {{{one - versine * square(c), -(versine * sine_cosine), st * c},
                                 {-(versine * sine_cosine), one - versine * square(s), st * s},
                                 {-(st * c), -(st * s), ct}}};
  return product(tilt, aboutZ(phi_plus_psi));
}

// R = Rz(phi) Ry(theta) Rz(psi) over the box's angles: both factorisations enclose it, and
// their intersection is tighter than either.
IntervalMatrix3 computedRotationEnclosure(const PoseBox& box) {
  std::array<Interval, 3> angle;
  for (int k = 0; k < 3; ++k) angle[k] = around(box.centre.euler_zyz[k], box.angle_half_width[k]);
  const Interval ct = intervalCos(angle[1]), st = intervalSin(angle[1]), zero(0.0), one(1.0);
  const IntervalMatrix3 about_y = {{{ct, zero, st}, {zero, one, zero}, {-st, zero, ct}}};
  IntervalMatrix3 result = product(product(aboutZ(angle[0]), about_y), aboutZ(angle[2]));
  const double sum_half_width =
      box.angle_sum_half_width.value_or(box.angle_half_width[0] + box.angle_half_width[2]);
  const IntervalMatrix3 tilted =
      tiltThenTurn(angle[0], angle[1], around(box.centre.euler_zyz[0] + box.centre.euler_zyz[2], sum_half_width));
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) result[i][j] = intersect(result[i][j], tilted[i][j]);
  }
  return result;
}

// A value computed from a box's angular range alone (for one owner), kept per thread: the
// boxes of a grid that turns the platform share a few thousand ranges between millions of
// positions, and the rotation's enclosure (six interval cosines and sines, two interval
// matrix products) and the nodes turned by it took half of a tilt-and-torsion
// classification. Direct-mapped: a collision only computes the value again.
template <class Value, class Compute>
Value perAngularRange(std::uint64_t owner, const PoseBox& box, const Compute& compute) {
  struct Slot {
    std::array<double, 7> key{};
    std::uint64_t owner = 0;
    bool used = false;
    Value value{};
  };
  constexpr std::size_t kSlots = 4096;
  thread_local std::vector<Slot> slots(kSlots);
  const std::array<double, 7> key = {box.centre.euler_zyz[0],   box.centre.euler_zyz[1],
                                     box.centre.euler_zyz[2],   box.angle_half_width[0],
                                     box.angle_half_width[1],   box.angle_half_width[2],
                                     box.angle_sum_half_width.value_or(-1.0)};
  std::uint64_t hash = 1469598103934665603ull ^ owner;
  for (double value : key) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    hash = (hash ^ bits) * 1099511628211ull;
    hash ^= hash >> 29;
  }
  Slot& slot = slots[hash % kSlots];
  if (!slot.used || slot.owner != owner || slot.key != key) {
    slot.value = compute();
    slot.key = key;
    slot.owner = owner;
    slot.used = true;
  }
  return slot.value;
}

IntervalMatrix3 rotationEnclosure(const PoseBox& box) {
  return perAngularRange<IntervalMatrix3>(0, box, [&] { return computedRotationEnclosure(box); });
}

// Certificates apart, whatever their addresses: the key of their cached values.
std::atomic<std::uint64_t> g_certificates{0};

IntervalPoint times(const IntervalMatrix3& m, const Eigen::Vector3d& v) {
  const IntervalPoint x = pointInterval(v);
  return {dot(m[0], x), dot(m[1], x), dot(m[2], x)};
}

double magnitude(const Interval& x) { return std::max(-x.lower(), x.upper()); }

using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxChains, kMaxChains>;

// Infinity norm of |a| |b| (entrywise absolute values), rounded up by a relative slack
// that covers the rounding of its at most 6 x 6 products and sums.
double absoluteProductNorm(const Matrix& a, const Matrix& b) {
  const Matrix absolute_product = a.cwiseAbs() * b.cwiseAbs();
  return absolute_product.rowwise().sum().maxCoeff() * (1.0 + 32.0 * kEpsilon);
}

// Columns l of dg/dp = I - t g^T / (g . t) over the box: how the rod g = p - a turns as the
// platform node p moves along axis l. Empty (false) where g . t may vanish: the box may
// touch the chain's IKP singularity, where the derivative is unbounded.
bool rodDerivative(const IntervalPoint& rod, const IntervalPoint& tangent, IntervalMatrix3& columns) {
  const Interval along = dot(rod, tangent);
  if (zero_in(along)) return false;
  for (int l = 0; l < 3; ++l) {
    const Interval share = rod[l] / along;
    for (int c = 0; c < 3; ++c) columns[l][c] = (c == l ? Interval(1.0) : Interval(0.0)) - share * tangent[c];
  }
  return true;
}

// rodDerivative over a box whose node moves at most `node_move` along each axis from where
// the rod is `centre_rod`, with the rod narrowed first: p and a move together, so the
// rod's mean-value form is much narrower than p - a; then the derivative again over the
// narrower rod (a subset: it cannot fail).
bool narrowedRodDerivative(const IntervalPoint& centre_rod, const Eigen::Vector3d& node_move,
                           const IntervalPoint& tangent, IntervalPoint& rod, IntervalMatrix3& columns) {
  if (!rodDerivative(rod, tangent, columns)) return false;
  for (int c = 0; c < 3; ++c) {
    Interval mean_value_form = centre_rod[c];
    for (int l = 0; l < 3; ++l) mean_value_form += columns[l][c] * Interval(-node_move[l], node_move[l]);
    rod[c] = intersect(rod[c], mean_value_form);
  }
  rodDerivative(rod, tangent, columns);
  return true;
}

// |g|^2 + |r x g|^2 / L^2, a row of the length-scaled twist form, with |g| = R (the rod's
// length at every assembled pose) and |r x g|^2 = |r|^2 R^2 - (r . g)^2: the rod's
// enclosure enters once, as r . g, so the bound stays tight over wide boxes.
Interval twistRowSquared(const Eigen::Vector3d& r, const IntervalPoint& rod, double rod_length, double length) {
  const Interval r_dot_g = dot(pointInterval(r), rod);
  const Interval rod2 = Interval(rod_length) * rod_length;
  Interval moment2 = squaredNorm(pointInterval(r)) * rod2 - boost::numeric::square(r_dot_g);
  moment2 = Interval(std::max(0.0, moment2.lower()), std::max(0.0, moment2.upper()));
  return rod2 + moment2 / (Interval(length) * length);
}

// Per chain over a box of poses, how its twist row (g, r x g) can move from the box's
// centre, for the perturbation bound preconditioned on the right (rightDelta). With r the
// platform node's offset from the TCP, g the rod and p the node, exactly
//   g(x) - g(c) = dg/dp (p(x) - p(c))  (dg/dp = I - t g^T / (g . t) over the box),
//   r(x) x g(x) - r(c) x g(c) = (r(x) - r(c)) x g(x) + r(c) x (g(x) - g(c)),
// so the row's change is linear in the node's and the offset's moves, with slopes
// enclosed over the box: the moves of the six entries are no longer bounded one by one.
// Enclosures as midpoints and radii.
struct RowSlopes {
  std::array<Eigen::Vector3d, kMaxChains> offset_mid, offset_rad;  // r(c)
  // Upper bounds of |r(x) - r(c)| and |p(x) - p(c)|, per axis.
  std::array<Eigen::Vector3d, kMaxChains> offset_move, node_move;
  // Per chain and branch: g over the box and dg/dp (slope(l, c) = dg_c / dp_l); the row
  // at the centre (g then r x g, enclosed); `bounded` false where g . t may vanish.
  std::array<std::array<Eigen::Vector3d, 2>, kMaxChains> rod_mid, rod_rad;
  std::array<std::array<Eigen::Matrix3d, 2>, kMaxChains> slope_mid, slope_rad;
  std::array<std::array<std::array<Interval, 6>, 2>, kMaxChains> centre_row;
  std::array<std::array<bool, 2>, kMaxChains> bounded{};
};

void setBall(const Interval& x, double& mid, double& rad) {
  const Ball ball = toBall(x);
  mid = ball.mid;
  rad = ball.rad;
}

RowSlopes rowSlopes(const RobotModel& model, const PoseBox& box, const std::array<IntervalPoint, kMaxChains>& from_tcp,
                    const std::array<IntervalPoint, kMaxChains>& centre_from_tcp,
                    const std::array<IntervalPoint, kMaxChains>& platform_node,
                    const std::array<NodeEnclosure, kMaxChains>& nodes) {
  RowSlopes slopes;
  const IntervalPoint position = pointInterval(box.centre.position);
  for (int i = 0; i < model.chainCount(); ++i) {
    const Chain& chain = *model.chains[i];
    const IntervalPoint offset_move = from_tcp[i] - centre_from_tcp[i];
    for (int l = 0; l < 3; ++l) {
      setBall(centre_from_tcp[i][l], slopes.offset_mid[i][l], slopes.offset_rad[i][l]);
      slopes.offset_move[i][l] = magnitude(offset_move[l]);
      slopes.node_move[i][l] = interval_detail::OutwardRounding::up(box.position_half_width[l] + slopes.offset_move[i][l]);
    }
    // The mean-value form follows a(p) along segments of platform nodes: only where the
    // chain assembles at every node of the box (floorsWhereAssembled's boxes may cross
    // the workspace's boundary).
    if (!(nodes[i].discriminant.lower() > 0.0)) continue;
    const IntervalPoint centre_node = position + centre_from_tcp[i];
    const NodeEnclosure at_centre = chain.intermediateNodeEnclosure(centre_node);
    for (int b = 0; b < 2; ++b) {
      const IntervalPoint centre_rod = centre_node - at_centre.a[b];
      const IntervalPoint centre_moment = cross(centre_from_tcp[i], position - at_centre.a[b]);
      for (int c = 0; c < 3; ++c) {
        slopes.centre_row[i][b][c] = centre_rod[c];
        slopes.centre_row[i][b][c + 3] = centre_moment[c];
      }
      IntervalPoint rod = platform_node[i] - nodes[i].a[b];
      const IntervalPoint tangent = chain.nodeTangentEnclosure(nodes[i].a[b]);
      IntervalMatrix3 columns;
      if (!narrowedRodDerivative(centre_rod, slopes.node_move[i], tangent, rod, columns)) continue;
      slopes.bounded[i][b] = true;
      for (int c = 0; c < 3; ++c) {
        setBall(rod[c], slopes.rod_mid[i][b][c], slopes.rod_rad[i][b][c]);
        for (int l = 0; l < 3; ++l) setBall(columns[l][c], slopes.slope_mid[i][b](l, c), slopes.slope_rad[i][b](l, c));
      }
    }
  }
  return slopes;
}

using Rows3 = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxChains>;

// Each column of `b` crossed with a, or a with it (the same up to sign).
Rows3 crossed(const Eigen::Vector3d& a, const Rows3& b) {
  Rows3 result(3, b.cols());
  for (int c = 0; c < 3; ++c) {
    const int i = (c + 1) % 3, j = (c + 2) % 3;
    result.row(c) = a[i] * b.row(j) - a[j] * b.row(i);
  }
  return result;
}
// The bound of |a x b| from |a| and |b| (non-negative), column by column.
Rows3 crossedMagnitude(const Eigen::Vector3d& a, const Rows3& b) {
  Rows3 result(3, b.cols());
  for (int c = 0; c < 3; ++c) {
    const int i = (c + 1) % 3, j = (c + 2) % 3;
    result.row(c) = a[i] * b.row(j) + a[j] * b.row(i);
  }
  return result;
}

struct Deviation {
  double delta = std::numeric_limits<double>::infinity(), residual = 0.0;
};

// ||J(x) X - I||_inf over the box, bounded (delta; infinity where a rod's rate is
// unbounded): X a computed inverse of the centre's J0 (both column-scaled), the residual
// of J0 X, J0's own rounding against the centre's enclosed row, and each row's change
// times X from its slopes (RowSlopes). With y the twist components' rows of X (Y = S X, S
// placing and scaling J's columns) and u = y_top + y_bottom x r(c), column k of row i's
// change times X is (p(x) - p(c)) . (dg/dp u) + (r(x) - r(c)) . (g(x) x y_bottom): the
// sums over a row's six entries keep their cancellations. Products of midpoints are
// rounded, and the bounds take 2^-49 of the magnitudes they came from for it.
Deviation rightDelta(const RobotModel& model, const RowSlopes& slopes, const WorkingMode& mode, const double* column_scale,
                     const Matrix& centre, const Matrix& inverse) {
  constexpr double kRounding = 0x1p-49;
  const int n = model.chainCount();
  Rows3 top = Rows3::Zero(3, n), bottom = Rows3::Zero(3, n);
  std::array<int, kMaxChains> component{};
  for (int j = 0; j < n; ++j) {
    component[j] = twistComponent(model, j);
    (component[j] < 3 ? top : bottom).row(component[j] % 3) = column_scale[j] * inverse.row(j);
  }
  const Rows3 top_abs = top.cwiseAbs(), bottom_abs = bottom.cwiseAbs();
  const double residual = (centre * inverse - Matrix::Identity(n, n)).cwiseAbs().rowwise().sum().maxCoeff() +
                          absoluteProductNorm(centre, inverse) * 8.0 * n * kEpsilon;
  const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxChains, 1> inverse_row_sums = inverse.cwiseAbs().rowwise().sum();
  double largest = 0.0;
  for (int i = 0; i < n; ++i) {
    const int b = static_cast<int>(mode.branch(i));
    if (!slopes.bounded[i][b]) return {};
    const Eigen::Vector3d& r = slopes.offset_mid[i];
    const Eigen::Matrix3d& slope = slopes.slope_mid[i][b];
    const Eigen::Matrix3d slope_abs = slope.cwiseAbs();
    const Rows3 u = top - crossed(r, bottom);
    const Rows3 u_rad = crossedMagnitude(slopes.offset_rad[i], bottom_abs) +
                        kRounding * (top_abs + crossedMagnitude(r.cwiseAbs() + slopes.offset_rad[i], bottom_abs));
    const Rows3 u_abs = u.cwiseAbs();
    const Rows3 along = (slope * u).cwiseAbs() + slope_abs * u_rad + slopes.slope_rad[i][b] * (u_abs + u_rad) +
                        kRounding * (slope_abs * u_abs);
    const Eigen::Vector3d& g = slopes.rod_mid[i][b];
    const Rows3 turned = crossed(g, bottom).cwiseAbs() + crossedMagnitude(slopes.rod_rad[i][b], bottom_abs) +
                         kRounding * crossedMagnitude(g.cwiseAbs() + slopes.rod_rad[i][b], bottom_abs);
    double row = slopes.node_move[i].dot(along.rowwise().sum()) + slopes.offset_move[i].dot(turned.rowwise().sum());
    // J0's rounding: the centre's exact row lies in its enclosure.
    for (int j = 0; j < n; ++j) {
      const Interval exact = slopes.centre_row[i][b][component[j]] * Interval(column_scale[j]);
      row += magnitude(exact - Interval(centre(i, j))) * inverse_row_sums[j];
    }
    if (!(row < 1.0)) return {};  // the bound fails: the other rows cannot save it
    largest = std::max(largest, row);
  }
  // Sums and products of non-negative bounds, each rounded once: a relative 2^-44 covers them.
  return {residual + largest * (1.0 + 0x1p-44), residual};
}

}  // namespace

// Per chain over the box: the platform node's offset from the TCP, the node, and the
// enclosure of its intermediate nodes.
struct MeasureCertificate::ChainEnclosures {
  IntervalPoint position;
  std::array<IntervalPoint, kMaxChains> from_tcp, platform_node;
  std::array<NodeEnclosure, kMaxChains> nodes;
  // Per chain and branch, how far the rod p - a can turn from its value at the box's
  // centre (narrowNodes; infinite where not bounded).
  std::array<std::array<double, 2>, kMaxChains> rod_moves;
};

MeasureCertificate::MeasureCertificate(const RobotModel& model, std::vector<WorkingMode> modes,
                                       const Pose& fixed_orientation)
    : model_(model),
      cache_id_(++g_certificates),
      classifier_(model, modes, fixed_orientation, false),
      fixed_classifier_(model, std::move(modes), fixed_orientation, true),
      fixed_orientation_(fixed_orientation) {
  PoseBox at_fixed;  // no width: the orientation alone
  at_fixed.centre = fixed_orientation;
  const IntervalMatrix3 fixed_rotation = rotationEnclosure(at_fixed);
  for (int i = 0; i < model.chainCount(); ++i) {
    fixed_from_tcp_[i] = times(fixed_rotation, model.chains[i]->platformNode());
    if (model.chains[i]->concaveDiscriminant()) assembled_along_translations_ |= 1u << i;
  }
  if (!prepareCouples()) couples_.clear();
  if (!couples_.empty()) product_sign_ = coupleOrderSign(model);
  if (RobotConstraints(model).active()) {
    limits_ = std::make_shared<const ModeConstraints>(model, classifier_.modes(), !couples_.empty());
  }
}

bool MeasureCertificate::prepareCouples() {
  if (model_.inputCount() != 3 || model_.chainCount() != 6 || model_.characteristic_length <= 0.0) return false;
  const Eigen::Matrix3d rotation = fixed_orientation_.rotation();
  for (const Input& input : model_.inputs) {
    if (input.chains.size() != 2) return false;
    const Couple couple{input.chains[0], rotation * model_.chains[input.chains[0]]->platformNode(),
                        rotation * model_.chains[input.chains[1]]->platformNode(), input.chains[1]};
    if (!model_.chains[input.chains[0]]->translateMismatch(*model_.chains[input.chains[1]], couple.r_second - couple.r_first).empty()) {
      return false;
    }
    for (const WorkingMode& mode : classifier_.modes()) {
      if (mode.branch(input.chains[0]) != mode.branch(input.chains[1])) return false;
    }
    couples_.push_back(couple);
  }
  return true;
}

std::array<IntervalPoint, kMaxChains> MeasureCertificate::fromTcp(const PoseBox& box) const {
  if (atFixedOrientation(box)) return fixed_from_tcp_;
  return perAngularRange<std::array<IntervalPoint, kMaxChains>>(cache_id_, box, [&] {
    const IntervalMatrix3 rotation = rotationEnclosure(box);
    std::array<IntervalPoint, kMaxChains> result;
    for (int i = 0; i < model_.chainCount(); ++i) result[i] = times(rotation, model_.chains[i]->platformNode());
    return result;
  });
}

BoxAssembly MeasureCertificate::assemblyOf(const PoseBox& box, std::uint32_t chains, std::uint32_t* undecided) const {
  return assembly(box, chains, undecided, false);
}

BoxAssembly MeasureCertificate::assemblyOfCell(const PoseBox& box, std::uint32_t chains, std::uint32_t* undecided) const {
  return assembly(box, chains, undecided, true);
}

BoxAssembly MeasureCertificate::assembly(const PoseBox& box, std::uint32_t chains, std::uint32_t* undecided,
                                         bool mean_value) const {
  const std::array<IntervalPoint, kMaxChains> from_tcp = fromTcp(box);
  const IntervalPoint position = positionEnclosure(box);
  const bool translation = mean_value && box.angle_half_width.isZero();
  const IntervalPoint centre = pointInterval(box.centre.position);
  std::uint32_t open = 0;
  for (int i = 0; i < model_.chainCount(); ++i) {
    if (!(chains >> i & 1u)) continue;
    const Chain& chain = *model_.chains[i];
    const IntervalPoint node = position + from_tcp[i];
    Interval discriminant = chain.discriminantEnclosure(node);
    if (translation) {
      discriminant = narrowedDiscriminant(chain, discriminant, node, centre + from_tcp[i], box.position_half_width);
    }
    if (discriminant.upper() < 0.0) return BoxAssembly::Outside;
    if (!(discriminant.lower() > 0.0)) open |= 1u << i;
  }
  if (undecided != nullptr) *undecided = open;
  return open == 0 ? BoxAssembly::Inside : BoxAssembly::Undecided;
}

std::uint32_t MeasureCertificate::chainsNearReach(const PoseBox& box, double spreads, std::uint32_t chains) const {
  const std::array<IntervalPoint, kMaxChains> from_tcp = fromTcp(box);
  const IntervalPoint position = positionEnclosure(box);
  std::uint32_t near = 0;
  for (int i = 0; i < model_.chainCount(); ++i) {
    if ((chains >> i & 1u) == 0) continue;
    const Interval discriminant = model_.chains[i]->discriminantEnclosure(position + from_tcp[i]);
    if (!(discriminant.lower() > spreads * width(discriminant))) near |= 1u << i;
  }
  return near;
}

AssemblyShares MeasureCertificate::assemblyShares(const PoseBox& box, std::uint32_t chains) const {
  if (!box.angle_half_width.isZero()) return {};
  const std::array<IntervalPoint, kMaxChains> from_tcp = fromTcp(box);
  const IntervalPoint position = positionEnclosure(box), centre = pointInterval(box.centre.position);
  // The part proven assembled is the intersection of each chain's: at least 1 minus the
  // sum of what each leaves out.
  double left_out = 0.0, unassembled = 0.0;
  for (int i = 0; i < model_.chainCount(); ++i) {
    if ((chains >> i & 1u) == 0) continue;
    const Chain& chain = *model_.chains[i];
    const IntervalPoint node = position + from_tcp[i];
    const Interval over_box = chain.discriminantEnclosure(node);
    if (over_box.lower() > 0.0) continue;
    if (over_box.upper() < 0.0) return {0.0, 1.0};
    const Interval at_centre = chain.discriminantEnclosure(centre + from_tcp[i]);
    const IntervalPoint gradient = chain.discriminantGradientEnclosure(node);
    const IntervalPoint falling = {-gradient[0], -gradient[1], -gradient[2]};
    // Only a part holding the centre is connected to it.
    left_out += at_centre.lower() > 0.0 ? 1.0 - provenPositiveShare(at_centre.lower(), gradient, box.position_half_width)
                                        : 1.0;
    unassembled = std::max(unassembled, provenPositiveShare(-at_centre.upper(), falling, box.position_half_width));
  }
  return {std::max(0.0, 1.0 - left_out), unassembled};
}

BoxAssembly MeasureCertificate::encloseChains(const PoseBox& box, ChainEnclosures& chains) const {
  chains.from_tcp = fromTcp(box);
  chains.position = positionEnclosure(box);
  const bool translation = box.angle_half_width.isZero();
  const IntervalPoint centre = pointInterval(box.centre.position);
  // On the factorised path a couple's second chain enters only through its discriminant
  // (its node would cost an RSS chain's angles for nothing).
  std::uint32_t with_nodes = ~0u;
  if (atFixedOrientation(box) && !couples_.empty() && limits_ == nullptr) {
    with_nodes = 0;
    for (const Couple& couple : couples_) with_nodes |= 1u << couple.first_chain;
  }
  bool inside = true;
  for (int i = 0; i < model_.chainCount(); ++i) {
    const Chain& chain = *model_.chains[i];
    chains.platform_node[i] = chains.position + chains.from_tcp[i];
    if (with_nodes >> i & 1u) {
      chains.nodes[i] = chain.intermediateNodeEnclosure(chains.platform_node[i]);
    } else {
      chains.nodes[i].discriminant = chain.discriminantEnclosure(chains.platform_node[i]);
      for (IntervalPoint& node : chains.nodes[i].a) node.fill(Interval::whole());
    }
    if (translation) {
      chains.nodes[i].discriminant = narrowedDiscriminant(chain, chains.nodes[i].discriminant, chains.platform_node[i],
                                                          centre + chains.from_tcp[i], box.position_half_width);
    }
    if (chains.nodes[i].discriminant.upper() < 0.0) return BoxAssembly::Outside;
    inside = inside && chains.nodes[i].discriminant.lower() > 0.0;
  }
  return inside ? BoxAssembly::Inside : BoxAssembly::Undecided;
}

BoxCertificate MeasureCertificate::blankCertificate() const {
  BoxCertificate result;
  result.measure_floor.assign(modes().size(), 0.0);
  result.centre_measure.assign(modes().size(), std::numeric_limits<double>::quiet_NaN());
  return result;
}

std::vector<double> MeasureCertificate::floorsWhereAssembled(const PoseBox& box) const {
  BoxCertificate result = blankCertificate();
  ChainEnclosures chains;
  if (limits_ != nullptr || encloseChains(box, chains) == BoxAssembly::Outside) return result.measure_floor;
  std::vector<double> signs(result.measure_floor.size(), 0.0);
  if (atFixedOrientation(box) && !couples_.empty()) {
    factorisedFloors(box, chains, false, result, signs.data());
  } else {
    // The perturbation bound starts from the centre's measure (where it is assembled), and
    // keeps its sign: the Jacobian perturbed that little stays regular.
    classifier_.classify(box.centre, result.centre_measure.data());
    perturbationFloors(box, chains, result);
    for (std::size_t m = 0; m < signs.size(); ++m) signs[m] = result.centre_measure[m] < 0.0 ? -1.0 : 1.0;
  }
  for (std::size_t m = 0; m < signs.size(); ++m) result.measure_floor[m] *= signs[m];
  return result.measure_floor;
}

BoxCertificate MeasureCertificate::certify(const PoseBox& box, std::uint64_t wanted, bool slopes_only) const {
  const std::size_t mode_count = modes().size();
  BoxCertificate result = blankCertificate();
  ChainEnclosures chains;
  result.assembly = encloseChains(box, chains);
  if (result.assembly == BoxAssembly::Outside) return result;
  const PoseClassifier& at_centre = atFixedOrientation(box) ? fixed_classifier_ : classifier_;
  if (result.assembly == BoxAssembly::Undecided || !at_centre.classify(box.centre, result.centre_measure.data())) {
    result.assembly = BoxAssembly::Undecided;
    return result;
  }
  for (auto& moves : chains.rod_moves) moves.fill(std::numeric_limits<double>::infinity());
  if (limits_ != nullptr && box.angle_half_width.isZero()) narrowAllNodes(atFixedOrientation(box), chains);
  const std::uint64_t all_modes = mode_count >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << mode_count) - 1;
  result.limits_kept = all_modes;
  if (limits_ != nullptr) provenLimits(box, chains, result);
  // Signs matter only for the modes proven to keep every limit.
  if (result.limits_kept == 0) return result;
  if (atFixedOrientation(box) && !couples_.empty()) {
    factorisedFloors(box, chains, true, result, nullptr, wanted, slopes_only);
  } else {
    perturbationFloors(box, chains, result, wanted);
  }
  return result;
}

// narrowNodes on every chain of an assembled box of positions (no rotation). At the
// couples' orientation a couple's second chain is its first moved by the offset, nodes and
// rods alike: narrowed once.
void MeasureCertificate::narrowAllNodes(bool couples_translate, ChainEnclosures& chains) const {
  std::array<bool, kMaxChains> narrowed{};
  for (const Couple& couple : couples_) {
    if (!couples_translate) break;
    narrowNodes(chains.platform_node[couple.first_chain], *model_.chains[couple.first_chain],
                chains.nodes[couple.first_chain], chains.rod_moves[couple.first_chain]);
    const IntervalPoint offset = pointInterval(Eigen::Vector3d(couple.r_second - couple.r_first));
    for (int b = 0; b < 2; ++b) {
      const IntervalPoint moved = chains.nodes[couple.first_chain].a[b] + offset;
      for (int c = 0; c < 3; ++c) {
        Interval& node = chains.nodes[couple.second_chain].a[b][c];
        if (overlap(node, moved[c])) node = intersect(node, moved[c]);
      }
    }
    chains.rod_moves[couple.second_chain] = chains.rod_moves[couple.first_chain];
    narrowed[couple.first_chain] = narrowed[couple.second_chain] = true;
  }
  for (int i = 0; i < model_.chainCount(); ++i) {
    if (!narrowed[i]) narrowNodes(chains.platform_node[i], *model_.chains[i], chains.nodes[i], chains.rod_moves[i]);
  }
}

// A chain's intermediate nodes over an assembled box of positions (no rotation), in
// mean-value form: a(p) in a(c) + da/dp (p - c) about a point c of the box, with
// da/dp = t g^T / (g . t) (t: how the node moves with the input, g = p - a). The natural
// enclosure of a node grows with the crank's leverage, and its g . t holds 0: the
// derivative is enclosed instead over a guess about a(c), sized from the derivative at c
// and widened until the mean-value form falls strictly inside it. That proves the guess:
// along the segment from c to any p of the box, a(p) is continuous and cannot reach the
// guess's boundary while the form, valid up to there, keeps it strictly inside.
void MeasureCertificate::narrowNodes(const IntervalPoint& platform_node, const Chain& chain, NodeEnclosure& nodes,
                                     std::array<double, 2>& rod_moves) const {
  IntervalPoint centre;
  for (int k = 0; k < 3; ++k) centre[k] = Interval(median(platform_node[k]));
  const IntervalPoint step = platform_node - centre;
  const NodeEnclosure at_centre = chain.intermediateNodeEnclosure(centre);
  IntervalPoint rod_move;  // the rod's move in the same form, with dg/dp = I - da/dp
  // The mean-value form over nodes in `over` and platform nodes in `over_p`; false where
  // g . t may vanish there.
  const auto meanValue = [&](int b, const IntervalPoint& over, const IntervalPoint& over_p, IntervalPoint& result) {
    const IntervalPoint tangent = chain.nodeTangentEnclosure(over);
    const IntervalPoint rod = over_p - over;
    const Interval along = dot(rod, tangent);
    if (zero_in(along)) return false;
    const IntervalPoint share = {rod[0] / along, rod[1] / along, rod[2] / along};
    for (int c = 0; c < 3; ++c) {
      result[c] = at_centre.a[b][c];
      rod_move[c] = Interval(0.0);
      for (int l = 0; l < 3; ++l) {
        const Interval derivative = tangent[c] * share[l];
        result[c] += derivative * step[l];
        rod_move[c] += (Interval(c == l ? 1.0 : 0.0) - derivative) * step[l];
      }
    }
    return true;
  };
  for (int b = 0; b < 2; ++b) {
    rod_moves[b] = std::numeric_limits<double>::infinity();
    IntervalPoint form, guess;
    if (!meanValue(b, at_centre.a[b], centre, form)) continue;
    for (int attempt = 0; attempt < 3; ++attempt) {
      // The node never leaves its natural enclosure: the guess need not either.
      for (int c = 0; c < 3; ++c) {
        const double spread = 0.25 * width(form[c]) + width(at_centre.a[b][c]) + 1e-12;
        guess[c] = Interval(form[c].lower() - spread, form[c].upper() + spread);
        if (overlap(guess[c], nodes.a[b][c])) guess[c] = intersect(guess[c], nodes.a[b][c]);
      }
      if (!meanValue(b, guess, platform_node, form)) break;
      bool inside = true;
      for (int c = 0; c < 3; ++c) {
        inside = inside && (form[c].lower() > guess[c].lower() || guess[c].lower() == nodes.a[b][c].lower()) &&
                 (form[c].upper() < guess[c].upper() || guess[c].upper() == nodes.a[b][c].upper());
      }
      if (!inside) continue;
      for (int c = 0; c < 3; ++c) nodes.a[b][c] = intersect(nodes.a[b][c], form[c]);
      rod_moves[b] = sqrt(squaredNorm({Interval(magnitude(rod_move[0])), Interval(magnitude(rod_move[1])),
                                       Interval(magnitude(rod_move[2]))})).upper();
      break;
    }
  }
}

// The limits over the box, from the chains' enclosures and their nodes at its centre.
void MeasureCertificate::provenLimits(const PoseBox& box, const ChainEnclosures& chains, BoxCertificate& result) const {
  std::array<ChainBox, kMaxChains> boxes;
  std::optional<IntervalMatrix3> rotation;  // made only for a platform-end cone
  for (int i = 0; i < model_.chainCount(); ++i) {
    const Chain& chain = *model_.chains[i];
    ChainBox& chain_box = boxes[i];
    chain_box.p = chains.platform_node[i];
    chain_box.a = chains.nodes[i].a;
    chain_box.rod_moves = chains.rod_moves[i];
    chain_box.rod_length = chain.rodLength();
    if (const auto& cone = chain.limits().platform_end) {
      if (!rotation) rotation = rotationEnclosure(box);
      chain_box.platform_axis = times(*rotation, cone->axis);
    }
    chain_box.p_centre = box.centre.toBase(chain.platformNode());
    chain_box.a_centre = chain.intermediateNodes(chain_box.p_centre).a;
  }
  // A couple's rods are translates only at the orientation they factorise at.
  const BoxLimits limits = limits_->overBox(boxes.data(), atFixedOrientation(box));
  result.limits_kept = limits.kept;
  result.limits_broken = limits.broken;
}

// Per couple k and branch b over a box: the rod g over the box and at its centre, D's row
// delta x g, their derivatives along each axis l (midpoint-radius form: per working mode,
// everything is sums of their products), and the row norms; then the cross products of
// the other two couples' rows, per pair of branches, shared by the working modes: pair[k]
// of couples k + 1 and k + 2.
struct MeasureCertificate::CoupleRows {
  Ball centre_rod[3][2][3], d_row[3][2][3], centre_d_row[3][2][3];
  Ball derivative[3][2][3][3], d_derivative[3][2][3][3];  // [k][b][l][coordinate]
  Ball box_rod[3][2][3];
  Interval row_norm[3][2];
  bool rates_bounded = false;  // every needed rod's derivative enclosed over the box
  Ball g_pair[3][2][2][3], d_pair[3][2][2][3], centre_g_pair[2][2][3], centre_d_pair[2][2][3];
  // The rows the working modes asked for use (couple k in branch b): the others are left.
  bool needed[3][2] = {};

  void pairUp() {
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      for (int bi = 0; bi < 2; ++bi) {
        for (int bj = 0; bj < 2; ++bj) {
          if (!needed[i][bi] || !needed[j][bj]) continue;
          cross(box_rod[i][bi], box_rod[j][bj], g_pair[k][bi][bj]);
          cross(d_row[i][bi], d_row[j][bj], d_pair[k][bi][bj]);
          if (k > 0) continue;
          cross(centre_rod[i][bi], centre_rod[j][bj], centre_g_pair[bi][bj]);
          cross(centre_d_row[i][bi], centre_d_row[j][bj], centre_d_pair[bi][bj]);
        }
      }
    }
  }
};

void MeasureCertificate::enclosedCoupleRows(const PoseBox& box, const ChainEnclosures& chains, bool mean_value,
                                            CoupleRows& rows, std::uint64_t wanted, bool slopes_only) const {
  const double length = model_.characteristic_length;
  rows.rates_bounded = mean_value;
  for (std::size_t m = 0; m < modes().size(); ++m) {
    if ((wanted >> m & 1u) == 0) continue;
    for (int k = 0; k < 3; ++k) rows.needed[k][static_cast<int>(modes()[m].branch(couples_[k].first_chain))] = true;
  }
  for (int k = 0; k < 3; ++k) {
    if (!rows.needed[k][0] && !rows.needed[k][1]) continue;
    const Couple& couple = couples_[k];
    const Chain& chain = *model_.chains[couple.first_chain];
    const IntervalPoint centre_node = pointInterval(Eigen::Vector3d(box.centre.position + couple.r_first));
    const NodeEnclosure at_centre = chain.intermediateNodeEnclosure(centre_node);
    const NodeEnclosure& over_box = chains.nodes[couple.first_chain];
    const Eigen::Vector3d offset_vector = couple.r_second - couple.r_first;
    const Ball offset[3] = {{offset_vector.x(), 0.0}, {offset_vector.y(), 0.0}, {offset_vector.z(), 0.0}};
    for (int b = 0; b < 2; ++b) {
      if (!rows.needed[k][b]) continue;
      IntervalPoint rod = chains.platform_node[couple.first_chain] - over_box.a[b];
      const IntervalPoint centre = centre_node - at_centre.a[b];
      const IntervalPoint tangent = chain.nodeTangentEnclosure(over_box.a[b]);
      IntervalMatrix3 columns;
      if (!rows.rates_bounded || !narrowedRodDerivative(centre, box.position_half_width, tangent, rod, columns)) {
        rows.rates_bounded = false;
        if (slopes_only) return;
      }
      for (int c = 0; c < 3; ++c) {
        rows.box_rod[k][b][c] = toBall(rod[c]);
        rows.centre_rod[k][b][c] = toBall(centre[c]);
        for (int l = 0; l < 3; ++l) rows.derivative[k][b][l][c] = rows.rates_bounded ? toBall(columns[l][c]) : Ball{};
      }
      cross(offset, rows.box_rod[k][b], rows.d_row[k][b]);
      cross(offset, rows.centre_rod[k][b], rows.centre_d_row[k][b]);
      for (int l = 0; l < 3; ++l) cross(offset, rows.derivative[k][b][l], rows.d_derivative[k][b][l]);
      rows.row_norm[k][b] = sqrt(twistRowSquared(couple.r_first, rod, chain.rodLength(), length) *
                                 twistRowSquared(couple.r_second, rod, chain.rodLength(), length));
    }
  }
  rows.pairUp();
}

// det(G) and det(D) in mean-value form (header), or in natural form where a rod's rate is
// unbounded over the box (or `mean_value` is false); the measure's floor is their smallest
// magnitudes over the largest row norms, in the length-scaled twist form.
void MeasureCertificate::factorisedFloors(const PoseBox& box, const ChainEnclosures& chains, bool mean_value,
                                         BoxCertificate& result, double* signs, std::uint64_t wanted,
                                         bool slopes_only) const {
  CoupleRows rows;
  enclosedCoupleRows(box, chains, mean_value, rows, wanted, slopes_only);
  if (slopes_only && !rows.rates_bounded) return;
  const double length = model_.characteristic_length;
  const Interval cube = Interval(length) * length * length;
  if (rows.rates_bounded) {
    result.norm_ratio.assign(result.measure_floor.size(), 0.0);
    result.centre = box.centre.position;
    result.half_width = box.position_half_width;
    result.product_gradient.assign(result.measure_floor.size(), IntervalPoint{});
    result.product_at_centre.assign(result.measure_floor.size(), Interval(0.0));
    result.product_scale.assign(result.measure_floor.size(), Interval(0.0));
  }
  for (std::size_t m = 0; m < result.measure_floor.size(); ++m) {
    if ((wanted >> m & 1u) == 0) continue;
    int b[3];
    for (int k = 0; k < 3; ++k) b[k] = static_cast<int>(modes()[m].branch(couples_[k].first_chain));
    const Interval norms = rows.row_norm[0][b[0]] * rows.row_norm[1][b[1]] * rows.row_norm[2][b[2]];
    if (rows.rates_bounded) {
      meanValueFloor(rows, b, m, box.position_half_width, norms, cube, result);
      continue;
    }
    BallDot det_g, det_d;
    for (int c = 0; c < 3; ++c) {
      det_g.add(rows.box_rod[0][b[0]][c], rows.g_pair[0][b[1]][b[2]][c]);
      det_d.add(rows.d_row[0][b[0]][c], rows.d_pair[0][b[1]][b[2]][c]);
    }
    const Ball g = det_g.result(), d = det_d.result();
    const Interval floor = Interval(mignitude(g)) * mignitude(d) / cube / norms.upper();
    result.measure_floor[m] = std::max(0.0, floor.lower());
    // Where the floor is above zero both factors keep their midpoints' signs.
    if (signs != nullptr) signs[m] = product_sign_ * (g.mid < 0.0 ? -1.0 : 1.0) * (d.mid < 0.0 ? -1.0 : 1.0);
  }
}

// Working mode m's (branches b) product at the box's centre, its gradient over the box,
// and its floor, from the mean-value forms of det(G) and det(D).
void MeasureCertificate::meanValueFloor(const CoupleRows& rows, const int* b, std::size_t m,
                                        const Eigen::Vector3d& half_width, const Interval& norms, const Interval& cube,
                                        BoxCertificate& result) const {
  BallDot det_g_sum, det_d_sum;
  for (int c = 0; c < 3; ++c) {
    det_g_sum.add(rows.centre_rod[0][b[0]][c], rows.centre_g_pair[b[1]][b[2]][c]);
    det_d_sum.add(rows.centre_d_row[0][b[0]][c], rows.centre_d_pair[b[1]][b[2]][c]);
  }
  result.product_at_centre[m] = product_sign_ * (toInterval(det_g_sum.result()) * toInterval(det_d_sum.result()));
  Ball gradient_g[3], gradient_d[3];
  for (int l = 0; l < 3; ++l) {
    BallDot along_g, along_d;
    for (int k = 0; k < 3; ++k) {
      const int bi = b[(k + 1) % 3], bj = b[(k + 2) % 3];
      for (int c = 0; c < 3; ++c) {
        along_g.add(rows.derivative[k][b[k]][l][c], rows.g_pair[k][bi][bj][c]);
        along_d.add(rows.d_derivative[k][b[k]][l][c], rows.d_pair[k][bi][bj][c]);
      }
    }
    gradient_g[l] = along_g.result();
    gradient_d[l] = along_d.result();
    const Ball step{0.0, half_width[l]};
    det_g_sum.add(gradient_g[l], step);
    det_d_sum.add(gradient_d[l], step);
  }
  const Ball det_g = det_g_sum.result(), det_d = det_d_sum.result();
  // Within the box, P = det_g det_d has gradient det_d grad(det_g) + det_g grad(det_d);
  // |measure| = |P| / (L^3 norms).
  result.norm_ratio[m] = (Interval(norms.lower()) / norms.upper()).lower();
  // Boost's products here: the two terms can cancel, and a midpoint-radius product's
  // wider lower side would lose that.
  const Interval det_g_range = toInterval(det_g), det_d_range = toInterval(det_d);
  result.product_scale[m] = cube * norms;
  for (int l = 0; l < 3; ++l) {
    result.product_gradient[m][l] =
        product_sign_ * (toInterval(gradient_g[l]) * det_d_range + det_g_range * toInterval(gradient_d[l]));
  }
  if (!(std::abs(result.centre_measure[m]) > kMeasureTolerance)) return;
  const Interval floor = Interval(mignitude(det_g)) * mignitude(det_d) / cube / norms.upper();
  result.measure_floor[m] = std::max(0.0, floor.lower());
}

double BoxCertificate::shareKeepingSign(std::size_t mode, const PoseBox& cell, double margin) const {
  if (!boundsVariation() || !cell.angle_half_width.isZero()) return 0.0;
  // Over this box P(x) >= P(centre) + m . (x - centre) - r . |x - centre| (m, r: the
  // gradient's midpoint and radius): at the cell's centre, `rising` or `falling` (for -P)
  // bounds it, and over the cell the same gradient leaves one plane below P (or -P).
  constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
  const Interval& at_centre = product_at_centre[mode];
  double rising = at_centre.lower(), falling = -at_centre.upper(), size = std::abs(rising) + std::abs(falling);
  IntervalPoint falling_gradient;
  for (int l = 0; l < 3; ++l) {
    const Interval& gradient = product_gradient[mode][l];
    const double offset = cell.centre.position[l] - centre[l];
    // The gradient holds over this box only.
    if (std::abs(offset) + cell.position_half_width[l] > half_width[l] * (1.0 + 1e-12) + 1e-15) return 0.0;
    const Ball ball = toBall(gradient);  // its radius rounded up
    rising += ball.mid * offset - ball.rad * std::abs(offset);
    falling += -ball.mid * offset - ball.rad * std::abs(offset);
    size += (std::abs(ball.mid) + ball.rad) * std::abs(offset);
    falling_gradient[l] = -gradient;
  }
  // The sums' rounding; and |P| beyond the margin (or the tolerance) times |P| / |measure|'s
  // bound: a share under the margin is no part of the analysis's regions.
  const double floor = 16.0 * kEpsilon * size + std::max(margin, kMeasureTolerance) * product_scale[mode].upper();
  if (rising > floor) return provenPositiveShare(rising - floor, product_gradient[mode], cell.position_half_width);
  if (falling > floor) return provenPositiveShare(falling - floor, falling_gradient, cell.position_half_width);
  return 0.0;
}

// The perturbation bound of the header, on the length-scaled twist form; where it fails,
// the same preconditioned on the right with the rows' slopes (rightDelta), for up to
// kRightBoundModes working modes. With more, a box is filled only when every mode is
// proven, which the second bound rarely completes: on the 6-RSS hexapod's 64 modes at 2 mm
// it proved 217 k more (box, mode) pairs for 1.4 % fewer poses and +0.15 % of certified
// maximal - volume, at +25 % of the classification's time (docs/benchmarks.md).
constexpr std::size_t kRightBoundModes = 16;
void MeasureCertificate::perturbationFloors(const PoseBox& box, const ChainEnclosures& chains, BoxCertificate& result,
                                            std::uint64_t wanted) const {
  const int n = model_.chainCount();
  const IkpResult ikp = solveIkp(model_, box.centre);
  std::array<double, kMaxChains> column_scale{};
  for (int j = 0; j < n; ++j) column_scale[j] = twistComponent(model_, j) >= 3 ? 1.0 / model_.characteristic_length : 1.0;
  std::optional<RowSlopes> slopes;
  for (std::size_t m = 0; m < result.measure_floor.size(); ++m) {
    if ((wanted >> m & 1u) == 0 || !ikp.assembled || !(std::abs(result.centre_measure[m]) > kMeasureTolerance)) continue;
    Matrix centre_jacobian = dkpJacobianTwist(model_, configurationOf(box.centre, ikp, modes()[m]));
    Matrix deviation(n, n);
    double row_ratio = 1.0;  // prod |row_i(centre)| / max over the box of |row_i|
    for (int i = 0; i < n; ++i) {
      const IntervalPoint& a = chains.nodes[i].a[static_cast<int>(modes()[m].branch(i))];
      // g = p - a, and r x g = r x (P - a) since r x r = 0 (tighter than the product).
      const IntervalPoint rod = chains.platform_node[i] - a;
      const IntervalPoint moment = cross(chains.from_tcp[i], chains.position - a);
      Interval box_norm2(0.0);
      for (int j = 0; j < n; ++j) {
        const int component = twistComponent(model_, j);
        const Interval entry = (component < 3 ? rod[component] : moment[component - 3]) * Interval(column_scale[j]);
        centre_jacobian(i, j) *= column_scale[j];
        deviation(i, j) = magnitude(entry - Interval(centre_jacobian(i, j)));
        box_norm2 += Interval(magnitude(entry)) * magnitude(entry);
      }
      row_ratio *= centre_jacobian.row(i).norm() * (1.0 - 8.0 * kEpsilon) / sqrt(box_norm2).upper();
    }
    const Matrix inverse = Eigen::PartialPivLU<Matrix>(centre_jacobian).inverse();
    const double residual = (inverse * centre_jacobian - Matrix::Identity(n, n)).cwiseAbs().rowwise().sum().maxCoeff() +
                            absoluteProductNorm(inverse, centre_jacobian) * 8.0 * n * kEpsilon;
    const double delta = residual + absoluteProductNorm(inverse, deviation);
    double kept = delta < 1.0 ? std::pow((1.0 - delta) / (1.0 + residual), n) : 0.0;
    if (!(kept > 0.0) && result.measure_floor.size() <= kRightBoundModes) {
      if (!slopes) slopes = rowSlopes(model_, box, chains.from_tcp, fromTcp(PoseBox{box.centre}), chains.platform_node, chains.nodes);
      const Deviation right = rightDelta(model_, *slopes, modes()[m], column_scale.data(), centre_jacobian, inverse);
      if (!(right.delta < 1.0)) continue;
      kept = std::pow((1.0 - right.delta) / (1.0 + right.residual), n);
    }
    // The centre's |measure| is within 1e-12 of the exact one (docs/kinematics.md, "How
    // exact the sign is"); taking the tolerance off keeps the floor below the exact value.
    const double floor = (std::abs(result.centre_measure[m]) - kMeasureTolerance) * row_ratio * kept *
                         (1.0 - 64.0 * kEpsilon);
    result.measure_floor[m] = std::max(0.0, floor);
  }
}

}  // namespace maximal_workspace
