// The certificate of a box of poses (kinematics/measure_certificate.h) is a proof: on every
// shipped kind of robot and box (translations, turning platforms, couples factorised, 64
// uncoupled working modes, a planar robot, limits), whatever it proves holds at random
// poses and corners of the box; and on the 5R, whose workspace is the intersection of two
// annuli in closed form, boxes well inside or well outside are decided.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/measure_certificate.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/rss_chain.h"
#include "kinematics/midpoint_radius.h"
#include "kinematics/proven_share.h"
#include "orientation_grid.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

struct BoxCase {
  std::string robot;
  bool uncoupled = false;
  double position_spread = 0.15, position_half_width = 0.015;  // m
  double angle_spread = 0.0, angle_half_width = 0.0;           // rad
  bool tilt_torsion = false;  // boxes of a tilt-and-torsion grid: psi moves with phi
};

// A pose of the box: each coordinate at its low end, high end (corners, bits of `corner`)
// or drawn uniformly. Where phi + psi has a half width of its own (a tilt-and-torsion
// box), the last coordinate drawn is that sum, and psi follows phi.
Pose poseIn(const PoseBox& box, int corner) {
  Pose pose = box.centre;
  const bool summed = box.angle_sum_half_width.has_value();
  for (int k = 0; k < 6; ++k) {
    const double half = k < 3 ? box.position_half_width[k] : k == 5 && summed ? *box.angle_sum_half_width
                                                                             : box.angle_half_width[k - 3];
    const double offset = corner >= 0 ? ((corner >> k) & 1 ? half : -half) : test::uniform(-half, half);
    if (k < 3) pose.position[k] += offset;
    else if (k == 5 && summed) pose.euler_zyz[2] += offset - (pose.euler_zyz[0] - box.centre.euler_zyz[0]);
    else pose.euler_zyz[k - 3] += offset;
  }
  return pose;
}

struct Counts {
  int inside = 0, outside = 0, signs = 0, sub_box_signs = 0, limits_kept = 0, limits_broken = 0;
  bool limits = false;  // the robot file sets some
};

// A box inside `box`, drawn at random.
PoseBox subBox(const PoseBox& box) {
  PoseBox sub = box;
  for (int k = 0; k < 3; ++k) {
    const double half = box.position_half_width[k];
    sub.position_half_width[k] = test::uniform(0.0, 1.0) * half;
    sub.centre.position[k] += test::uniform(-1.0, 1.0) * (half - sub.position_half_width[k]);
  }
  return sub;
}

// BoxCertificate::provingMagnitude over boxes inside a proven box, from the measure sampled at a
// reference: the sub-box's centre, a corner of it, a pose in it, or a pose anywhere in the
// proven box (as the classification tries a cube from its parent's sample beside it). The
// sign and the floor hold at corners and random poses of the sub-box.
void checkSubBoxes(const PoseBox& box, const BoxCertificate& proof, const PoseClassifier& classifier, Counts& counts) {
  const std::size_t modes = classifier.modes().size();
  std::vector<double> at_reference(modes), measures(modes);
  for (int b = 0; b < 8; ++b) {
    const PoseBox sub = subBox(box);
    Pose reference = sub.centre;
    for (int k = 0; k < 3; ++k) {
      const double half = sub.position_half_width[k], outer = box.position_half_width[k];
      switch (b % 4) {
        case 0: break;
        case 1: reference.position[k] += k == b % 3 ? half : -half; break;
        case 2: reference.position[k] += test::uniform(-half, half); break;
        default: reference.position[k] = box.centre.position[k] + test::uniform(-outer, outer);
      }
    }
    const Eigen::Vector3d low = sub.centre.position - sub.position_half_width - reference.position;
    const Eigen::Vector3d high = sub.centre.position + sub.position_half_width - reference.position;
    ASSERT_TRUE(classifier.classify(reference, at_reference.data()));
    for (int s = -16; s < 8; ++s) {
      ASSERT_TRUE(classifier.classify(poseIn(sub, s >= 0 ? s : -1), measures.data()));
      for (std::size_t m = 0; m < modes; ++m) {
        if (!(proof.limits_kept >> m & 1u)) continue;
        // Floors from a tenth of the sample's magnitude to all of it: where the sample lies
        // beyond provingMagnitude, the floor holds.
        for (double share : {0.1, 0.5, 1.0}) {
          const double floor = share * std::abs(at_reference[m]);
          if (!(std::abs(at_reference[m]) > proof.provingMagnitude(m, at_reference[m] > 0.0, low, high, floor))) continue;
          ++counts.sub_box_signs;
          EXPECT_GT(measures[m] * at_reference[m], 0.0) << "sub-box " << b << " mode " << m;
          EXPECT_GE(std::abs(measures[m]), floor - 1e-12) << "sub-box " << b << " mode " << m << " share " << share;
        }
      }
    }
  }
}

// What the limits' proof of a box says at one of its poses (assembled), against the margins
// of each mode's configuration there (RobotConstraints, from the pose's IKP).
void checkLimitProof(const RobotModel& model, const std::vector<WorkingMode>& modes, const RobotConstraints& constraints,
                     const Pose& pose, const BoxCertificate& proof, const double* measures, Counts& counts) {
  const IkpResult ikp = solveIkp(model, pose);
  for (std::size_t m = 0; m < modes.size(); ++m) {
    const bool breaks = constraints.margins(pose, ikp, modes[m]).violated != ConstraintKind::None;
    if (proof.limits_kept >> m & 1u) {
      ++counts.limits_kept;
      EXPECT_FALSE(breaks) << model.name << " mode " << modes[m].name << ": a limit broken in a box proven to keep them";
      EXPECT_TRUE(modeAdmissible(measures[m])) << model.name << " mode " << modes[m].name;
    }
    if (proof.limits_broken >> m & 1u) {
      ++counts.limits_broken;
      EXPECT_TRUE(breaks) << model.name << " mode " << modes[m].name << ": every limit kept in a box proven to break one";
    }
  }
}

