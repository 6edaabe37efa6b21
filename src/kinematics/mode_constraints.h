#pragma once
// RobotConstraints in batch form for the pose classifier: which of the analysed working
// modes keep every limit, over a block of poses, with products and square roots only; and
// the same checks proven over a box of poses for the certificate (internal to the
// kinematics). Each check is made once per chain and branch (inputs, cones) or per pair of
// rods and branches, whatever the number of modes sharing it.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/interval.h"
#include "maximal_workspace/model/robot_model.h"

namespace maximal_workspace {

constexpr std::size_t kConstraintBlock = 64;
constexpr std::size_t kRodRun = 16;  // poses whose rods are boxed together

// One chain over a block of poses, base frame: its platform node p, both branches'
// intermediate nodes a, and where its platform-end cone's axis points (read only for a
// chain with that cone). The arrays hold p and a moved by -shift: a couple's second chain
// is its first one's arrays with the couple's offset as shift, no copy.
struct ChainBlock {
  const double* p[3];
  const double* a[2][3];
  const double* platform_axis[3];
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
};

// One chain over a box of poses (interval enclosures, base frame), and at the box's centre:
// its platform node p, both branches' intermediate nodes a, and its platform-end cone's
// axis (read only for a chain with that cone).
struct ChainBox {
  IntervalPoint p;
  std::array<IntervalPoint, 2> a;
  IntervalPoint platform_axis;
  Eigen::Vector3d p_centre = Eigen::Vector3d::Zero();
  std::array<Eigen::Vector3d, 2> a_centre{};
  // Per branch, how far the rod p - a turns from its centre value over the box: infinite
  // unless the box has one orientation (every platform node then moves as the TCP does).
  std::array<double, 2> rod_moves{};
  double rod_length = 0.0;
};

// What holds over a whole box, per working mode (bit m): it keeps every limit at every
// pose (`kept`), or breaks one at every pose (`broken`); neither where the box may cross a
// limit.
struct BoxLimits {
  std::uint64_t kept = 0, broken = 0;
};

class ModeConstraints {
 public:
  // `couples_translate`: the two chains of a couple are translates at every pose checked
  // (the classifier's factorised case): in one branch their rods are parallel, and their
  // distance has a shorter closed form.
  ModeConstraints(const RobotModel& model, const std::vector<WorkingMode>& modes, bool couples_translate);

  bool active() const { return !branch_checks_.empty() || !pair_checks_.empty(); }
  bool hasPlatformCone(int chain) const;
  // admissible[i]: bit m set where working mode m keeps every limit at pose i (count up to
  // kConstraintBlock); 0 where assembled[i] is 0. A check is skipped where no pose still
  // needs it, and the exact rod distance where a cheap lower bound clears every pose.
  void admissible(std::size_t count, const ChainBlock* chains, const std::uint8_t* assembled,
                  std::uint64_t* admissible) const;
  // The same checks proven over a box every chain assembles over (chains[c] per chain):
  // inputs and cones by interval enclosures, rods by their distance at the centre less
  // how far the box moves their ends.
  // `couples_translate`: as for the constructor, over this box (the classifier's case and
  // orientation).
  BoxLimits overBox(const ChainBox* chains, bool couples_translate) const;

 private:
  // The pairs of rods over poses [begin, begin + count) of the block.
  void checkRods(std::size_t begin, std::size_t count, const ChainBlock* chains, std::uint64_t* admissible) const;

  // The limits of one chain in one branch, and the modes taking that branch.
  struct BranchCheck {
    int chain = 0, branch = 0;
    std::vector<NodeHalfSpace> input_range;
    bool fixed_cone = false, platform_cone = false;
    NodeAxisMap fixed_axis;
    double fixed_cos = 0.0, platform_cos = 0.0;  // R cos(half_angle)
    std::uint64_t modes = 0;
  };
  // Two rods in given branches, the squared distance their axes must keep, and the modes
  // taking both branches.
  struct PairCheck {
    int chains[2] = {0, 0}, branches[2] = {0, 0};
    double distance2 = 0.0;
    std::uint64_t modes = 0;
    bool translates = false;  // a couple's two rods in one branch
  };
  std::vector<BranchCheck> branch_checks_;
  std::vector<PairCheck> pair_checks_;
  std::uint64_t all_modes_ = 0;
  std::vector<bool> platform_cone_;
};

}  // namespace maximal_workspace
