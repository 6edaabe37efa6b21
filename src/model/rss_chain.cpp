#include "maximal_workspace/model/rss_chain.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "model/field_reader.h"
#include "model/vector_kernel.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

RssChain::RssChain(ChainCommon common, Eigen::Vector3d crank_centre, Eigen::Vector3d axis,
                   double crank_length, Eigen::Vector3d crank_zero)
    : Chain(std::move(common)),
      crank_centre_(crank_centre),
      axis_(axis.normalized()),
      crank_length_(crank_length) {
  u_ = (crank_zero - crank_zero.dot(axis_) * axis_).normalized();
  v_ = axis_.cross(u_);
  // |w^T E w| <= |w|^2 times the sum of |E|'s entries (at least its 2-norm), E enclosed.
  const IntervalPoint u = pointInterval(u_), v = pointInterval(v_), e = pointInterval(axis_);
  Interval excess_bound(0.0);
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) {
      const Interval entry = Interval(k == j ? 1.0 : 0.0) - u[k] * u[j] - v[k] * v[j] - e[k] * e[j];
      excess_bound += Interval(std::max(-entry.lower(), entry.upper()));
    }
  }
  frame_excess_ = excess_bound.upper();
}

ChainPtr RssChain::fromFields(const FieldReader& fields, ChainCommon common) {
  const Eigen::Vector3d axis = fields.unitVector("axis");
  Eigen::Vector3d crank_zero = Eigen::Vector3d::UnitX();
  if (fields.has("crank_zero")) {
    crank_zero = fields.unitVector("crank_zero");
    if (crank_zero.cross(axis).norm() < 1e-6) fields.fail("crank_zero", "must not be parallel to the axis");
  } else if (crank_zero.cross(axis).norm() < 1e-6) {
    crank_zero = Eigen::Vector3d::UnitY();
  }
  return std::make_shared<RssChain>(std::move(common), fields.point("fixed_node"), axis,
                                    fields.positiveLength("crank_length"), crank_zero);
}

// Sphere of radius R about p cut by the crank circle: with w = p - c,
// A cos q + B sin q = C, A = 2L u.w, B = 2L v.w, C = |w|^2 + L^2 - R^2, and
// q = atan2(B, A) +/- acos(C / sqrt(A^2 + B^2)). cos q and sin q of both roots come from
// A, B, C and one square root, so a needs no trigonometric call.
ChainNodes RssChain::intermediateNodes(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d w = p - crank_centre_;
  const double a_coef = 2.0 * crank_length_ * u_.dot(w);
  const double b_coef = 2.0 * crank_length_ * v_.dot(w);
  const double c_coef = w.squaredNorm() + crank_length_ * crank_length_ - rodLength() * rodLength();
  const double rho2 = a_coef * a_coef + b_coef * b_coef;
  ChainNodes nodes;
  nodes.discriminant = rho2 - c_coef * c_coef;
  nodes.assembled = nodes.discriminant >= 0.0;
  if (!nodes.assembled) return nodes;
  const double root = std::sqrt(nodes.discriminant);
  for (int b = 0; b < 2; ++b) {
    const double sign = b == 0 ? 1.0 : -1.0;
    double cos_q = 1.0, sin_q = 0.0;
    // p on the axis with C = 0: every crank angle assembles; report q = 0 for both.
    if (rho2 > 0.0) {
      cos_q = (a_coef * c_coef - sign * b_coef * root) / rho2;
      sin_q = (b_coef * c_coef + sign * a_coef * root) / rho2;
    }
    nodes.a[b] = crank_centre_ + crank_length_ * (cos_q * u_ + sin_q * v_);
  }
  return nodes;
}