// A box of the case drawn about the robot's reference pose: its centre within the
// spreads, each half width between `least` and 1 times the case's.
PoseBox drawnBox(const RobotModel& model, const BoxCase& box_case, double least) {
  PoseBox box;
  box.centre = model.reference.pose;
  for (int k = 0; k < 3; ++k) {
    box.centre.position[k] += test::uniform(-box_case.position_spread, box_case.position_spread);
    box.position_half_width[k] = test::uniform(least, 1.0) * box_case.position_half_width;
    if (box_case.angle_spread == 0.0) continue;
    box.centre.euler_zyz[k] += test::uniform(-box_case.angle_spread, box_case.angle_spread);
    box.angle_half_width[k] = test::uniform(least, 1.0) * box_case.angle_half_width;
  }
  if (box_case.tilt_torsion) {  // as Grid::cellsBox makes them, the tilt from the pole on
    box.centre.euler_zyz[1] = test::uniform(0.0, box_case.angle_spread);
    box.angle_sum_half_width = box.angle_half_width[2];
    box.angle_half_width[2] += box.angle_half_width[0];
  }
  return box;
}

Counts checkBoxes(const BoxCase& box_case) {
  const RobotModel model = loadRobotFile(test::sourcePath(box_case.robot));
  const std::vector<WorkingMode> modes = box_case.uncoupled ? uncoupledWorkingModes(model) : coupledWorkingModes(model);
  const MeasureCertificate certificate(model, modes, model.reference.pose);
  const PoseClassifier classifier(model, modes, model.reference.pose, false);
  const RobotConstraints constraints(model);  // the reference: margins from each pose's IKP
  std::vector<double> measures(modes.size());
  Counts counts;
  counts.limits = constraints.active();
  for (int b = 0; b < 300; ++b) {
    const PoseBox box = drawnBox(model, box_case, 0.02);
    const BoxCertificate proof = certificate.certify(box);
    counts.inside += proof.assembly == BoxAssembly::Inside;
    counts.outside += proof.assembly == BoxAssembly::Outside;
    for (int s = -64; s < 64; ++s) {  // 64 corners (some repeated), 64 poses drawn
      const Pose pose = poseIn(box, s >= 0 ? s : -1);
      const bool assembled = classifier.classify(pose, measures.data());
      if (proof.assembly == BoxAssembly::Outside) EXPECT_FALSE(assembled) << box_case.robot << " box " << b;
      if (proof.assembly != BoxAssembly::Inside) continue;
      EXPECT_TRUE(assembled) << box_case.robot << " box " << b;
      checkLimitProof(model, modes, constraints, pose, proof, measures.data(), counts);
      for (std::size_t m = 0; m < modes.size(); ++m) {
        if (proof.measure_floor[m] <= 0.0 || !(proof.limits_kept >> m & 1u)) continue;
        ++counts.signs;
        EXPECT_GT(measures[m] * proof.centre_measure[m], 0.0) << box_case.robot << " box " << b << " mode " << modes[m].name;
        // The sampled measure's own rounding is under 1e-12 (docs/kinematics.md).
        EXPECT_GE(std::abs(measures[m]), proof.measure_floor[m] - 1e-12) << box_case.robot << " box " << b << " mode " << modes[m].name;
      }
    }
    if (proof.assembly == BoxAssembly::Inside) checkSubBoxes(box, proof, classifier, counts);
  }
  std::printf("%-32s %s: %d boxes inside, %d outside, %d proven signs checked, %d in boxes inside them; "
              "limits kept %d, broken %d (mode x pose)\n",
              box_case.robot.c_str(), box_case.uncoupled ? "uncoupled" : "coupled", counts.inside, counts.outside,
              counts.signs, counts.sub_box_signs, counts.limits_kept, counts.limits_broken);
  return counts;
}

// The midpoint-radius sums the factorised path uses per working mode: every sum of
// products of points drawn in the balls (ends and zero included), computed in long double,
// lies in the result, and magnitude / mignitude bound its |value|. The balls come from
// intervals of every kind: narrow or wide, holding zero or not, near underflow, and a
// large value with a small one (cancellation).
TEST(MidpointRadius, SumsOfProductsHoldEveryProductOfPointsInTheBalls) {
  std::mt19937_64 random(20261128);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), fraction(0.0, 1.0);
  const double scales[] = {1e-310, 1e-20, 1e-3, 1.0, 1e3, 1e20};
  auto drawInterval = [&] {
    const double scale = scales[random() % 6];
    const double centre = unit(random) * scale, width = (random() % 3 == 0 ? 0.0 : fraction(random)) * scale;
    return random() % 4 == 0 ? Interval(centre) : Interval(centre - width, centre + width);
  };
  auto pointIn = [&](const Interval& x) {
    switch (random() % 4) {
      case 0: return static_cast<long double>(x.lower());
      case 1: return static_cast<long double>(x.upper());
      default: return static_cast<long double>(x.lower()) + (static_cast<long double>(x.upper()) - x.lower()) * fraction(random);
    }
  };
  int sums = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const int terms = 1 + static_cast<int>(random() % 12);
    std::vector<Interval> a(terms), b(terms);
    BallDot sum;
    for (int i = 0; i < terms; ++i) {
      a[i] = drawInterval(), b[i] = drawInterval();
      if (trial % 5 == 0 && i == 1) a[1] = -a[0], b[1] = b[0];  // cancellation
      sum.add(toBall(a[i]), toBall(b[i]));
    }
    const Ball result = sum.result();
    const Interval enclosure = toInterval(result);
    for (int draw = 0; draw < 8; ++draw) {
      long double exact = 0.0L;
      for (int i = 0; i < terms; ++i) exact += pointIn(a[i]) * pointIn(b[i]);
      ASSERT_LE(enclosure.lower(), exact) << "trial " << trial;
      ASSERT_GE(enclosure.upper(), exact) << "trial " << trial;
      ASSERT_GE(static_cast<long double>(magnitude(result)), std::abs(exact)) << "trial " << trial;
      ASSERT_LE(static_cast<long double>(mignitude(result)), std::abs(exact)) << "trial " << trial;
      ++sums;
    }
  }
  // A cross product of balls holds the cross product of points drawn in them.
  for (int trial = 0; trial < 2000; ++trial) {
    Interval a[3], b[3];
    Ball ball_a[3], ball_b[3], product[3];
    for (int c = 0; c < 3; ++c) a[c] = drawInterval(), b[c] = drawInterval(), ball_a[c] = toBall(a[c]), ball_b[c] = toBall(b[c]);
    cross(ball_a, ball_b, product);
    long double x[3], y[3];
    for (int c = 0; c < 3; ++c) x[c] = pointIn(a[c]), y[c] = pointIn(b[c]);
    for (int c = 0; c < 3; ++c) {
      const int i = (c + 1) % 3, j = (c + 2) % 3;
      const long double exact = x[i] * y[j] - x[j] * y[i];
      const Interval enclosure = toInterval(product[c]);
      ASSERT_LE(enclosure.lower(), exact) << "trial " << trial;
      ASSERT_GE(enclosure.upper(), exact) << "trial " << trial;
    }
  }
  EXPECT_EQ(sums, 160000);
}

