#pragma once
// What holds over a whole box of poses, proven rather than sampled: whether every pose of
// the box is assembled, and for each working mode a floor on |measure| over the box (where
// the floor is above zero, the measure keeps over the whole box the sign it has at the
// centre: no DKP singularity of that mode lies in the box).
//
// The chains' intermediate nodes are enclosed in interval arithmetic with outward rounding
// (Chain::intermediateNodeEnclosure). Two ways to bound the determinant, both proofs:
// - Couples at the fixed orientation (the factorised path of pose_classifier.h): det J_DKP
//   is +/- det(G) det(D), two triple products of the rods g_k and of delta_k x g_k. Each is
//   enclosed in mean-value form, f(box) in f(centre) + grad f(box) . (box - centre), with
//   the gradient from dg/dp = I - t g^T / (g . t) (t: how the node moves with the input).
//   The enclosure's excess over the true range is second order in the box's size. Where a
//   rod's rate is unbounded (the box touches a chain's reach), in natural form instead.
// - Otherwise, a perturbation bound: with |J(x) - J0| <= E entrywise and X0 a computed
//   inverse of the centre's J0, ||X0 J(x) - I||_inf <= delta; delta < 1 proves every J(x)
//   regular, and |det J(x)| >= |det J0| ((1 - delta) / (1 + residual))^n. First order: it
//   proves less on coarse boxes.
// The robot's limits (inputs, joint cones, rods apart) are proven per working mode over an
// assembled box: kept at every pose, broken at every pose, or undecided. docs/kinematics.md,
// "What the enclosures prove", gives the figures.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/interval.h"
#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

class ModeConstraints;

// The shares of a box's volume proven assembled (every chain, around the centre) and
// proven not assembled (some chain), where no whole-box proof holds.
struct AssemblyShares {
  double assembled = 0.0, unassembled = 0.0;
};

enum class BoxAssembly : std::uint8_t {
  Inside,     // every chain assembles at every pose of the box
  Outside,    // some chain assembles at no pose of the box
  Undecided,  // the box may cross the workspace boundary
};

struct BoxCertificate {
  BoxAssembly assembly = BoxAssembly::Undecided;
  // Where `assembly` is Inside, per working mode (bit m): it keeps every limit of the robot
  // at every pose of the box (every mode, for a robot without limits), or breaks one at
  // every pose. 0 otherwise.
  std::uint64_t limits_kept = 0, limits_broken = 0;
  // Per working mode: every pose of the box has |measure| >= measure_floor[m], with the sign
  // of centre_measure[m]. 0 where nothing is proven (always, unless `assembly` is Inside).
  std::vector<double> measure_floor;
  // The measure at the centre as the workspace engine computes it (NaN where the centre is
  // not assembled or the mode breaks a limit there).
  std::vector<double> centre_measure;
  // How far the measure can move within the box, for proofs over smaller boxes inside it
  // from one sample each (the factorised path over an assembled box; empty otherwise). Per
  // working mode: P = +/- det(G) det(D) at the box's centre and its gradient over the box,
  // signed so that measure = P / (L^3 norms); a lower bound of norms(x) / norms(y); and
  // `product_scale` enclosing L^3 norms over the box.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), half_width = Eigen::Vector3d::Zero();
  std::vector<Interval> product_at_centre;
  std::vector<IntervalPoint> product_gradient;
  std::vector<Interval> product_scale;
  std::vector<double> norm_ratio;
  bool boundsVariation() const { return !product_gradient.empty(); }
  // The least |sample| of working mode `mode`, of the given sign, at a reference (as the
  // engine samples it) that proves |measure| above `floor`, with the sample's sign, over the
  // box reference + [low, high] (offsets along x y z) inside this one; infinity where none
  // does. The gradient's signs count: a box on the side where |measure| grows from the
  // sample is proven whatever its size. One comparison then decides a mode for every sample
  // at that offset.
  double provingMagnitude(std::size_t mode, bool positive, const Eigen::Vector3d& low, const Eigen::Vector3d& high,
                          double floor) const;
  // The share of `cell` (a box of one orientation inside this one) where working mode
  // `mode`'s measure keeps the sign it has at the cell's centre with |measure| beyond
  // `margin` (the analysis's dexterity margin) and kMeasureTolerance (so a cell's code,
  // sampled or proven, has it); 0 unless that holds at the centre. The part is convex and
  // holds the centre, so it lies in the centre's component.
  double shareKeepingSign(std::size_t mode, const PoseBox& cell, double margin) const;

 private:
  // How far the measure may move, over reference + [low, high], towards zero from a sample
  // of sign `sign` (negative) or away from it: provingMagnitude's term.
  double movedOver(std::size_t mode, double sign, const Eigen::Vector3d& low, const Eigen::Vector3d& high) const;
  // Its slack for the few operations' rounding (round-to-nearest: this runs for every
  // cube the classification tries), relative to the magnitudes summed.
  static constexpr double kSlack = 16.0 * std::numeric_limits<double>::epsilon();
};