namespace {

// As intermediateNodes above, branch-free: where rho2 = 0 the blend gives q = 0.
MOW_VECTOR_KERNEL void rssNodes(const double* __restrict x, const double* __restrict y, const double* __restrict z,
                                std::size_t count, const double c[3], const double u[3], const double v[3],
                                double crank, double rod, double* __restrict discriminant, double* __restrict ax0,
                                double* __restrict ay0, double* __restrict az0, double* __restrict ax1,
                                double* __restrict ay1, double* __restrict az1) {
  const double cx = c[0], cy = c[1], cz = c[2];
  const double ux = u[0], uy = u[1], uz = u[2], vx = v[0], vy = v[1], vz = v[2];
  const double two_l = 2.0 * crank, constant = crank * crank - rod * rod;
  for (std::size_t i = 0; i < count; ++i) {
    const double wx = x[i] - cx, wy = y[i] - cy, wz = z[i] - cz;
    const double a = two_l * (ux * wx + uy * wy + uz * wz);
    const double b = two_l * (vx * wx + vy * wy + vz * wz);
    const double cc = (wx * wx + wy * wy + wz * wz) + constant;
    const double rho2 = a * a + b * b;
    const double disc = rho2 - cc * cc;
    const double root = std::sqrt(std::max(disc, 0.0));
    const double inverse = 1.0 / (rho2 > 0.0 ? rho2 : 1.0);
    const double on_axis = rho2 > 0.0 ? 0.0 : 1.0;
    const double ac = a * cc * inverse + on_axis, bc = b * cc * inverse;
    const double br = b * root * inverse, ar = a * root * inverse;
    const double cos0 = ac - br, sin0 = bc + ar, cos1 = ac + br, sin1 = bc - ar;
    discriminant[i] = disc;
    ax0[i] = cx + crank * (cos0 * ux + sin0 * vx);
    ay0[i] = cy + crank * (cos0 * uy + sin0 * vy);
    az0[i] = cz + crank * (cos0 * uz + sin0 * vz);
    ax1[i] = cx + crank * (cos1 * ux + sin1 * vx);
    ay1[i] = cy + crank * (cos1 * uy + sin1 * vy);
    az1[i] = cz + crank * (cos1 * uz + sin1 * vz);
  }
}

}  // namespace

void RssChain::intermediateNodes(const PointBatch& points, const NodeBatch& nodes) const {
  rssNodes(points.x, points.y, points.z, points.count, crank_centre_.data(), u_.data(), v_.data(), crank_length_,
           rodLength(), nodes.discriminant, nodes.x[0], nodes.y[0], nodes.z[0], nodes.x[1], nodes.y[1], nodes.z[1]);
}

namespace {

// Slack for libm's atan2 and acos (within an ulp or two) and for the rounding of their
// arguments' bounds, which the monotonicity below turns into bounds of the angle.
constexpr double kAngleSlack = 1e-14;

// The angle of (A, B) over a box of (A, B) that keeps away from the origin: the corners
// span it (the box is convex and the angle turns by less than pi across it).
Interval angleOf(const Interval& a, const Interval& b) {
  const double middle = std::atan2(median(b), median(a));
  double low = INFINITY, high = -INFINITY;
  for (double x : {a.lower(), a.upper()}) {
    for (double y : {b.lower(), b.upper()}) {
      const double turn = std::remainder(std::atan2(y, x) - middle, 2.0 * M_PI);
      low = std::min(low, turn);
      high = std::max(high, turn);
    }
  }
  return Interval(middle + low - kAngleSlack, middle + high + kAngleSlack);
}

}  // namespace

// q = atan2(B, A) +/- acos(C / sqrt(A^2 + B^2)) over the box, each function monotone in
// its argument, then a = c + L (cos q u + sin q v). Tighter than the closed form of
// intermediateNodes, whose quotient repeats A, B and C.
RssChain::Coefficients RssChain::coefficients(const IntervalPoint& p) const {
  using boost::numeric::square;
  Coefficients k;
  k.w = p - pointInterval(crank_centre_);
  const Interval two_l = Interval(2.0) * crank_length_;
  k.along_u = dot(pointInterval(u_), k.w);
  k.along_v = dot(pointInterval(v_), k.w);
  k.a = two_l * k.along_u;
  k.b = two_l * k.along_v;
  k.w_squared = squaredNorm(k.w);
  k.c = k.w_squared + (Interval(crank_length_) * crank_length_ - Interval(rodLength()) * rodLength());
  k.a2_b2 = square(k.a) + square(k.b);
  return k;
}

Interval RssChain::discriminantEnclosure(const IntervalPoint& p) const { return discriminantOf(coefficients(p)); }