TEST(MeasureCertificate, WhatABoxProofSaysHoldsAtEveryPoseTried) {
  const std::vector<BoxCase> cases = {
      {"config/delta_like.yaml"},                             // couples: mean-value triple products
      {"config/delta_like.yaml", true, 0.15, 0.003},          // 64 working modes: perturbation bound
      {"config/clavel_delta.yaml", false, 0.3, 0.01},         // cranks
      {"config/linear_delta.yaml", false, 0.15, 0.01},        // limits: sliders, cones, rods
      {"config/linear_delta.yaml", false, 0.15, 0.003},
      {"config/delta_like_limited.yaml", false, 0.3, 0.01},   // limits: cranks and sliders
      {"config/rotary_delta.yaml", false, 0.15, 0.003},       // limits: cranks
      {"config/five_bar.yaml", false, 0.15, 0.01},            // planar
      {"config/hexapod_6rss.yaml", false, 0.05, 0.002, 0.2, 0.01},  // turning platform
      {"config/hexapod_6rss_long.yaml", false, 0.05, 0.002, 0.2, 0.01},  // DKP singularities under tilt
      {"config/hexaglide_6pss.yaml", false, 0.6, 0.01, 0.3, 0.01},      // rails, cones, turning platform
      {"config/hexaglide_6pss.yaml", false, 0.3, 0.01, 0.3, 0.04, true},  // tilt-and-torsion boxes
      {"test/robots/planar_3rrr.yaml", false, 0.05, 0.003, 0.5, 0.02},
  };
  for (const BoxCase& box_case : cases) {
    const Counts counts = checkBoxes(box_case);
    EXPECT_GT(counts.inside, 0) << box_case.robot;
    EXPECT_GT(counts.signs, 0) << box_case.robot << ": nothing proven, nothing checked";
    // The factorised path bounds the measure's variation too (the deltas).
    if (&box_case - cases.data() < 7 && !box_case.uncoupled) {
      EXPECT_GT(counts.sub_box_signs, 0) << box_case.robot << ": no variation bound checked";
    }
    if (counts.limits) {
      EXPECT_GT(counts.limits_kept, 0) << box_case.robot << ": no limit proven kept";
      EXPECT_GT(counts.limits_broken, 0) << box_case.robot << ": no limit proven broken";
    }
  }
}

// The cells of a tilt-and-torsion grid about the hexaglide's reference, where every chain
// assembles with room to spare at every pose tried (the discriminants at the cell's
// corners and at random poses above 0.02 m^2, against a spread over the cell of about
// 0.01 m^2), are proven assembled whole, at the pole and at 15 deg of tilt alike. Before
// the enclosures kept phi + psi apart and the slider's offset along its rail out of the
// discriminant, most such cells of a 6-D analysis were left undecided and sampled.
TEST(MeasureCertificate, TiltAndTorsionCellsDeepInsideTheHexaglidesWorkspaceAreProvenAssembled) {
  const RobotModel model = loadRobotFile(test::sourcePath("config/hexaglide_6pss.yaml"));
  const Grid grid(model, test::orientationGrid(model, 0.02, {{-0.02, 0.02}, {-0.02, 0.02}, {0.28, 0.32}},
                                               OrientationSet{0.26, {-0.26, 0.26}, 0.087}));
  const MeasureCertificate certificate(model, coupledWorkingModes(model), model.reference.pose);
  int roomy = 0, proven = 0;
  for (std::uint64_t index = 0; index < grid.cellCount(); ++index) {
    const PoseBox box = grid.cellBox(index);
    double lowest = std::numeric_limits<double>::infinity();
    for (int s = -16; s < 64; ++s) {
      const Pose pose = poseIn(box, s >= 0 ? s : -1);
      for (const ChainPtr& chain : model.chains) lowest = std::min(lowest, chain->solve(pose.toBase(chain->platformNode())).discriminant);
    }
    if (lowest < 0.02) continue;
    ++roomy;
    std::uint32_t undecided = 0;
    proven += certificate.assemblyOf(box, ~0u, &undecided) == BoxAssembly::Inside;
  }
  EXPECT_GT(roomy, static_cast<int>(grid.cellCount()) / 2);
  EXPECT_EQ(proven, roomy);
}

