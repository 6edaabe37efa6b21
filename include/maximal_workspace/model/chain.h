#pragma once
// A kinematic chain (leg) of a fully-parallel manipulator, seen as the chapter's
// characteristic equation f = |p - a(q)|^2 - R^2 = 0 (Eq. 1): one input q moves the
// intermediate node a(q); a rod of length R joins a to the platform node p.
// Each leg type (PSS, RSS, ...) is one class in its own file behind this interface.

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "maximal_workspace/model/interval.h"

namespace maximal_workspace {

// The two roots of a chain's IKP: p takes the + root, n the - root.
enum class Branch : unsigned char { Positive = 0, Negative = 1 };
char branchLetter(Branch branch);

struct ChainBranch {
  double q = 0.0;            // input (m for prismatic, rad for revolute)
  Eigen::Vector3d a;         // intermediate node, base frame
};

// Where the intermediate node can be for a platform node p: the geometric cut alone,
// without the inputs (the workspace engine needs no more, and skips their atan2).
struct ChainNodes {
  double discriminant = 0.0;
  bool assembled = false;
  std::array<Eigen::Vector3d, 2> a;  // p branch, n branch; meaningful only when assembled
};

struct ChainSolution {
  // >= 0 exactly when the chain can be assembled; 0 on the IKP singularity.
  double discriminant = 0.0;
  bool assembled = false;
  std::array<ChainBranch, 2> branches;  // meaningful only when assembled
  const ChainBranch& branch(Branch b) const { return branches[static_cast<int>(b)]; }
};

// intermediateNodes over a box of platform nodes: every p in the box has its discriminant
// in `discriminant` and, where it assembles, its branch-b node in a[b].
struct NodeEnclosure {
  Interval discriminant;
  std::array<IntervalPoint, 2> a;
};

enum class InputKind { Prismatic, Revolute };

// Platform nodes of a batch of poses (base frame), structure of arrays, so that chain
// types can compute many poses per instruction.
struct PointBatch {
  const double* x = nullptr;
  const double* y = nullptr;
  const double* z = nullptr;
  std::size_t count = 0;
};

// intermediateNodes of a batch: per point the discriminant (>= 0 exactly when the chain
// assembles there), and per branch b (0: p, 1: n) the nodes' coordinates, finite but
// meaningless where it does not. Arrays of `count` values each, not overlapping the input.
struct NodeBatch {
  double* discriminant = nullptr;
  std::array<double*, 2> x{}, y{}, z{};
};

// A spherical joint's range: the rod's direction stays within `half_angle` of `axis`
// (docs/robot_file.md says in which frame each end's axis is given).
struct JointCone {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // unit
  double half_angle = 0.0;                          // rad, in (0, pi]
};

// What a real chain allows beyond its reach; every field optional.
struct ChainLimits {
  std::optional<JointCone> fixed_end;     // at the intermediate node a
  std::optional<JointCone> platform_end;  // at the platform node p
  double rod_radius = 0.0;                // m; the rod a-p is a capsule of this radius
};

// Where the intermediate node keeps the input within a range: normal . a + offset >= 0
// (a on the chain's path of a). Half-spaces, so the batch classifier tests a range with
// products and no inverse trigonometry.
struct NodeHalfSpace {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double offset = 0.0;
};

// The fixed-end cone's axis in the base frame as a function of the intermediate node:
// linear * a + offset (constant for a slider, turning with a crank).
struct NodeAxisMap {
  Eigen::Matrix3d linear = Eigen::Matrix3d::Zero();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};

// What every chain has, whatever its type.
struct ChainCommon {
  std::string name;
  std::string input;               // name of the input that drives it
  Eigen::Vector3d platform_node;   // platform coordinates (relative to the TCP)
  double rod_length = 0.0;         // R, between a and p
  ChainLimits limits;
};

class Chain {
 public:
  explicit Chain(ChainCommon common) : common_(std::move(common)) {}
  virtual ~Chain() = default;

  const std::string& name() const { return common_.name; }
  const std::string& input() const { return common_.input; }
  const Eigen::Vector3d& platformNode() const { return common_.platform_node; }
  double rodLength() const { return common_.rod_length; }
  const ChainLimits& limits() const { return common_.limits; }
  const ChainCommon& common() const { return common_; }