inline double BoxCertificate::movedOver(std::size_t mode, double sign, const Eigen::Vector3d& low,
                                        const Eigen::Vector3d& high) const {
  // With s the sample's sign, s P(x) >= |P(reference)| + the least of s grad P . (x -
  // reference) over the box (the gradient holds over the segment, inside this box);
  // dividing by L^3 norms(x) gives the move.
  double least = 0.0, magnitudes = 0.0;
  for (int l = 0; l < 3; ++l) {
    const double g_low = sign * (sign > 0.0 ? product_gradient[mode][l].lower() : product_gradient[mode][l].upper());
    const double g_high = sign * (sign > 0.0 ? product_gradient[mode][l].upper() : product_gradient[mode][l].lower());
    const double corner = std::min(std::min(g_low * low[l], g_low * high[l]), std::min(g_high * low[l], g_high * high[l]));
    least += corner;
    magnitudes += std::abs(corner);
  }
  least -= kSlack * magnitudes;
  const Interval& scale = product_scale[mode];
  const double moved = least >= 0.0 ? least / scale.upper() : least / scale.lower();
  return moved - kSlack * std::abs(moved);
}

inline double BoxCertificate::provingMagnitude(std::size_t mode, bool positive, const Eigen::Vector3d& low,
                                               const Eigen::Vector3d& high, double floor) const {
  if (!boundsVariation() || !(norm_ratio[mode] > 0.0)) return std::numeric_limits<double>::infinity();
  // |P(reference)| >= (|sample| - kMeasureTolerance) L^3 norms(reference): the sampled
  // measure is within kMeasureTolerance of the exact one (docs/kinematics.md, "How exact
  // the sign is"). Over the box |measure| >= (|sample| - kMeasureTolerance) norm_ratio +
  // moved, solved here for |sample|; the margin covers the rounding.
  const double moved = movedOver(mode, positive ? 1.0 : -1.0, low, high);
  const double least = kMeasureTolerance + (floor - moved) / (norm_ratio[mode] * (1.0 - kSlack));
  return least + kSlack * std::abs(least);
}

class MeasureCertificate {
 public:
  // `fixed_orientation`: the orientation at which couples factorise (a grid's start pose).
  MeasureCertificate(const RobotModel& model, std::vector<WorkingMode> modes, const Pose& fixed_orientation);
  const std::vector<WorkingMode>& modes() const { return classifier_.modes(); }
  // True when the robot file sets limits: then a box's certificate says which working modes
  // keep them.
  bool hasLimits() const { return limits_ != nullptr; }
  // True when boxes of translations at the fixed orientation get the factorised path's
  // variation bounds (BoxCertificate::provingMagnitude) and signs' shares (shareKeepingSign).
  bool factorises() const { return !couples_.empty(); }
  // Whether certify takes the factorised path over the box (couples, one orientation):
  // there it bounds the measure's variation wherever every rod's rate is bounded.
  bool factorisesOver(const PoseBox& box) const { return factorises() && atFixedOrientation(box); }
  // `wanted` (bit m: working mode m): the modes whose floors and slopes are computed; the
  // others prove nothing (a caller that needs a few of many spares the rest). With
  // `slopes_only`, nothing is computed past a rod whose rate is unbounded over the box (the
  // certificate then proves no mode): for callers that use it only where it bounds the
  // variation.
  BoxCertificate certify(const PoseBox& box, std::uint64_t wanted = ~std::uint64_t{0}, bool slopes_only = false) const;
  // Per working mode, a floor of |measure| over the poses of the box where every chain
  // assembles, for a box that may cross the workspace boundary, signed: where it is not
  // zero, the measure has its sign over them. Zeros for a robot with limits (not proven
  // here).
  std::vector<double> floorsWhereAssembled(const PoseBox& box) const;
  // The assembly part alone (each chain's discriminant), a few times cheaper; only the
  // chains of `chains` (bit i: chain i) when the others are known to assemble over the box.
  // `undecided`, when given, gets the chains whose discriminant may vanish in the box.
  BoxAssembly assemblyOf(const PoseBox& box, std::uint32_t chains = ~0u, std::uint32_t* undecided = nullptr) const;
  // The same, for a box of one cell: where the natural enclosure leaves a chain undecided
  // over a translation, the mean-value form too (the centre's discriminant plus its
  // gradient's reach), which decides many of the cells the boundary passes near. Not on
  // larger boxes: there it would send cubes near the boundary to certificates that prove
  // fewer working modes than splitting them does (docs/benchmarks.md).
  BoxAssembly assemblyOfCell(const PoseBox& box, std::uint32_t chains = ~0u, std::uint32_t* undecided = nullptr) const;
  // The chains (bit i: chain i) that may come near their reach limit in the box: whose
  // discriminant's enclosure over it is not above `spreads` times its own width (about
  // that many boxes from the limit, or across it). The thin layers' check looks for sign
  // layers there (workspace/thin_layers.h), within half a spread. Only `chains` are
  // enclosed: one not near over a box is not near over any box inside it (its enclosure
  // there lies inside, and is no wider).
  std::uint32_t chainsNearReach(const PoseBox& box, double spreads = kNearReachSpreads, std::uint32_t chains = ~0u) const;
  static constexpr double kNearReachSpreads = 0.5;
  // Where the box may cross the workspace boundary, the shares of it proven on each side,
  // from each chain's discriminant at the centre and its gradient over the box: the part
  // proven assembled is convex and holds the centre, so it lies in the centre's component.
  // Only over a translation (a box of one orientation); {0, 0} otherwise. Only the chains
  // of `chains` when the others are known to assemble over the box.
  AssemblyShares assemblyShares(const PoseBox& box, std::uint32_t chains = ~0u) const;
  // The chains (bit i: chain i) that assemble all along a translation between two poses
  // where they assemble (Chain::concaveDiscriminant: the platform nodes move straight).
  std::uint32_t chainsAssembledAlongTranslations() const { return assembled_along_translations_; }