// Cubes of 2 cells a side of issue 30's grid (10 mm, 2.5 deg, tilt and torsion to 15 deg)
// about the hexaglide's reference, where its reference working mode stays well regular (the
// measure at the cube's 64 corners and 16 random poses at least 0.25 in magnitude, 0.449
// at the reference, by the robot file) and keeps every limit there: the certificate proves
// that mode's sign over each. A turning cube moves the Jacobian's entries by about a tenth
// of their size, and the perturbation bound on |X0| |J(x) - J0| entry by entry, first
// order, proved none of them; the bound on the rows' changes in mean-value form,
// preconditioned on the right, keeps the cancellations within each row.
TEST(MeasureCertificate, TurningCubesWhereTheReferenceModeStaysRegularAreProven) {
  const RobotModel model = loadRobotFile(test::sourcePath("config/hexaglide_6pss.yaml"));
  const Grid grid(model, test::orientationGrid(model, 0.01, {{-0.04, 0.04}, {-0.04, 0.04}, {0.26, 0.34}},
                                               OrientationSet{0.2618, {-0.2618, 0.2618}, 0.0436}));
  const std::vector<WorkingMode> all = uncoupledWorkingModes(model);
  const std::vector<WorkingMode> reference = {all[workingModeIndex(all, "ppnnpp", "the test")]};
  const MeasureCertificate certificate(model, reference, model.reference.pose);
  const PoseClassifier classifier(model, reference, model.reference.pose, false);
  std::mt19937_64 random(20261130);
  int regular = 0, proven = 0;
  for (int drawn = 0; drawn < 400; ++drawn) {
    GridCell first{}, last{};
    for (int d = 0; d < grid.dims(); ++d) {
      first[d] = std::uniform_int_distribution<std::int64_t>(0, grid.size(d) - 2)(random);
      last[d] = first[d] + 1;
    }
    const PoseBox box = grid.cellsBox(first, last);
    double lowest = std::numeric_limits<double>::infinity();
    for (int s = -16; s < 64; ++s) {
      double measure = 0.0;
      if (!classifier.classify(poseIn(box, s >= 0 ? s : -1), &measure) || !modeAdmissible(measure)) measure = 0.0;
      lowest = std::min(lowest, std::abs(measure));
    }
    if (lowest < 0.25) continue;
    ++regular;
    proven += certificate.certify(box).measure_floor[0] > 0.0;
  }
  EXPECT_GT(regular, 40);
  EXPECT_EQ(proven, regular);
}

// The 5R's platform point is assembled exactly where it lies in both chains' annuli
// |L - R| <= |p - c| <= L + R. A box whose every point is farther than `margin` inside
// both (or outside one) must be decided: the enclosures' excess is a small multiple of the
// box's size.
TEST(MeasureCertificate, FiveBarBoxesAwayFromTheAnnuliEdgesAreDecided) {
  const RobotModel model = loadRobotFile(test::sourcePath("config/five_bar.yaml"));
  const MeasureCertificate certificate(model, coupledWorkingModes(model), model.reference.pose);
  const double half = 0.002;
  int decided = 0;
  for (double x = -0.6; x <= 0.6; x += 0.01) {
    for (double y = -0.6; y <= 0.6; y += 0.01) {
      // Distance of the box's centre from each annulus' nearer edge: > 0 inside.
      double depth = INFINITY;
      for (const ChainPtr& chain : model.chains) {
        const auto& rss = dynamic_cast<const RssChain&>(*chain);
        const double r = std::hypot(x - rss.crankCentre().x(), y - rss.crankCentre().y());
        const double inner = std::abs(rss.crankLength() - rss.rodLength()), outer = rss.crankLength() + rss.rodLength();
        depth = std::min(depth, std::min(r - inner, outer - r));
      }
      const double margin = 4.0 * std::sqrt(2.0) * half;  // half-diagonal, four times
      if (std::abs(depth) < margin) continue;
      PoseBox box;
      box.centre = model.reference.pose;
      box.centre.position = Eigen::Vector3d(x, y, 0.0);
      box.position_half_width = Eigen::Vector3d(half, half, 0.0);
      const BoxAssembly assembly = certificate.certify(box).assembly;
      EXPECT_EQ(assembly, depth > 0.0 ? BoxAssembly::Inside : BoxAssembly::Outside) << x << ", " << y;
      ++decided;
    }
  }
  EXPECT_GT(decided, 10000);
}

// Boxes about poses where some working mode is within 2 mm (or 0.002 rad) of a limit of
// each kind, clear at the centre: the proofs must see the limit crossing the box (rods:
// their distance moves as much as the ends do, not as the centre's).
TEST(MeasureCertificate, LimitProofsHoldInBoxesNearEachLimit) {
  for (const char* robot : {"config/linear_delta.yaml", "config/delta_like_limited.yaml", "config/rotary_delta.yaml",
                            "test/robots/linear_delta_thick_rods.yaml"}) {
    const RobotModel model = loadRobotFile(test::sourcePath(robot));
    const std::vector<WorkingMode> modes = coupledWorkingModes(model);
    const MeasureCertificate certificate(model, modes, model.reference.pose);
    const PoseClassifier classifier(model, modes, model.reference.pose, false);
    const RobotConstraints constraints(model);
    std::vector<double> measures(modes.size());
    // One draw of centres serves the three kinds: a centre near a limit of some kind makes
    // a box for that kind, until each has 150.
    const std::array<ConstraintKind, 3> kinds = {ConstraintKind::InputRange, ConstraintKind::JointCone,
                                                 ConstraintKind::Interference};
    std::array<Counts, 3> counts;
    std::array<int, 3> boxes{};
    const auto full = [&boxes] { return std::all_of(boxes.begin(), boxes.end(), [](int n) { return n >= 150; }); };
    for (int tries = 0; tries < 200000 && !full(); ++tries) {
      Pose centre = model.reference.pose;
      for (int k = 0; k < 3; ++k) centre.position[k] += test::uniform(-0.3, 0.3);
      const IkpResult ikp = solveIkp(model, centre);
      if (!ikp.assembled) continue;
      std::array<bool, 3> near{};
      for (const WorkingMode& mode : modes) {
        const ConstraintMargins margins = constraints.margins(centre, ikp, mode);
        if (!margins.satisfied()) continue;
        near[0] = near[0] || margins.min_input < 0.002;
        near[1] = near[1] || margins.min_cone < 0.002;
        near[2] = near[2] || margins.min_rod_distance < 0.002;
      }
      for (int kind = 0; kind < 3; ++kind) {
        if (!near[kind] || boxes[kind] >= 150) continue;
        PoseBox box;
        box.centre = centre;
        for (int k = 0; k < 3; ++k) box.position_half_width[k] = test::uniform(0.001, 0.008);
        const BoxCertificate proof = certificate.certify(box);
        if (proof.assembly != BoxAssembly::Inside) continue;
        ++boxes[kind];
        for (int s = -64; s < 64; ++s) {
          const Pose pose = poseIn(box, s >= 0 ? s : -1);
          ASSERT_TRUE(classifier.classify(pose, measures.data()));
          checkLimitProof(model, modes, constraints, pose, proof, measures.data(), counts[kind]);
        }
      }
    }
    for (int kind = 0; kind < 3; ++kind) {
      std::printf("%-32s %s: %d boxes near the limit, limits kept %d, broken %d (mode x pose)\n", robot,
                  constraintKindName(kinds[kind]), boxes[kind], counts[kind].limits_kept, counts[kind].limits_broken);
    }
  }
}