  virtual const char* type() const = 0;
  virtual InputKind inputKind() const = 0;
  // Closed-form IKP for a platform node p in the base frame: intermediateNodes plus the
  // input of each branch.
  ChainSolution solve(const Eigen::Vector3d& p) const;
  virtual ChainNodes intermediateNodes(const Eigen::Vector3d& p) const = 0;
  // The same for a batch. This default calls the one above per point; chain types on the
  // workspace engine's hot path override it with branch-free loops the compiler vectorises.
  virtual void intermediateNodes(const PointBatch& points, const NodeBatch& nodes) const;
  // The same over a box of platform nodes, in interval arithmetic (the certificate's
  // enclosures, kinematics/measure_certificate.h); the discriminant alone is cheaper.
  virtual NodeEnclosure intermediateNodeEnclosure(const IntervalPoint& p) const = 0;
  virtual Interval discriminantEnclosure(const IntervalPoint& p) const = 0;
  // The discriminant's gradient in the platform node over a box of them: with the value at
  // a box's centre it bounds the discriminant at every point of the box (mean-value form),
  // whence the share of a cell proven on each side of the reach (MeasureCertificate::assemblyShares).
  virtual IntervalPoint discriminantGradientEnclosure(const IntervalPoint& p) const = 0;
  // True when the discriminant is concave in the platform node: the chain then assembles on
  // a convex set of node positions, and on a straight move between two of them.
  virtual bool concaveDiscriminant() const = 0;
  // A multiple of da/dq at every intermediate node of a box: how the node moves with the
  // input, whence how the rod turns with the platform node (the certificate's derivatives).
  virtual IntervalPoint nodeTangentEnclosure(const IntervalPoint& a) const = 0;
  // The input that puts the intermediate node at `a` (a reachable by this chain).
  virtual double inputOf(const Eigen::Vector3d& a) const = 0;
  virtual Eigen::Vector3d intermediateNode(double q) const = 0;
  // da/dq, for J_IKP.
  virtual Eigen::Vector3d intermediateNodeRate(double q) const = 0;
  // The actuator for robot descriptions: a frame at the actuator (base frame) whose z is
  // the revolute axis (the input turns the actuator link about it) or whose x is the
  // slider direction (the input moves it along it), and where the intermediate node sits
  // in the actuator link's frame: a(q) = frame * motion(q) * node.
  virtual Eigen::Isometry3d actuatorFrame() const = 0;
  virtual Eigen::Vector3d intermediateNodeOnActuator() const = 0;
  // Axis-aligned box (base frame) holding every platform-node position at which this chain
  // can be assembled with its input within `input_limits` (none: any input);
  // +/-infinity where it is unbounded (along a slider line without limits).
  virtual std::array<Eigen::Vector2d, 3> reachBox(const std::optional<std::array<double, 2>>& input_limits) const = 0;
  // Distance between two input values (revolute inputs wrap around).
  virtual double inputDistance(double q1, double q2) const = 0;
  // Signed distance (m or rad) from q to the nearer end of `limits`: >= 0 inside. A
  // revolute range is an arc, and may cross +/-pi.
  virtual double inputMargin(double q, const std::array<double, 2>& limits) const = 0;
  // The half-spaces of the intermediate node where the input is within `limits`.
  virtual std::vector<NodeHalfSpace> inputRange(const std::array<double, 2>& limits) const = 0;
  // Where the fixed end's cone axis points for an intermediate node, given the axis as the
  // robot file states it (docs/robot_file.md).
  virtual NodeAxisMap fixedEndAxis(const Eigen::Vector3d& axis) const = 0;
  // Empty when `other` equals this chain moved by `offset` (base frame): the condition
  // for two chains driven by one input to form a parallelogram. Otherwise the reason.
  virtual std::string translateMismatch(const Chain& other, const Eigen::Vector3d& offset) const = 0;
  // One line of the chain's own parameters, for `mow info`.
  virtual void describe(std::ostream& out) const = 0;

 private:
  ChainCommon common_;
};

using ChainPtr = std::shared_ptr<const Chain>;

const char* inputUnit(InputKind kind);

}  // namespace maximal_workspace