// D = A^2 + B^2 - C^2 = 4 L^2 rho^2 - (rho^2 + h^2 + L^2 - R^2)^2, with rho the distance of w
// from the crank's axis and h its offset along it, factors as
//   (R^2 - h^2 - (rho - L)^2) ((rho + L)^2 + h^2 - R^2),
// the sphere about p against the crank circle's near and far points. In each factor rho
// and h enter once, where the expanded form repeats w in A, B and C: over a turning box of
// a hexapod the expanded form alone left most cells undecided. Both enclose D; the
// intersection is kept (always: then a box inside another gets an enclosure inside the
// other's, which the thin layers' marking of cells near their reach relies on).
// |w|^2 = rho^2 + h^2 + w^T E w with E the frame's rounding excess.
Interval RssChain::discriminantOf(const Coefficients& k) const {
  using boost::numeric::square;
  const Interval expanded = k.a2_b2 - square(k.c);
  const Interval rho = sqrt(square(k.along_u) + square(k.along_v));
  const Interval h2 = square(dot(pointInterval(axis_), k.w));
  const Interval excess = Interval(-1.0, 1.0) * (Interval(frame_excess_) * k.w_squared.upper());
  const Interval crank(crank_length_), rod2 = Interval(rodLength()) * rodLength();
  const Interval near = rod2 - h2 - excess - square(rho - crank);
  const Interval far = square(rho + crank) + h2 + excess - rod2;
  return intersect(expanded, near * far);
}

// D = a^2 + b^2 - c^2 with a = 2 l u . w, b = 2 l v . w, c = |w|^2 + l^2 - R^2:
// grad D = 4 l (a u + b v) - 4 c w.
IntervalPoint RssChain::discriminantGradientEnclosure(const IntervalPoint& p) const {
  const Coefficients k = coefficients(p);
  const IntervalPoint along_crank = k.a * pointInterval(u_) + k.b * pointInterval(v_);
  return Interval(4.0) * (Interval(crank_length_) * along_crank - k.c * k.w);
}

NodeEnclosure RssChain::intermediateNodeEnclosure(const IntervalPoint& p) const {
  const Coefficients k = coefficients(p);
  NodeEnclosure nodes;
  nodes.discriminant = discriminantOf(k);
  const Interval whole(-M_PI, M_PI);
  std::array<Interval, 2> angle = {whole, whole};  // p near the axis: anywhere on the crank circle
  if (!(zero_in(k.a) && zero_in(k.b))) {
    const Interval base = angleOf(k.a, k.b);
    const Interval ratio = intersect(k.c / sqrt(k.a2_b2), Interval(-1.0, 1.0));
    if (!empty(ratio)) {
      const Interval half(std::acos(ratio.upper()) - kAngleSlack, std::acos(ratio.lower()) + kAngleSlack);
      angle = {base + half, base - half};
    }
  }
  for (int b = 0; b < 2; ++b) {
    nodes.a[b] = pointInterval(crank_centre_) +
                 Interval(crank_length_) * (intervalCos(angle[b]) * pointInterval(u_) + intervalSin(angle[b]) * pointInterval(v_));
  }
  return nodes;
}

// The crank end moves about the axis: axis x (a - c), a positive multiple of da/dq.
IntervalPoint RssChain::nodeTangentEnclosure(const IntervalPoint& a) const {
  return cross(pointInterval(axis_), a - pointInterval(crank_centre_));
}

double RssChain::inputOf(const Eigen::Vector3d& a) const {
  const Eigen::Vector3d crank = a - crank_centre_;
  return std::atan2(v_.dot(crank), u_.dot(crank));
}

Eigen::Vector3d RssChain::intermediateNode(double q) const {
  return crank_centre_ + crank_length_ * (std::cos(q) * u_ + std::sin(q) * v_);
}

Eigen::Vector3d RssChain::intermediateNodeRate(double q) const {
  return crank_length_ * (-std::sin(q) * u_ + std::cos(q) * v_);
}

// x along crank_zero, z along the axis: turning by q about z puts the crank end at a(q).
Eigen::Isometry3d RssChain::actuatorFrame() const {
  Eigen::Matrix3d rotation;
  rotation << u_, v_, axis_;
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = rotation;
  frame.translation() = crank_centre_;
  return frame;
}