// Boxes that cross the workspace boundary (the certificate cannot say they are assembled):
// where floorsWhereAssembled gives a mode a floor other than zero, every assembled pose
// tried in the box has at least its magnitude as |measure|, and its sign. At the boundary
// the rods' rates are unbounded, so these floors come from the natural enclosures alone;
// a robot with limits gets none (its membership there needs the limits' proof).
TEST(MeasureCertificate, FloorsWhereAssembledHoldOverTheAssembledPartOfBoundaryBoxes) {
  const std::vector<BoxCase> cases = {
      {"config/delta_like.yaml", false, 0.6, 0.008},        // couples: natural triple products
      {"config/delta_like.yaml", true, 0.6, 0.004},         // 64 working modes: perturbation bound
      {"config/clavel_delta.yaml", false, 0.5, 0.008},      // cranks
      {"test/robots/tricylinder.yaml", false, 0.6, 0.008},
      {"config/rotary_delta.yaml", false, 0.4, 0.004},      // limits: no floors
  };
  for (const BoxCase& box_case : cases) {
    const RobotModel model = loadRobotFile(test::sourcePath(box_case.robot));
    const std::vector<WorkingMode> modes = box_case.uncoupled ? uncoupledWorkingModes(model) : coupledWorkingModes(model);
    const MeasureCertificate certificate(model, modes, model.reference.pose);
    const PoseClassifier classifier(model, modes, model.reference.pose, false);
    std::vector<double> measures(modes.size());
    int boxes = 0, proven = 0, checked = 0;
    for (int tries = 0; tries < 100000 && boxes < 200; ++tries) {
      PoseBox box;
      box.centre = model.reference.pose;
      for (int k = 0; k < 3; ++k) {
        box.centre.position[k] += test::uniform(-box_case.position_spread, box_case.position_spread);
        box.position_half_width[k] = test::uniform(0.25, 1.0) * box_case.position_half_width;
      }
      if (certificate.certify(box).assembly != BoxAssembly::Undecided) continue;
      ++boxes;
      const std::vector<double> floors = certificate.floorsWhereAssembled(box);
      ASSERT_EQ(floors.size(), modes.size());
      for (std::size_t m = 0; m < modes.size(); ++m) {
        proven += floors[m] != 0.0;
        if (certificate.hasLimits()) EXPECT_EQ(floors[m], 0.0) << box_case.robot << " mode " << modes[m].name;
      }
      for (int s = -128; s < 64; ++s) {
        if (!classifier.classify(poseIn(box, s >= 0 ? s : -1), measures.data())) continue;
        for (std::size_t m = 0; m < modes.size(); ++m) {
          if (floors[m] == 0.0) continue;
          ++checked;
          EXPECT_GT(measures[m] * floors[m], 0.0) << box_case.robot << " box " << boxes << " mode " << modes[m].name;
          EXPECT_GE(std::abs(measures[m]), std::abs(floors[m]) - 1e-12)
              << box_case.robot << " box " << boxes << " mode " << modes[m].name;
        }
      }
    }
    std::printf("%-36s %s: %d boxes across the boundary, %d floors not zero, %d checked (mode x pose)\n",
                box_case.robot.c_str(), box_case.uncoupled ? "uncoupled" : "coupled", boxes, proven, checked);
    EXPECT_EQ(boxes, 200) << box_case.robot;
    if (!certificate.hasLimits()) EXPECT_GT(checked, 1000) << box_case.robot << ": nothing proven, nothing checked";
  }
}

// Closed forms of the share of a box where a linear function is positive.
TEST(ProvenShare, AnExactGradientGivesTheShareOfTheBoxAboveItsPlane) {
  const Eigen::Vector3d unit(1.0, 1.0, 1.0), square(1.0, 1.0, 0.0);
  const IntervalPoint along_x = pointInterval(Eigen::Vector3d(1.0, 0.0, 0.0));
  const IntervalPoint diagonal = pointInterval(Eigen::Vector3d(1.0, 1.0, 1.0));
  // Halves by symmetry; the slopes raised to 1/4096 of their sum cost a little.
  EXPECT_NEAR(provenPositiveShare(0.0, along_x, unit), 0.5, 1e-3);
  // 1e-6: the slack for the closed form's rounding.
  EXPECT_NEAR(provenPositiveShare(0.0, diagonal, unit), 0.5, 2e-6);
  // x + y > -1/2 on [-1, 1]^2 leaves out a triangle of legs 3/2: 1 - 9/8 / 4.
  EXPECT_NEAR(provenPositiveShare(0.5, diagonal, square), 1.0 - 1.125 / 4.0, 2e-6);
  // x > -1/2 on [-1, 1]: three quarters, whatever the other half widths.
  EXPECT_NEAR(provenPositiveShare(0.5, along_x, Eigen::Vector3d(1.0, 0.0, 0.0)), 0.75, 2e-6);
  EXPECT_NEAR(provenPositiveShare(0.5, along_x, Eigen::Vector3d(1.0, 5.0, 0.001)), 0.75, 1e-3);
  EXPECT_EQ(provenPositiveShare(3.5, diagonal, unit), 1.0);
  EXPECT_EQ(provenPositiveShare(-3.5, diagonal, unit), 0.0);
  // Random planes against a Monte-Carlo count, and wider gradients never prove more.
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d half = test::uniformVector(0.1, 1.0), g = test::uniformVector(-1.0, 1.0);
    const double value = test::uniform(-1.0, 1.0);
    int above = 0;
    const int samples = 4000;
    for (int k = 0; k < samples; ++k) above += value + g.dot(test::uniformVector(-1.0, 1.0).cwiseProduct(half)) > 0.0;
    const double share = provenPositiveShare(value, pointInterval(g), half);
    EXPECT_NEAR(share, static_cast<double>(above) / samples, 0.03) << "trial " << trial;
    IntervalPoint wider;
    for (int k = 0; k < 3; ++k) wider[k] = Interval(g[k] - test::uniform(0.0, 0.3), g[k] + test::uniform(0.0, 0.3));
    EXPECT_LE(provenPositiveShare(value, wider, half), share + 1e-3) << "trial " << trial;
  }
}

