#pragma once
// PSS chain: a prismatic actuator slides node a along a fixed line, a rod of length R
// joins a to the platform by two spherical joints. a(q) = f + q d.

#include "maximal_workspace/model/chain.h"

namespace maximal_workspace {

class FieldReader;  // the robot file's reader (src/model/field_reader.h)

class PssChain : public Chain {
 public:
  PssChain(ChainCommon common, Eigen::Vector3d fixed_node, Eigen::Vector3d direction);

  static constexpr const char* kType = "PSS";
  // Reads fixed_node and direction; the common fields are already in `common`.
  static ChainPtr fromFields(const FieldReader& fields, ChainCommon common);

  const Eigen::Vector3d& fixedNode() const { return fixed_node_; }
  const Eigen::Vector3d& direction() const { return direction_; }

  const char* type() const override { return kType; }
  InputKind inputKind() const override { return InputKind::Prismatic; }
  ChainNodes intermediateNodes(const Eigen::Vector3d& p) const override;
  void intermediateNodes(const PointBatch& points, const NodeBatch& nodes) const override;
  NodeEnclosure intermediateNodeEnclosure(const IntervalPoint& p) const override;
  Interval discriminantEnclosure(const IntervalPoint& p) const override;
  IntervalPoint discriminantGradientEnclosure(const IntervalPoint& p) const override;
  // R^2 minus the squared distance from the slider line.
  bool concaveDiscriminant() const override { return true; }
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
  IntervalPoint offLine(const IntervalPoint& w) const;  // (I - d d^T) w

  Eigen::Vector3d fixed_node_;
  Eigen::Vector3d direction_;  // unit
  // Rows of I - d d^T, and |d|^2 - 1 (rounding), enclosed: the discriminant as R^2 minus
  // the squared distance from the line, in which each coordinate of p enters once.
  std::array<IntervalPoint, 3> off_line_;
  Interval norm_excess_;
  int along_axis_ = -1;  // the coordinate axis the slider runs along, if it does
};

}  // namespace maximal_workspace