Eigen::Vector3d RssChain::intermediateNodeOnActuator() const { return Eigen::Vector3d(crank_length_, 0.0, 0.0); }

// The crank circle spans L sqrt(1 - e_k^2) along base axis k; the rod adds R. A crank
// range would cut an arc from the circle: the whole circle's box still holds it.
std::array<Eigen::Vector2d, 3> RssChain::reachBox(const std::optional<std::array<double, 2>>&) const {
  std::array<Eigen::Vector2d, 3> box;
  for (int k = 0; k < 3; ++k) {
    const double half = crank_length_ * std::sqrt(std::max(0.0, 1.0 - axis_[k] * axis_[k])) + rodLength();
    box[k] = Eigen::Vector2d(crank_centre_[k] - half, crank_centre_[k] + half);
  }
  return box;
}

double RssChain::inputDistance(double q1, double q2) const {
  return std::abs(std::remainder(q1 - q2, 2.0 * M_PI));
}

// The range is the arc from min turning positively to max; q is placed on the turn that
// starts at min.
double RssChain::inputMargin(double q, const std::array<double, 2>& limits) const {
  const double width = limits[1] - limits[0];
  if (width >= 2.0 * M_PI) return INFINITY;
  double along = std::fmod(q - limits[0], 2.0 * M_PI);
  if (along < 0.0) along += 2.0 * M_PI;
  if (along <= width) return std::min(along, width - along);
  return -std::min(along - width, 2.0 * M_PI - along);
}

// The arc of half-width h about the middle angle m: the crank's unit direction
// (a - c) / L makes an angle of at most h with (cos m u + sin m v).
std::vector<NodeHalfSpace> RssChain::inputRange(const std::array<double, 2>& limits) const {
  const double width = limits[1] - limits[0];
  if (width >= 2.0 * M_PI) return {};
  const double middle = 0.5 * (limits[0] + limits[1]);
  const Eigen::Vector3d normal = (std::cos(middle) * u_ + std::sin(middle) * v_) / crank_length_;
  return {NodeHalfSpace{normal, -normal.dot(crank_centre_) - std::cos(0.5 * width)}};
}

// The crank's frame: x = (a - c) / L, z = e, y = e x x; the axis is stated in it.
NodeAxisMap RssChain::fixedEndAxis(const Eigen::Vector3d& axis) const {
  const Eigen::Vector3d local = axis.normalized();
  Eigen::Matrix3d cross;
  cross << 0.0, -axis_.z(), axis_.y(), axis_.z(), 0.0, -axis_.x(), -axis_.y(), axis_.x(), 0.0;
  NodeAxisMap map;
  map.linear = (local.x() * Eigen::Matrix3d::Identity() + local.y() * cross) / crank_length_;
  map.offset = -map.linear * crank_centre_ + local.z() * axis_;
  return map;
}

std::string RssChain::translateMismatch(const Chain& other, const Eigen::Vector3d& offset) const {
  const auto* rss = dynamic_cast<const RssChain*>(&other);
  if (rss == nullptr) return std::string("it is ") + other.type() + ", not " + kType;
  const double scale = 1.0 + crank_centre_.norm() + crank_length_ + rodLength();
  const double tolerance = 1e-9 * scale;
  if ((rss->axis_ - axis_).norm() > 1e-9) return "its axis differs";
  if ((rss->u_ - u_).norm() > 1e-9) return "its crank_zero direction differs";
  if (std::abs(rss->crank_length_ - crank_length_) > tolerance) return "its crank length differs";
  if (std::abs(rss->rodLength() - rodLength()) > tolerance) return "its rod length differs";
  if ((rss->crank_centre_ - crank_centre_ - offset).norm() > tolerance) {
    return "its crank centre is not moved by the same offset as its platform node";
  }
  return {};
}

void RssChain::describe(std::ostream& out) const {
  out << "crank centre " << vectorText(crank_centre_) << ", axis " << vectorText(axis_)
      << ", crank_zero " << vectorText(u_) << ", crank L = " << numberText(crank_length_)
      << " m, rod R = " << numberText(rodLength()) << " m";
}

}  // namespace maximal_workspace