// The shares of a box proven assembled and not (the certified volumes' cells the
// workspace's boundary crosses) hold at poses drawn in the box; the part proven assembled
// holds the centre.
TEST(MeasureCertificate, AssemblySharesHoldInBoxesAcrossTheBoundary) {
  const std::vector<BoxCase> cases = {
      {"config/delta_like.yaml", false, 0.6, 0.002},     // sliders and cranks
      {"config/clavel_delta.yaml", false, 0.5, 0.002},   // cranks
      {"test/robots/tricylinder.yaml", false, 0.4, 0.005},
      {"config/five_bar.yaml", false, 0.5, 0.004},       // planar: no z
  };
  for (const BoxCase& box_case : cases) {
    const RobotModel model = loadRobotFile(test::sourcePath(box_case.robot));
    const std::vector<WorkingMode> modes = coupledWorkingModes(model);
    const MeasureCertificate certificate(model, modes, model.reference.pose);
    const PoseClassifier classifier(model, modes, model.reference.pose, false);
    const bool planar = box_case.robot == "config/five_bar.yaml";
    std::vector<double> measures(modes.size());
    int boxes = 0;
    double decided = 0.0;
    for (int tries = 0; tries < 200000 && boxes < 100; ++tries) {
      PoseBox box;
      box.centre = model.reference.pose;
      for (int k = 0; k < (planar ? 2 : 3); ++k) {
        box.centre.position[k] += test::uniform(-box_case.position_spread, box_case.position_spread);
        box.position_half_width[k] = box_case.position_half_width;
      }
      if (certificate.assemblyOf(box) != BoxAssembly::Undecided) continue;
      ++boxes;
      const AssemblyShares shares = certificate.assemblyShares(box);
      decided += shares.assembled + shares.unassembled;
      EXPECT_LE(shares.assembled + shares.unassembled, 1.0 + 1e-12) << box_case.robot << " box " << boxes;
      if (shares.assembled > 0.0) {
        EXPECT_TRUE(classifier.classify(box.centre, measures.data())) << box_case.robot << " box " << boxes;
      }
      const int samples = 1000;
      int assembled = 0;
      for (int s = 0; s < samples; ++s) assembled += classifier.classify(poseIn(box, -1), measures.data());
      // Three standard deviations of the count at most.
      EXPECT_GE(static_cast<double>(assembled) / samples, shares.assembled - 0.05) << box_case.robot << " box " << boxes;
      EXPECT_GE(1.0 - static_cast<double>(assembled) / samples, shares.unassembled - 0.05)
          << box_case.robot << " box " << boxes;
    }
    std::printf("%-32s %d boxes across the boundary, mean share decided %.3f\n", box_case.robot.c_str(), boxes,
                decided / boxes);
    EXPECT_EQ(boxes, 100) << box_case.robot;
    // A smooth surface crosses a box of a few millimetres almost as a plane: the mean-value
    // form leaves undecided a layer second order in the box's size, a small part of it.
    // (Every box drawn here is one the natural form leaves undecided; since a slider's
    // discriminant is enclosed without its offset along the rail, those are boxes the
    // boundary really crosses, not ones beside it that the shares decide whole: the
    // tricylinder's mean went from above 0.8 to 0.78 to 0.80 by that alone.)
    EXPECT_GT(decided / boxes, 0.75) << box_case.robot;
  }
}

