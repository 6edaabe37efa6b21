#pragma once
// The per-pose work of the workspace engine: is the pose assembled, and what is the DKP
// singularity measure of every working mode there. Built once for a model, a set of
// working modes and a platform orientation that the grid keeps fixed (or not).
//
// When every input drives two chains that are parallel translates at the fixed
// orientation (the delta-like robot's parallelogram couples), each couple's rod vector g
// is shared, and subtracting a couple's first row from its second leaves [0, delta x g]
// with delta the constant offset between their platform nodes. The twist-form J_DKP is
// then block triangular after a row permutation: det J_DKP = sign * det(G) * det(D), G
// with rows g_k and D with rows delta_k x g_k. All working modes' determinants come from
// two triple products each, and only one chain per couple needs its IKP. Otherwise (the
// generic path) the working modes' determinants share minors: they are expanded along the
// chains' rows, both branches of each, in one vectorised pass over a block of poses.

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

class ModeDeterminants;
class ModeConstraints;

// The measure of a working mode whose configuration breaks a limit of the robot at the
// pose (kinematics/constraints.h): the mode is not there, and has no sign.
constexpr double kBlockedMeasure = std::numeric_limits<double>::quiet_NaN();
inline bool modeAdmissible(double measure) { return !std::isnan(measure); }

// Where three inputs drive two chains each (couples): the parity of the permutation from
// the chains' order to the couples' (first chains, then second). On the factorised path a
// working mode's measure is this sign times det(G) det(D) / (L^3 row norms).
double coupleOrderSign(const RobotModel& model);

// The instructions the batch kernels run with on this CPU, as the loader picked their
// clone: "AVX2 (x86-64-v3)", or "x86-64 baseline" where the CPU lacks them (or
// the compiler made one version only: "as compiled").
const char* vectorKernelsInUse();

class PoseClassifier {
 public:
  // `orientation_fixed`: every pose classified has the orientation of `start` (the grid
  // has no rotational variable); required for the factorised path.
  PoseClassifier(const RobotModel& model, std::vector<WorkingMode> modes, const Pose& start, bool orientation_fixed);

  const std::vector<WorkingMode>& modes() const { return modes_; }
  // True when every pose classified keeps the orientation of `start`: then the batch form
  // below classifies grid cells from their TCP positions alone.
  bool orientationFixed() const { return orientation_fixed_; }
  bool factorised() const { return factorised_; }
  // False when some chain cannot be assembled. Otherwise the singularity measure of each
  // working mode (docs/kinematics.md) goes to measures[0 .. modes - 1]: kBlockedMeasure
  // for a mode that breaks one of the robot's limits there.
  bool classify(const Pose& pose, double* measures) const;
  // The same for a batch of TCP positions at the orientation of `start`: inside[i] is 1 or
  // 0, and measures[i * modes + m] is set where inside. Both paths run as vectorised loops
  // over blocks of poses.
  void classify(const PointBatch& positions, std::uint8_t* inside, double* measures) const;
  // The same for poses of any orientation (a grid with rotational variables). Poses that
  // share an orientation in runs, as a grid's do, share its rotation.
  void classify(const Pose* poses, std::size_t count, std::uint8_t* inside, double* measures) const;

 private:
  // Sets couples_, permutation_sign_ and mode_branches_; false when the couples do not
  // factorise after all (not translates at this orientation, or split by a mode).
  bool prepareCouples();
  bool classifyFactorised(const Pose& pose, double* measures) const;
  // classify over a batch of positions where the couples do not factorise: every working
  // mode's determinant from the shared minors.
  void classifyGeneric(const PointBatch& positions, std::uint8_t* inside, double* measures) const;

  const RobotModel& model_;
  std::vector<WorkingMode> modes_;
  Pose start_;
  bool orientation_fixed_ = false;
  bool factorised_ = false;
  // Factorised path: per couple k, its first chain, and the platform-node offsets (base
  // frame, fixed orientation) of both chains from the TCP and between them.
  struct Couple {
    int first_chain = 0;
    Eigen::Vector3d r_first, r_second, offset;
  };
  std::array<Couple, 3> couples_;
  double permutation_sign_ = 1.0;
  std::vector<std::array<int, 3>> mode_branches_;  // branch index of each couple, per mode
  // Generic path: the shared-minor expansion over the working modes' branches.
  std::shared_ptr<const ModeDeterminants> mode_determinants_;
  // The robot's limits per working mode; null when its file sets none.
  std::shared_ptr<const ModeConstraints> constraints_;
};

// Below this |measure| the sign of a computed measure is not trusted: a bound on the
// rounding error of its computation in double precision, at poses farther than 1e-14 m
// from an IKP singularity (docs/kinematics.md, "How exact the sign is").
constexpr double kMeasureTolerance = 1e-9;

// The sign of det J_DKP with a margin: +1 or -1, or 0 when |measure| is under the margin
// (a dexterity margin chosen by the user, 0 by default) or under kMeasureTolerance.
inline std::int8_t bandedSign(double measure, double margin) {
  const double band = margin > kMeasureTolerance ? margin : kMeasureTolerance;
  return measure >= band ? 1 : measure <= -band ? -1 : 0;
}

}  // namespace maximal_workspace
