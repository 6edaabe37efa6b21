#pragma once
// RSS chain: a revolute actuator of axis e turns a crank of length L about the crank
// centre c; a rod of length R joins the crank end a to the platform by two spherical
// joints. a(q) = c + L (cos q u + sin q v), (u, v, e) right-handed and orthonormal.

#include "maximal_workspace/model/chain.h"

namespace maximal_workspace {

class FieldReader;  // the robot file's reader (src/model/field_reader.h)

class RssChain : public Chain {
 public:
  // `crank_zero` is projected onto the plane normal to `axis`; it fixes where q = 0.
  RssChain(ChainCommon common, Eigen::Vector3d crank_centre, Eigen::Vector3d axis,
           double crank_length, Eigen::Vector3d crank_zero);

  static constexpr const char* kType = "RSS";
  // Reads fixed_node (the crank centre), axis, crank_length and the optional crank_zero
  // (default: base x projected onto the crank plane, or base y when x is the axis).
  static ChainPtr fromFields(const FieldReader& fields, ChainCommon common);

  const Eigen::Vector3d& crankCentre() const { return crank_centre_; }
  const Eigen::Vector3d& axis() const { return axis_; }
  double crankLength() const { return crank_length_; }
  const Eigen::Vector3d& crankZero() const { return u_; }

  const char* type() const override { return kType; }
  InputKind inputKind() const override { return InputKind::Revolute; }
  ChainNodes intermediateNodes(const Eigen::Vector3d& p) const override;
  void intermediateNodes(const PointBatch& points, const NodeBatch& nodes) const override;
  NodeEnclosure intermediateNodeEnclosure(const IntervalPoint& p) const override;
  Interval discriminantEnclosure(const IntervalPoint& p) const override;
  IntervalPoint discriminantGradientEnclosure(const IntervalPoint& p) const override;
  // The node reaches a shell about the crank's circle, which is not convex.
  bool concaveDiscriminant() const override { return false; }
  IntervalPoint nodeTangentEnclosure(const IntervalPoint& a) const override;
  double inputOf(const Eigen::Vector3d& a) const override;
  Eigen::Vector3d intermediateNode(double q) const override;
  Eigen::Vector3d intermediateNodeRate(double q) const override;
  Eigen::Isometry3d actuatorFrame() const override;
  Eigen::Vector3d intermediateNodeOnActuator() const override;
  std::array<Eigen::Vector2d, 3> reachBox(const std::optional<std::array<double, 2>>& input_limits) const override;
  double inputDistance(double q1, double q2) const override;
  double inputMargin(double q, const std::array<double, 2>& limits) const override;
  std::vector<NodeHalfSpace> inputRange(const std::array<double, 2>& limits) const override;
  NodeAxisMap fixedEndAxis(const Eigen::Vector3d& axis) const override;
  std::string translateMismatch(const Chain& other, const Eigen::Vector3d& offset) const override;
  void describe(std::ostream& out) const override;

 private:
  // A, B and C of the IKP (intermediateNodes) over a box of platform nodes, and the parts
  // the nodes and the discriminant share: w = p - c, its components along u and v, |w|^2
  // and A^2 + B^2.
  struct Coefficients {
    Interval a, b, c;
    IntervalPoint w;
    Interval along_u, along_v, w_squared, a2_b2;
  };
  Coefficients coefficients(const IntervalPoint& p) const;
  Interval discriminantOf(const Coefficients& coefficients) const;

  Eigen::Vector3d crank_centre_;
  Eigen::Vector3d axis_;  // e, unit
  double crank_length_;
  Eigen::Vector3d u_;     // q = 0 direction
  Eigen::Vector3d v_;     // e x u
  // A bound on the 2-norm of I - u u^T - v v^T - e e^T: the rounding by which the frame is
  // not exactly orthonormal, for the discriminant's factored enclosure.
  double frame_excess_ = 0.0;
};

}  // namespace maximal_workspace