// The thin layers' marking (workspace/thin_layers.cpp) encloses over a box's halves only
// the chains near their reach over the box: that holds because a chain not near over a
// box is not near over any box inside it. Boxes drawn across the workspace's boundary,
// boxes drawn inside them, turning ones too (a hexapod over ZYZ angles).
TEST(MeasureCertificate, AChainNearItsReachInABoxInsideAnotherIsNearInThatOne) {
  const std::vector<BoxCase> cases = {
      {"config/delta_like.yaml", false, 0.6, 0.016},
      {"config/clavel_delta.yaml", false, 0.5, 0.016},
      {"test/robots/tricylinder.yaml", false, 0.4, 0.02},
      {"config/hexapod_6rss_long.yaml", false, 0.15, 0.02, 0.3, 0.05},
  };
  for (const BoxCase& box_case : cases) {
    const RobotModel model = loadRobotFile(test::sourcePath(box_case.robot));
    const MeasureCertificate certificate(model, coupledWorkingModes(model), model.reference.pose);
    int near_boxes = 0, fewer_inside = 0;
    for (int b = 0; b < 400; ++b) {
      const PoseBox box = drawnBox(model, box_case, 0.1);
      const std::uint32_t near = certificate.chainsNearReach(box);
      near_boxes += near != 0;
      for (int s = 0; s < 8; ++s) {
        PoseBox inside = box;
        for (int k = 0; k < 3; ++k) {
          inside.position_half_width[k] = test::uniform(0.05, 0.9) * box.position_half_width[k];
          inside.centre.position[k] +=
              test::uniform(-1.0, 1.0) * (box.position_half_width[k] - inside.position_half_width[k]);
          inside.angle_half_width[k] = test::uniform(0.05, 0.9) * box.angle_half_width[k];
          inside.centre.euler_zyz[k] += test::uniform(-1.0, 1.0) * (box.angle_half_width[k] - inside.angle_half_width[k]);
        }
        const std::uint32_t near_inside = certificate.chainsNearReach(inside);
        EXPECT_EQ(near_inside & ~near, 0u) << box_case.robot << " box " << b << ": a chain near inside, not over the box";
        EXPECT_EQ(certificate.chainsNearReach(inside, MeasureCertificate::kNearReachSpreads, near), near_inside)
            << box_case.robot << " box " << b;
        fewer_inside += near_inside != near;
      }
    }
    std::printf("%-32s %d of 400 boxes with a chain near its reach, %d boxes inside them with fewer\n",
                box_case.robot.c_str(), near_boxes, fewer_inside);
    EXPECT_GT(near_boxes, 40) << box_case.robot;
    EXPECT_GT(fewer_inside, 40) << box_case.robot;
  }
}

// A cube of 2 cells a side (cells of `half_width`) about a translation of `reference` by
// up to `spread` along each axis, drawn at random, and one of its cells.
void drawCellInCube(const Pose& reference, double spread, double half_width, PoseBox& cube, PoseBox& cell) {
  cube.centre = reference;
  for (int k = 0; k < 3; ++k) {
    cube.centre.position[k] += test::uniform(-spread, spread);
    cube.position_half_width[k] = 2.0 * half_width;
  }
  cell.centre = cube.centre;
  for (int k = 0; k < 3; ++k) {
    cell.centre.position[k] += test::uniform(0.0, 1.0) < 0.5 ? -half_width : half_width;
    cell.position_half_width[k] = half_width;
  }
}

// The share of a cell where a working mode keeps the sign of det J_DKP it has at the
// cell's centre (the certified volumes' cells a mode's singular surface crosses), from a
// certificate of the 2-cell cube around the cell: poses drawn in
// the cell have that sign at least as often as the share says, and the mean-value form
// decides a part of such cells. On robots whose couples factorise and that set no
// limits (the tally counts no share of a robot with limits).
TEST(MeasureCertificate, SignSharesHoldInCellsAcrossSingularSurfaces) {
  // With the least mean share each robot's cells get: 0.43 to 0.48 and 0.03 to 0.09 seen
  // (the draws depend on the tests run before; the Clavel delta's cranks leave wide
  // enclosures of the rods' rates).
  const std::vector<std::pair<BoxCase, double>> cases = {
      {{"config/delta_like.yaml", false, 0.5, 0.001}, 0.3},     // sliders and cranks
      {{"config/clavel_delta.yaml", false, 0.4, 0.001}, 0.01},  // cranks
  };
  for (const auto& [box_case, least_mean_share] : cases) {
    const RobotModel model = loadRobotFile(test::sourcePath(box_case.robot));
    const std::vector<WorkingMode> modes = coupledWorkingModes(model);
    const MeasureCertificate certificate(model, modes, model.reference.pose);
    ASSERT_TRUE(certificate.factorises()) << box_case.robot;
    const PoseClassifier classifier(model, modes, model.reference.pose, false);
    std::vector<double> measures(modes.size()), at_centre(modes.size());
    int cells = 0;
    double shared = 0.0;
    for (int tries = 0; tries < 400000 && cells < 100; ++tries) {
      PoseBox cube, cell;
      drawCellInCube(model.reference.pose, box_case.position_spread, box_case.position_half_width, cube, cell);
      if (!classifier.classify(cell.centre, at_centre.data())) continue;
      // A mode whose sign changes in the cell (at a corner), on a cube proven assembled.
      int crossing = -1;
      for (int corner = 0; corner < 8 && crossing < 0; ++corner) {
        if (!classifier.classify(poseIn(cell, corner), measures.data())) break;
        for (std::size_t m = 0; m < modes.size() && crossing < 0; ++m) {
          if (measures[m] * at_centre[m] < 0.0) crossing = static_cast<int>(m);
        }
      }
      if (crossing < 0) continue;
      const BoxCertificate proof = certificate.certify(cube);
      if (proof.assembly != BoxAssembly::Inside || !proof.boundsVariation()) continue;
      ++cells;
      const double share = proof.shareKeepingSign(static_cast<std::size_t>(crossing), cell, 0.0);
      shared += share;
      EXPECT_LE(share, 1.0) << box_case.robot << " cell " << cells;
      const int samples = 1000;
      int kept = 0;
      for (int s = 0; s < samples; ++s) {
        kept += classifier.classify(poseIn(cell, -1), measures.data()) && measures[crossing] * at_centre[crossing] > 0.0;
      }
      // Three standard deviations of the count at most.
      EXPECT_GE(static_cast<double>(kept) / samples, share - 0.05) << box_case.robot << " cell " << cells;
    }
    std::printf("%-32s %d cells across a singular surface, mean share proven %.3f\n", box_case.robot.c_str(), cells,
                shared / cells);
    EXPECT_EQ(cells, 100) << box_case.robot;
    // A surface crosses a cell almost as a plane, and the part on the centre's side is half
    // the cell on average; the mean-value form over the 2-cell cube proves a part of it.
    EXPECT_GT(shared / cells, least_mean_share) << box_case.robot;
  }
}

