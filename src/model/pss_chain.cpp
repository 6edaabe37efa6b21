#include "maximal_workspace/model/pss_chain.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "model/field_reader.h"
#include "model/vector_kernel.h"
#include "maximal_workspace/model/vector_text.h"

namespace maximal_workspace {

PssChain::PssChain(ChainCommon common, Eigen::Vector3d fixed_node, Eigen::Vector3d direction)
    : Chain(std::move(common)), fixed_node_(fixed_node), direction_(direction.normalized()) {
  const IntervalPoint d = pointInterval(direction_);
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) off_line_[k][j] = Interval(k == j ? 1.0 : 0.0) - d[k] * d[j];
  }
  norm_excess_ = squaredNorm(d) - Interval(1.0);
  for (int k = 0; k < 3; ++k) {
    if (std::abs(direction_[k]) == 1.0) along_axis_ = k;  // the others are then exactly 0
  }
}

ChainPtr PssChain::fromFields(const FieldReader& fields, ChainCommon common) {
  return std::make_shared<PssChain>(std::move(common), fields.point("fixed_node"),
                                    fields.unitVector("direction"));
}

// Sphere of radius R about p cut by the slider line: with w = p - f,
// q = d.w +/- sqrt((d.w)^2 - |w|^2 + R^2).
ChainNodes PssChain::intermediateNodes(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d w = p - fixed_node_;
  const double along = direction_.dot(w);
  ChainNodes nodes;
  nodes.discriminant = along * along - w.squaredNorm() + rodLength() * rodLength();
  nodes.assembled = nodes.discriminant >= 0.0;
  if (nodes.assembled) {
    const double root = std::sqrt(nodes.discriminant);
    nodes.a[0] = fixed_node_ + (along + root) * direction_;
    nodes.a[1] = fixed_node_ + (along - root) * direction_;
  }
  return nodes;
}

namespace {

MOW_VECTOR_KERNEL void pssNodes(const double* __restrict x, const double* __restrict y, const double* __restrict z,
                                std::size_t count, const double f[3], const double d[3], double rod2,
                                double* __restrict discriminant, double* __restrict ax0, double* __restrict ay0,
                                double* __restrict az0, double* __restrict ax1, double* __restrict ay1,
                                double* __restrict az1) {
  const double fx = f[0], fy = f[1], fz = f[2], dx = d[0], dy = d[1], dz = d[2];
  for (std::size_t i = 0; i < count; ++i) {
    const double wx = x[i] - fx, wy = y[i] - fy, wz = z[i] - fz;
    const double along = dx * wx + dy * wy + dz * wz;
    const double disc = along * along - (wx * wx + wy * wy + wz * wz) + rod2;
    const double root = std::sqrt(std::max(disc, 0.0));
    const double t0 = along + root, t1 = along - root;
    discriminant[i] = disc;
    ax0[i] = fx + t0 * dx;
    ay0[i] = fy + t0 * dy;
    az0[i] = fz + t0 * dz;
    ax1[i] = fx + t1 * dx;
    ay1[i] = fy + t1 * dy;
    az1[i] = fz + t1 * dz;
  }
}

}  // namespace

void PssChain::intermediateNodes(const PointBatch& points, const NodeBatch& nodes) const {
  pssNodes(points.x, points.y, points.z, points.count, fixed_node_.data(), direction_.data(), rodLength() * rodLength(),
           nodes.discriminant, nodes.x[0], nodes.y[0], nodes.z[0], nodes.x[1], nodes.y[1], nodes.z[1]);
}

// D = (d . w)^2 - |w|^2 + R^2 = R^2 - |(I - d d^T) w|^2 + (|d|^2 - 1) (d . w)^2. The second
// form encloses it over a box far tighter: in the first, the component of w along the slider
// enters twice with opposite signs, and over a turning box (the hexaglide's rails 0.8 m from
// the platform) that left 89 % of single 6-D cells deep inside the workspace undecided.
Interval PssChain::discriminantEnclosure(const IntervalPoint& p) const {
  using boost::numeric::square;
  const IntervalPoint w = p - pointInterval(fixed_node_);
  if (along_axis_ >= 0) {  // a slider along a coordinate axis: D = R^2 minus the other two squares, exactly
    return Interval(rodLength()) * rodLength() - square(w[(along_axis_ + 1) % 3]) - square(w[(along_axis_ + 2) % 3]);
  }
  const Interval along = dot(pointInterval(direction_), w);
  return Interval(rodLength()) * rodLength() - squaredNorm(offLine(w)) + norm_excess_ * square(along);
}

// grad D = 2 ((d . w) d - w) = -2 (I - d d^T) w: minus twice the node's offset from the
// slider line.
IntervalPoint PssChain::discriminantGradientEnclosure(const IntervalPoint& p) const {
  return Interval(-2.0) * offLine(p - pointInterval(fixed_node_));
}