 private:
  struct ChainEnclosures;
  struct CoupleRows;
  BoxAssembly assembly(const PoseBox& box, std::uint32_t chains, std::uint32_t* undecided, bool mean_value) const;
  // The platform nodes' offsets from the TCP (base frame) over the box's orientations.
  std::array<IntervalPoint, kMaxChains> fromTcp(const PoseBox& box) const;
  // Sets couples_ (the factorised path's); false when the couples do not factorise.
  bool prepareCouples();
  // Whether every pose of the box has the fixed orientation (where the couples factorise).
  bool atFixedOrientation(const PoseBox& box) const {
    return box.angle_half_width.isZero() && box.centre.euler_zyz == fixed_orientation_.euler_zyz;
  }
  void narrowAllNodes(bool couples_translate, ChainEnclosures& chains) const;
  void narrowNodes(const IntervalPoint& platform_node, const Chain& chain, NodeEnclosure& nodes,
                   std::array<double, 2>& rod_moves) const;
  void provenLimits(const PoseBox& box, const ChainEnclosures& chains, BoxCertificate& result) const;
  // Every chain's discriminant over the box, and the intermediate nodes of the chains that
  // need them: the couples' first chains on the factorised path without limits (whose rows
  // alone enter the floors), every chain otherwise; the others' nodes are left unbounded.
  BoxAssembly encloseChains(const PoseBox& box, ChainEnclosures& chains) const;
  BoxCertificate blankCertificate() const;
  // factorisedFloors's steps: the couples' rows over the box (`mean_value`: with their
  // derivatives where bounded), and one working mode's floor and slopes from them.
  // Only the rows the modes of `wanted` use; with `slopes_only`, they stop at the first
  // rod whose rate is unbounded.
  void enclosedCoupleRows(const PoseBox& box, const ChainEnclosures& chains, bool mean_value, CoupleRows& rows,
                          std::uint64_t wanted, bool slopes_only) const;
  void meanValueFloor(const CoupleRows& rows, const int* branches, std::size_t mode, const Eigen::Vector3d& half_width,
                      const Interval& norms, const Interval& cube, BoxCertificate& result) const;
  // `mean_value`: enclose det(G) and det(D) in mean-value form where the rods' rates are
  // bounded over the box (then the certificate gets slopes); else in natural form, and
  // `signs` (when given) gets the sign the measure keeps where its floor is above zero.
  // Both floors: for the working modes of `wanted` only; `slopes_only` as certify's.
  void factorisedFloors(const PoseBox& box, const ChainEnclosures& chains, bool mean_value,
                        BoxCertificate& result, double* signs = nullptr, std::uint64_t wanted = ~std::uint64_t{0},
                        bool slopes_only = false) const;
  void perturbationFloors(const PoseBox& box, const ChainEnclosures& chains, BoxCertificate& result,
                          std::uint64_t wanted = ~std::uint64_t{0}) const;

  const RobotModel& model_;
  std::uint64_t cache_id_;  // keys the nodes it turns, cached per angular range
  PoseClassifier classifier_;
  // The same at the fixed orientation, as a grid without rotational variables classifies
  // (the couples' factorised path where they factorise: several times cheaper per pose).
  PoseClassifier fixed_classifier_;
  std::shared_ptr<const ModeConstraints> limits_;  // null when the robot file sets none
  Pose fixed_orientation_;
  // The factorised path's couples at the fixed orientation; empty when they do not factorise.
  struct Couple {
    int first_chain = 0;
    Eigen::Vector3d r_first, r_second;
    int second_chain = 0;
  };
  std::vector<Couple> couples_;
  double product_sign_ = 1.0;  // coupleOrderSign's, where the couples factorise
  // fromTcp at the fixed orientation, which every box of a grid without rotational
  // variables keeps: made once.
  std::array<IntervalPoint, kMaxChains> fixed_from_tcp_;
  std::uint32_t assembled_along_translations_ = 0;
};

}  // namespace maximal_workspace