// Under a dexterity margin M a region holds only the poses where |measure| >= M, so the
// share of a cell that the margin's surface crosses counts only where the certificate
// proves |measure| beyond M, not wherever the sign is kept: poses drawn in the cell keep
// the sign with |measure| >= M at least as often as the share says. (Counting the sign
// alone made the delta-like robot's certified maximal + volume under margin 0.2 equal to
// the sampled one at 4 and 2 mm, 0.0608402 and 0.0608449 m^3: no lower bound.)
TEST(MeasureCertificate, SignSharesUnderAMarginKeepTheMargin) {
  const double margin = 0.2;
  const RobotModel model = loadRobotFile(test::sourcePath("config/delta_like.yaml"));
  const std::vector<WorkingMode> modes = coupledWorkingModes(model);
  const MeasureCertificate certificate(model, modes, model.reference.pose);
  const PoseClassifier classifier(model, modes, model.reference.pose, false);
  std::vector<double> measures(modes.size()), at_centre(modes.size());
  const double half_width = 0.002;
  int cells = 0;
  double shared = 0.0;
  for (int tries = 0; tries < 400000 && cells < 100; ++tries) {
    PoseBox cube, cell;
    drawCellInCube(model.reference.pose, 0.5, half_width, cube, cell);
    if (!classifier.classify(cell.centre, at_centre.data())) continue;
    // A mode beyond the margin at the centre and under it at a corner.
    int crossing = -1;
    for (int corner = 0; corner < 8 && crossing < 0; ++corner) {
      if (!classifier.classify(poseIn(cell, corner), measures.data())) break;
      for (std::size_t m = 0; m < modes.size() && crossing < 0; ++m) {
        if (std::abs(at_centre[m]) >= margin && std::abs(measures[m]) < margin) crossing = static_cast<int>(m);
      }
    }
    if (crossing < 0) continue;
    const BoxCertificate proof = certificate.certify(cube);
    if (proof.assembly != BoxAssembly::Inside || !proof.boundsVariation()) continue;
    ++cells;
    const double share = proof.shareKeepingSign(static_cast<std::size_t>(crossing), cell, margin);
    shared += share;
    const int samples = 1000;
    int kept = 0;
    for (int s = 0; s < samples; ++s) {
      kept += classifier.classify(poseIn(cell, -1), measures.data()) &&
              measures[crossing] * at_centre[crossing] > 0.0 && std::abs(measures[crossing]) >= margin;
    }
    // Three standard deviations of the count at most.
    EXPECT_GE(static_cast<double>(kept) / samples, share - 0.05) << "cell " << cells;
  }
  EXPECT_EQ(cells, 100);
  std::printf("%d cells across the margin's surface, mean share proven %.3f\n", cells, shared / cells);
}

// A certificate asked for some working modes proves of each what the whole certificate
// does (the same floor and slopes, where both bound the variation), and nothing of the
// others; with slopes_only, a certificate that bounds no variation proves nothing. The
// masked one may bound the variation where the whole does not: it encloses only the rods
// of the branches its modes use.
TEST(MeasureCertificate, AskedForSomeModesItProvesOfEachWhatTheWholeOneDoes) {
  for (const BoxCase& box_case : {BoxCase{"config/delta_like.yaml", false, 0.5, 0.002},
                                  BoxCase{"config/clavel_delta.yaml", false, 0.4, 0.002}}) {
    const RobotModel model = loadRobotFile(test::sourcePath(box_case.robot));
    const std::vector<WorkingMode> modes = coupledWorkingModes(model);
    const MeasureCertificate certificate(model, modes, model.reference.pose);
    ASSERT_TRUE(certificate.factorises()) << box_case.robot;
    const std::uint64_t all = (std::uint64_t{1} << modes.size()) - 1;
    int compared = 0, masked_only = 0;
    for (int b = 0; b < 400; ++b) {
      const PoseBox box = drawnBox(model, box_case, 0.2);
      const BoxCertificate whole = certificate.certify(box);
      if (whole.assembly != BoxAssembly::Inside) continue;
      const std::uint64_t wanted = 1 + static_cast<std::uint64_t>(test::uniform(0.0, 1.0) * static_cast<double>(all - 1));
      for (const bool slopes_only : {false, true}) {
        const BoxCertificate masked = certificate.certify(box, wanted, slopes_only);
        ASSERT_EQ(masked.assembly, whole.assembly);
        masked_only += masked.boundsVariation() && !whole.boundsVariation();
        for (std::size_t m = 0; m < modes.size(); ++m) {
          if ((wanted >> m & 1u) == 0 || (slopes_only && !masked.boundsVariation())) {
            EXPECT_EQ(masked.measure_floor[m], 0.0) << box_case.robot << " box " << b << " mode " << m;
            continue;
          }
          if (!whole.boundsVariation() || !masked.boundsVariation()) continue;
          ++compared;
          EXPECT_EQ(masked.measure_floor[m], whole.measure_floor[m]) << box_case.robot << " box " << b << " mode " << m;
          EXPECT_EQ(masked.product_at_centre[m].lower(), whole.product_at_centre[m].lower());
          EXPECT_EQ(masked.product_at_centre[m].upper(), whole.product_at_centre[m].upper());
          for (int l = 0; l < 3; ++l) {
            EXPECT_EQ(masked.product_gradient[m][l].lower(), whole.product_gradient[m][l].lower());
            EXPECT_EQ(masked.product_gradient[m][l].upper(), whole.product_gradient[m][l].upper());
          }
        }
        if (!whole.boundsVariation() && !slopes_only) {
          // Natural form where a rod's rate is unbounded: the same floors for the modes asked.
          for (std::size_t m = 0; m < modes.size(); ++m) {
            if ((wanted >> m & 1u) == 0 || masked.boundsVariation()) continue;
            EXPECT_EQ(masked.measure_floor[m], whole.measure_floor[m]) << box_case.robot << " box " << b << " mode " << m;
          }
        }
      }
    }
    std::printf("%-28s %d (box, mode) pairs compared, %d masked certificates bounding what the whole did not\n",
                box_case.robot.c_str(), compared, masked_only);
    EXPECT_GT(compared, 100) << box_case.robot;
  }
}

}  // namespace
}  // namespace maximal_workspace