IntervalPoint PssChain::offLine(const IntervalPoint& w) const {
  return {dot(off_line_[0], w), dot(off_line_[1], w), dot(off_line_[2], w)};
}

NodeEnclosure PssChain::intermediateNodeEnclosure(const IntervalPoint& p) const {
  const IntervalPoint d = pointInterval(direction_);
  const Interval along = dot(d, p - pointInterval(fixed_node_));
  NodeEnclosure nodes;
  nodes.discriminant = discriminantEnclosure(p);
  // Only where the chain assembles do the nodes matter: the root of the discriminant's
  // non-negative part.
  const Interval root = sqrt(max(nodes.discriminant, Interval(0.0)));
  nodes.a[0] = pointInterval(fixed_node_) + (along + root) * d;
  nodes.a[1] = pointInterval(fixed_node_) + (along - root) * d;
  return nodes;
}

IntervalPoint PssChain::nodeTangentEnclosure(const IntervalPoint&) const { return pointInterval(direction_); }

double PssChain::inputOf(const Eigen::Vector3d& a) const { return direction_.dot(a - fixed_node_); }

Eigen::Vector3d PssChain::intermediateNode(double q) const { return fixed_node_ + q * direction_; }

Eigen::Vector3d PssChain::intermediateNodeRate(double) const { return direction_; }

// x along the slider; y and z any completion (the carriage does not turn).
Eigen::Isometry3d PssChain::actuatorFrame() const {
  const Eigen::Vector3d reference = std::abs(direction_.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d y = reference.cross(direction_).normalized();
  Eigen::Matrix3d rotation;
  rotation << direction_, y, direction_.cross(y);
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = rotation;
  frame.translation() = fixed_node_;
  return frame;
}

Eigen::Vector3d PssChain::intermediateNodeOnActuator() const { return Eigen::Vector3d::Zero(); }

// A cylinder of radius R about the slider line, bounded only across the line; with
// limits, the box of the rail's segment widened by R.
std::array<Eigen::Vector2d, 3> PssChain::reachBox(const std::optional<std::array<double, 2>>& input_limits) const {
  std::array<Eigen::Vector2d, 3> box;
  for (int k = 0; k < 3; ++k) {
    if (input_limits) {
      const double first = fixed_node_[k] + (*input_limits)[0] * direction_[k];
      const double last = fixed_node_[k] + (*input_limits)[1] * direction_[k];
      box[k] = Eigen::Vector2d(std::min(first, last) - rodLength(), std::max(first, last) + rodLength());
      continue;
    }
    const double half = direction_[k] == 0.0 ? rodLength() : INFINITY;
    box[k] = Eigen::Vector2d(fixed_node_[k] - half, fixed_node_[k] + half);
  }
  return box;
}

double PssChain::inputDistance(double q1, double q2) const { return std::abs(q1 - q2); }

double PssChain::inputMargin(double q, const std::array<double, 2>& limits) const {
  return std::min(q - limits[0], limits[1] - q);
}

// q = d.(a - f): min <= q and q <= max.
std::vector<NodeHalfSpace> PssChain::inputRange(const std::array<double, 2>& limits) const {
  const double along_fixed = direction_.dot(fixed_node_);
  return {NodeHalfSpace{direction_, -along_fixed - limits[0]}, NodeHalfSpace{-direction_, along_fixed + limits[1]}};
}

// The carriage does not turn: the axis is the file's, in base coordinates.
NodeAxisMap PssChain::fixedEndAxis(const Eigen::Vector3d& axis) const {
  NodeAxisMap map;
  map.offset = axis.normalized();
  return map;
}

std::string PssChain::translateMismatch(const Chain& other, const Eigen::Vector3d& offset) const {
  const auto* pss = dynamic_cast<const PssChain*>(&other);
  if (pss == nullptr) return std::string("it is ") + other.type() + ", not " + kType;
  const double scale = 1.0 + fixed_node_.norm() + rodLength();
  const double tolerance = 1e-9 * scale;
  if ((pss->direction_ - direction_).norm() > 1e-9) return "its slider direction differs";
  if (std::abs(pss->rodLength() - rodLength()) > tolerance) return "its rod length differs";
  if ((pss->fixed_node_ - fixed_node_ - offset).norm() > tolerance) {
    return "its fixed node is not moved by the same offset as its platform node";
  }
  return {};
}

void PssChain::describe(std::ostream& out) const {
  out << "fixed node " << vectorText(fixed_node_) << ", slider direction " << vectorText(direction_)
      << ", rod R = " << numberText(rodLength()) << " m";
}

}  // namespace maximal_workspace
