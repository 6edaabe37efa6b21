// The robot's limits (issue 16) against answers worked out here from the geometry alone:
// - cones on a single PSS leg and on a single RSS leg: the margins of a configuration and
//   the batch classifier's blocked working modes, against acos of the rod direction;
// - a planar 5R with one crank limited: the workspace area and the per-working-mode areas
//   against a closed form derived below, and cell by cell against the limits evaluated
//   at the cell centres;
// - a linear delta with carriage strokes: no bounds needed, the z extent of the workspace
//   against a closed form, the volume against a Monte-Carlo estimate;
// - a transition refused because its point breaks a cone, the regions on both sides kept.
// Nothing here asks the library for an expected value: the IKP, the crank frames, the
// angles and the areas are computed by the test's own code.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iomanip>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "maximal_workspace/kinematics/constraints.h"
#include "maximal_workspace/kinematics/inverse_kinematics.h"
#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/kinematics/working_mode.h"
#include "maximal_workspace/model/input_error.h"
#include "maximal_workspace/model/robot_file.h"
#include "maximal_workspace/regions/workspace_analysis.h"
#include "maximal_workspace/workspace/grid.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// ---------------------------------------------------------------------------------------
// Test-side geometry.

// The angle between two vectors: acos of their normalised dot product.
double angleOf(const Vector3d& u, const Vector3d& v) {
  const double c = u.normalized().dot(v.normalized());
  return std::acos(std::max(-1.0, std::min(1.0, c)));
}

// ZYZ Euler angles (phi, theta, psi): R = Rz(phi) Ry(theta) Rz(psi).
Matrix3d zyz(const Vector3d& euler) {
  return (Eigen::AngleAxisd(euler[0], Vector3d::UnitZ()) * Eigen::AngleAxisd(euler[1], Vector3d::UnitY()) *
          Eigen::AngleAxisd(euler[2], Vector3d::UnitZ()))
      .toRotationMatrix();
}

// Numbers for the YAML texts, at full double precision.
std::string num(double value) {
  std::ostringstream out;
  out << std::setprecision(17) << value;
  return out.str();
}

std::string vec(const Vector3d& v) { return "[" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "]"; }

// Area of the intersection of two discs of radii r1, r2 whose centres are d apart.
double discIntersection(double r1, double r2, double d) {
  if (d >= r1 + r2) return 0.0;
  if (d <= std::abs(r1 - r2)) return M_PI * std::pow(std::min(r1, r2), 2);
  const double half1 = std::acos((d * d + r1 * r1 - r2 * r2) / (2.0 * d * r1));  // half-angle at centre 1
  const double half2 = std::acos((d * d + r2 * r2 - r1 * r1) / (2.0 * d * r2));
  // Two circular segments: sector minus triangle on each side of the common chord.
  return r1 * r1 * (half1 - std::sin(2.0 * half1) / 2.0) + r2 * r2 * (half2 - std::sin(2.0 * half2) / 2.0);
}

// ---------------------------------------------------------------------------------------
// 1. Cones on a single leg.

// Where a leg's intermediate node can be for a platform node, solved here: the p branch
// first (docs/kinematics.md: p takes the + root; for a crank, the + root turns positively
// about the axis), then n.
struct LegNodes {
  double discriminant = 0.0;  // >= 0: assembled (same sign as the library's, not its scale)
  std::array<Vector3d, 2> a;
};

// One leg of a one-chain mechanism: how to solve it here, and its cones.
struct LegUnderTest {
  std::string yaml;
  Vector3d platform_node;
  std::function<LegNodes(const Vector3d& p)> nodes;
  // The fixed end's cone axis in the base frame for the intermediate node a.
  std::function<Vector3d(const Vector3d& a)> fixed_axis;
  double fixed_half_angle = 0.0;
  std::optional<Vector3d> platform_axis;  // platform coordinates
  double platform_half_angle = 0.0;
  Vector3d sample_centre;  // random TCPs are drawn in a box about it
  double sample_half_width = 0.0;
};

// A PSS leg on a tilted slider, both cones set: a(q) = f + q d, the rod a-p of length R.
LegUnderTest pssLeg() {
  const Vector3d f(0.013, -0.021, 0.0), direction(0.1, -0.2, 1.0), node(0.02, -0.01, 0.03);
  const Vector3d fixed_axis(0.3, -0.2, -0.9), platform_axis(-0.2, 0.4, 0.9);
  const double rod = 0.3;
  LegUnderTest leg;
  leg.yaml =
      "name: cone_pss\noutput_variables: [x]\ninputs: [{name: q}]\nchains:\n"
      "  - name: leg\n    type: PSS\n    input: q\n    fixed_node: " +
      vec(f) + "\n    direction: " + vec(direction) + "\n    rod_length: " + num(rod) +
      "\n    platform_node: " + vec(node) + "\n    joint_limits:\n      fixed_end: {axis: " + vec(fixed_axis) +
      ", half_angle: 1.7}" + "\n      platform_end: {axis: " + vec(platform_axis) + ", half_angle: 1.4}" +
      "\nreference: {position: [0.05, 0.02, 0.0]}\n";
  leg.platform_node = node;
  const Vector3d d = direction.normalized();
  leg.nodes = [=](const Vector3d& p) {
    // The foot of p on the slider line is at q = d.(p - f); the rod's end a is on the line
    // at R from p: q = d.(p - f) +/- sqrt(R^2 - (distance of p from the line)^2).
    const Vector3d w = p - f;
    const double along = d.dot(w);
    LegNodes nodes;
    nodes.discriminant = rod * rod - (w - along * d).squaredNorm();
    const double root = std::sqrt(std::max(0.0, nodes.discriminant));
    nodes.a = {f + (along + root) * d, f + (along - root) * d};
    return nodes;
  };
  const Vector3d axis = fixed_axis.normalized();
  leg.fixed_axis = [=](const Vector3d&) { return axis; };  // base frame, fixed (the slider translates)
  leg.fixed_half_angle = 1.7;
  leg.platform_axis = platform_axis.normalized();
  leg.platform_half_angle = 1.4;
  leg.sample_centre = f;
  leg.sample_half_width = 0.35;
  return leg;
}

// An RSS leg on a tilted axis with a fixed-end cone in the crank's frame (x from the crank
// centre towards a, z the axis, y = z x x) and a platform-end cone.
LegUnderTest rssLeg() {
  const Vector3d c(0.01, 0.02, -0.03), axis_raw(0.2, 0.3, 1.0), zero_raw(1.0, 0.0, 0.0), node(0.01, 0.02, -0.01);
  const Vector3d cone_in_crank_frame(-0.3, -0.2, 0.8), platform_axis(-0.6, -0.3, -0.7);
  const double crank = 0.15, rod = 0.3;
  LegUnderTest leg;
  leg.yaml =
      "name: cone_rss\noutput_variables: [x]\ninputs: [{name: q}]\nchains:\n"
      "  - name: leg\n    type: RSS\n    input: q\n    fixed_node: " +
      vec(c) + "\n    axis: " + vec(axis_raw) + "\n    crank_length: " + num(crank) +
      "\n    crank_zero: " + vec(zero_raw) + "\n    rod_length: " + num(rod) + "\n    platform_node: " + vec(node) +
      "\n    joint_limits:\n      fixed_end: {axis: " + vec(cone_in_crank_frame) + ", half_angle: 1.3}" +
      "\n      platform_end: {axis: " + vec(platform_axis) + ", half_angle: 1.3}" +
      "\nreference: {position: [0.2, 0.1, 0.15]}\n";
  leg.platform_node = node;
  const Vector3d e = axis_raw.normalized();
  leg.nodes = [=](const Vector3d& p) {
    // Split w = p - c into h e (along the axis) and w_par (in the crank plane). The crank
    // end a = c + L x, x a unit vector of the crank plane at angle g from w_par/|w_par|:
    // |p - a|^2 = |w_par|^2 + L^2 - 2 L |w_par| cos g + h^2 = R^2 gives cos g; the crank
    // turned by +g about e from w_par is the p branch, by -g the n branch.
    const Vector3d w = p - c;
    const double h = e.dot(w);
    const Vector3d w_par = w - h * e;
    const double m = w_par.norm();
    const double cos_g = (m * m + crank * crank + h * h - rod * rod) / (2.0 * crank * m);
    LegNodes nodes;
    nodes.discriminant = 1.0 - cos_g * cos_g;
    const double sin_g = std::sqrt(std::max(0.0, nodes.discriminant));
    const Vector3d toward = w_par / m, side = e.cross(toward);
    nodes.a = {c + crank * (cos_g * toward + sin_g * side), c + crank * (cos_g * toward - sin_g * side)};
    return nodes;
  };
  const Vector3d k = cone_in_crank_frame.normalized();
  leg.fixed_axis = [=](const Vector3d& a) {
    const Vector3d x = (a - c).normalized(), z = e, y = z.cross(x);
    return Vector3d(k.x() * x + k.y() * y + k.z() * z);
  };
  leg.fixed_half_angle = 1.3;
  leg.platform_axis = platform_axis.normalized();
  leg.platform_half_angle = 1.3;
  leg.sample_centre = c;
  leg.sample_half_width = 0.45;
  return leg;
}

// The cone angles of branch b for the TCP at `position` with the platform turned by `rotation`.
struct ConeAngles {
  bool assembled = false;
  bool near_reach = false;  // too close to the IKP singularity to tell
  std::array<Vector3d, 2> a;
  std::array<double, 2> fixed{}, platform{};
};

ConeAngles coneAngles(const LegUnderTest& leg, const Vector3d& position, const Matrix3d& rotation) {
  const Vector3d p = position + rotation * leg.platform_node;
  const LegNodes nodes = leg.nodes(p);
  ConeAngles angles;
  angles.assembled = nodes.discriminant >= 0.0;
  angles.near_reach = std::abs(nodes.discriminant) < 1e-10;
  if (!angles.assembled) return angles;
  angles.a = nodes.a;
  for (int b = 0; b < 2; ++b) {
    angles.fixed[b] = angleOf(p - nodes.a[b], leg.fixed_axis(nodes.a[b]));
    // p to a in platform coordinates.
    angles.platform[b] = leg.platform_axis ? angleOf(rotation.transpose() * (nodes.a[b] - p), *leg.platform_axis) : 0.0;
  }
  return angles;
}

// Branch b of the working mode named by one letter (docs/kinematics.md).
int branchOfMode(const WorkingMode& mode) { return mode.name == "p" ? 0 : 1; }

void expectMarginsAreAcosOfTheRod(const LegUnderTest& leg) {
  const RobotModel model = parseRobotFile(leg.yaml, "leg.yaml");
  const RobotConstraints constraints(model);
  ASSERT_TRUE(constraints.active());
  const std::vector<WorkingMode> modes = coupledWorkingModes(model);
  ASSERT_EQ(modes.size(), 2u);
  int compared = 0, broken = 0, kept = 0;
  double worst = 0.0;
  for (int k = 0; k < 3000; ++k) {
    Pose pose;
    pose.position = leg.sample_centre + test::uniformVector(-leg.sample_half_width, leg.sample_half_width);
    pose.euler_zyz = Vector3d(test::uniform(-M_PI, M_PI), test::uniform(0.0, M_PI), test::uniform(-M_PI, M_PI));
    const ConeAngles angles = coneAngles(leg, pose.position, zyz(pose.euler_zyz));
    if (angles.near_reach) continue;
    const IkpResult ikp = solveIkp(model, pose);
    ASSERT_EQ(ikp.assembled, angles.assembled) << "pose " << pose.position.transpose();
    if (!angles.assembled) continue;
    for (const WorkingMode& mode : modes) {
      const int b = branchOfMode(mode);
      const Configuration configuration = configurationOf(pose, ikp, mode);
      ASSERT_LT((configuration.a[0] - angles.a[b]).norm(), 1e-9) << "branch " << mode.name;
      const ConstraintMargins margins = constraints.margins(configuration);
      const double fixed = leg.fixed_half_angle - angles.fixed[b];
      const double platform = leg.platform_half_angle - angles.platform[b];
      EXPECT_NEAR(margins.fixed_cone[0], fixed, 1e-9) << "mode " << mode.name << " at " << pose.position.transpose();
      EXPECT_NEAR(margins.platform_cone[0], platform, 1e-9) << "mode " << mode.name;
      worst = std::max({worst, std::abs(margins.fixed_cone[0] - fixed), std::abs(margins.platform_cone[0] - platform)});
      EXPECT_EQ(margins.input[0], INFINITY);  // no input limits in this file
      if (std::min(std::abs(fixed), std::abs(platform)) > 1e-9) {
        const bool holds = fixed > 0.0 && platform > 0.0;
        EXPECT_EQ(margins.satisfied(), holds) << "mode " << mode.name;
        if (!holds) {
          EXPECT_EQ(margins.violated, ConstraintKind::JointCone);
        }
        (holds ? kept : broken) += 1;
      }
      // From the pose and its own IKP: the same margins.
      const IkpResult solved = solveIkp(model, pose);
      ASSERT_TRUE(solved.assembled);
      EXPECT_EQ(constraints.margins(pose, solved, mode).fixed_cone[0], margins.fixed_cone[0]);
      ++compared;
    }
  }
  // Both outcomes occur often, so a classifier that blocked all or nothing would fail.
  EXPECT_GT(compared, 1000);
  EXPECT_GT(broken, 200);
  EXPECT_GT(kept, 200);
  std::printf(
      "[          ] %s: %d configurations (%d keep both cones, %d break one), largest |margin - (half_angle - "
      "acos)| %.2e rad\n",
      model.name.c_str(), compared, kept, broken, worst);
}

TEST(ConeMargins, PssLegMarginsAreHalfAngleMinusAcosOfTheRodDirection) { expectMarginsAreAcosOfTheRod(pssLeg()); }

TEST(ConeMargins, RssLegFixedEndConeTurnsWithTheCrank) { expectMarginsAreAcosOfTheRod(rssLeg()); }

void expectClassifierBlocksExactlyTheModesOutsideTheirCones(const LegUnderTest& leg) {
  const RobotModel model = parseRobotFile(leg.yaml, "leg.yaml");
  const std::vector<WorkingMode> modes = coupledWorkingModes(model);
  Pose start = model.reference.pose;
  start.euler_zyz = Vector3d(0.4, 0.7, -0.3);  // a turned platform, kept for the whole batch
  const Matrix3d rotation = zyz(start.euler_zyz);
  const PoseClassifier classifier(model, modes, start, true);
  const std::size_t count = 20000;
  std::vector<double> x(count), y(count), z(count);
  for (std::size_t i = 0; i < count; ++i) {
    const Vector3d tcp = leg.sample_centre + test::uniformVector(-leg.sample_half_width, leg.sample_half_width);
    x[i] = tcp.x(), y[i] = tcp.y(), z[i] = tcp.z();
  }
  std::vector<std::uint8_t> inside(count);
  std::vector<double> measures(count * modes.size());
  classifier.classify(PointBatch{x.data(), y.data(), z.data(), count}, inside.data(), measures.data());
  int wrong_inside = 0, wrong_mode = 0, skipped = 0;
  std::array<int, 2> blocked{}, admitted{};
  for (std::size_t i = 0; i < count; ++i) {
    const ConeAngles angles = coneAngles(leg, Vector3d(x[i], y[i], z[i]), rotation);
    if (angles.near_reach) continue;
    wrong_inside += (inside[i] != 0) != angles.assembled;
    if (!angles.assembled || !inside[i]) continue;
    for (std::size_t m = 0; m < modes.size(); ++m) {
      const int b = branchOfMode(modes[m]);
      const double fixed = leg.fixed_half_angle - angles.fixed[b];
      const double platform = leg.platform_half_angle - angles.platform[b];
      if (std::abs(fixed) < 1e-9 || std::abs(platform) < 1e-9) {
        ++skipped;
        continue;
      }
      const bool expected_blocked = fixed < 0.0 || platform < 0.0;
      const bool got_blocked = !modeAdmissible(measures[i * modes.size() + m]);
      wrong_mode += expected_blocked != got_blocked;
      (expected_blocked ? blocked : admitted)[b] += 1;
    }
  }
  EXPECT_EQ(wrong_inside, 0);
  EXPECT_EQ(wrong_mode, 0);
  for (int b = 0; b < 2; ++b) {
    EXPECT_GT(blocked[b], 200) << "branch " << b;
    EXPECT_GT(admitted[b], 200) << "branch " << b;
  }
  std::printf("[          ] %s: blocked p %d n %d, admitted p %d n %d, %d within 1e-9 of a cone skipped\n",
              model.name.c_str(), blocked[0], blocked[1], admitted[0], admitted[1], skipped);
}

TEST(ConeClassifier, PssLegBatchBlocksExactlyTheModesOutsideTheirCones) {
  expectClassifierBlocksExactlyTheModesOutsideTheirCones(pssLeg());
}

TEST(ConeClassifier, RssLegBatchBlocksExactlyTheModesOutsideTheirCones) {
  expectClassifierBlocksExactlyTheModesOutsideTheirCones(rssLeg());
}

// ---------------------------------------------------------------------------------------
// 2 and 4. The planar 5R of config/five_bar.yaml: base joints c_L = (-0.1, 0), c_R =
// (0.1, 0), cranks L = 0.2, distal links R = 0.25, the TCP at the common distal joint.

constexpr double kCrank = 0.2, kRod = 0.25;
const Vector3d kLeftBase(-0.1, 0.0, 0.0), kRightBase(0.1, 0.0, 0.0);

// The five_bar file with `left_input` and `left_extra` (more fields of the left chain).
std::string fiveBarYaml(const std::string& left_input, const std::string& left_extra, const std::string& reference) {
  const std::string head = "name: five_bar_limits\noutput_variables: [x, y]\ninputs:\n  - ";
  const std::string left =
      "  - {name: left, type: RSS, input: left, fixed_node: [-0.1, 0.0, 0.0], axis: [0, 0, 1],\n"
      "     crank_length: 0.2, rod_length: 0.25, platform_node: [0, 0, 0]";
  const std::string right =
      "  - {name: right, type: RSS, input: right, fixed_node: [0.1, 0.0, 0.0], axis: [0, 0, 1],\n"
      "     crank_length: 0.2, rod_length: 0.25, platform_node: [0, 0, 0]}\n";
  return head + left_input + "\n  - {name: right}\nchains:\n" + left + left_extra + "}\n" + right +
         "reference: " + reference + "\n";
}

// The crank angles (from +x, counter-clockwise: q as the file measures it) at which a leg
// based at `base` reaches the point: the elbow is on the circle of radius L about the base
// and on the circle of radius R about the point, at angle +/- g from the direction to the
// point, with cos g from the triangle base-elbow-point. Branch p turns positively (+g).
struct CrankAngles {
  bool assembled = false;
  double distance = 0.0;  // from the base
  std::array<double, 2> q{};
};

CrankAngles crankAngles(const Vector3d& base, double x, double y) {
  CrankAngles angles;
  const double dx = x - base.x(), dy = y - base.y();
  angles.distance = std::hypot(dx, dy);
  angles.assembled = angles.distance >= kRod - kCrank && angles.distance <= kRod + kCrank;
  if (!angles.assembled) return angles;
  const double cos_g =
      (angles.distance * angles.distance + kCrank * kCrank - kRod * kRod) / (2.0 * kCrank * angles.distance);
  const double g = std::acos(std::max(-1.0, std::min(1.0, cos_g)));
  const double towards = std::atan2(dy, dx);
  angles.q = {towards + g, towards - g};
  return angles;
}

// Signed distance of angle q (mod 2 pi) from the arc [low, high]: >= 0 inside.
double arcMargin(double q, double low, double high) {
  const double from_low = std::fmod(std::fmod(q - low, 2.0 * M_PI) + 2.0 * M_PI, 2.0 * M_PI);
  const double span = high - low;
  if (from_low <= span) return std::min(from_low, span - from_low);
  return -std::min(from_low - span, 2.0 * M_PI - from_low);
}

// 2. The left crank limited to [a, b] with b - a = D, the right crank free.
//
// Closed form. In polar coordinates (r, t) about c_L, a point at distance r in (R - L,
// R + L) is reached with the crank at q = t -/+ g(r), cos g(r) = (r^2 + L^2 - R^2) / (2 r L)
// (the two branches). So a branch reaches, at each r, the angles t of an arc of length D,
// and its area is int_{R-L}^{R+L} D r dr = 2 R L D, whatever [a, b]. Both branches reach a
// point where both of t - g and t + g are in range:
//   - near the outer circle, where 2 g < D: an angular length D - 2 g;
//   - near the inner circle, where g > pi - D / 2 (the two arcs overlap round the back):
//     D + 2 g - 2 pi.
// The integrals of r g(r) are areas: {(r, t) : |t| <= g(r)} is exactly the disc of radius
// R about the point (L, 0), because |(r, t) - (L, 0)|^2 = r^2 + L^2 - 2 r L cos t <= R^2
// iff cos t >= cos g(r). Let r1 and r2 be the radii where g = D / 2 and g = pi - D / 2,
// from the same triangle: r1 = L cos(D/2) + sqrt(R^2 - L^2 sin^2(D/2)) and
// r2 = -L cos(D/2) + sqrt(R^2 - L^2 sin^2(D/2)); and I(s) the area of that disc within
// radius s of c_L (two discs' intersection, radii R and s, centres L apart). Then
//   outer overlap = int_{r1}^{R+L} r (D - 2 g) dr = D ((R+L)^2 - r1^2) / 2 - (pi R^2 - I(r1))
//   inner overlap = int_{R-L}^{r2} r (D + 2 g - 2 pi) dr = D (r2^2 - (R-L)^2) / 2 - (pi r2^2 - I(r2))
//   the left leg's reach = 4 R L D - outer overlap - inner overlap.
// The right leg must reach the point too. Every circle of radius R about an elbow e with
// |e - c_R| <= L lies in its annulus R - L <= |P - c_R| <= R + L, and the left elbow
// e(q) = c_L + L (cos q, sin q) has |e(q) - c_R| = 2 L |sin(q / 2)| <= L for |q| <= pi / 3.
// So with [a, b] within [-pi/3, pi/3] the right leg reaches all of the left leg's reach,
// and the workspace (connected: the image of [a, b] x a circle of rod directions) is the
// union above; each working mode's area is 2 R L D.
struct FiveBarAreas {
  double per_branch = 0.0;
  double both_branches = 0.0;
};

FiveBarAreas limitedFiveBarAreas(double span) {
  const double L = kCrank, R = kRod, D = span;
  const double root = std::sqrt(R * R - L * L * std::pow(std::sin(D / 2.0), 2));
  const double r1 = L * std::cos(D / 2.0) + root;   // g(r1) = D / 2
  const double r2 = -L * std::cos(D / 2.0) + root;  // g(r2) = pi - D / 2
  const double outer = D * ((R + L) * (R + L) - r1 * r1) / 2.0 - (M_PI * R * R - discIntersection(R, r1, L));
  const double inner = D * (r2 * r2 - (R - L) * (R - L)) / 2.0 - (M_PI * r2 * r2 - discIntersection(R, r2, L));
  return {2.0 * R * L * D, 4.0 * R * L * D - outer - inner};
}

struct FiveBarCellCheck {
  std::uint64_t expected_cells = 0, ambiguous = 0, wrong_inside = 0;
  std::array<std::uint64_t, 4> mode_cells{}, expected_mode_cells{}, wrong_mode_labelled{}, unlabelled_mode{};
};

// Every cell of the analysis against the limits evaluated here at its centre.
FiveBarCellCheck checkFiveBarCells(const WorkspaceAnalysis& analysis, double low, double high) {
  FiveBarCellCheck check;
  const Grid& grid = analysis.grid();
  for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
    const GridCell index = grid.cell(cell);
    const double x = grid.centre(0, index[0]), y = grid.centre(1, index[1]);
    const CrankAngles left = crankAngles(kLeftBase, x, y), right = crankAngles(kRightBase, x, y);
    bool ambiguous = false;
    for (const CrankAngles* leg : {&left, &right}) {
      ambiguous = ambiguous || std::abs(leg->distance - (kRod + kCrank)) < 1e-9 ||
                  std::abs(leg->distance - (kRod - kCrank)) < 1e-9;
    }
    std::array<bool, 2> left_branch{};
    for (int b = 0; b < 2; ++b) {
      const double margin = arcMargin(left.q[b], low, high);
      left_branch[b] = left.assembled && margin >= 0.0;
      ambiguous = ambiguous || (left.assembled && std::abs(margin) < 1e-9);
    }
    if (ambiguous) {
      ++check.ambiguous;
      continue;
    }
    const bool in = right.assembled && (left_branch[0] || left_branch[1]);
    check.expected_cells += in;
    check.wrong_inside += analysis.inside(cell) != in;
    for (std::size_t m = 0; m < analysis.modes().size(); ++m) {
      const std::string& name = analysis.modes()[m].name;  // left letter, right letter
      const bool mode_in = right.assembled && left_branch[name[0] == 'p' ? 0 : 1];
      const bool labelled = analysis.label(cell, static_cast<int>(m)) >= 0;
      check.expected_mode_cells[m] += mode_in;
      check.mode_cells[m] += labelled;
      check.wrong_mode_labelled[m] += labelled && !mode_in;
      check.unlabelled_mode[m] += mode_in && !labelled;  // only in the DKP-singular band
    }
  }
  return check;
}

void expectLimitedFiveBarArea(double low, double high) {
  const double step = 0.003;
  const RobotModel model = parseRobotFile(
      fiveBarYaml("{name: left, limits: [" + num(low) + ", " + num(high) + "]}", "", "{position: [0.25, 0.0, 0.0]}"),
      "five_bar_limited.yaml");
  AnalysisOptions options;
  options.start_mode = "pp";  // at (0.25, 0) both left branches are in range (q = +/-0.775)
  const WorkspaceAnalysis analysis = analyseWorkspace(model, test::referenceGrid(model, step), options);
  const Grid& grid = analysis.grid();
  ASSERT_EQ(analysis.modes().size(), 4u);

  const FiveBarAreas areas = limitedFiveBarAreas(high - low);
  // Grid tolerance: the cells the boundary crosses (about perimeter / step of them; the
  // perimeter is under (R + L) D + (R - L) D + 4 pi R: the two arcs and the whole of the
  // two circles about the arc's ends) each count or not by their centre, an error of up to
  // half a cell either way, independent: six standard deviations of that sum.
  const double perimeter = 2.0 * kRod * (high - low) + 4.0 * M_PI * kRod;
  const double tolerance = 6.0 * std::sqrt(perimeter / step / 12.0) * grid.cellVolume();
  EXPECT_EQ(grid.volumeUnit(), "m^2");
  EXPECT_NEAR(analysis.workspaceVolume(), areas.both_branches, tolerance);
  const FiveBarCellCheck check = checkFiveBarCells(analysis, low, high);
  EXPECT_EQ(check.wrong_inside, 0u);
  EXPECT_LE(check.ambiguous, 4u);
  std::printf(
      "[          ] left in [%g, %g]: area %.6f m^2, closed form %.6f (tolerance %.1e); %llu cells, %llu "
      "expected at their centres\n",
      low, high, analysis.workspaceVolume(), areas.both_branches, tolerance,
      static_cast<unsigned long long>(analysis.voxelCount()), static_cast<unsigned long long>(check.expected_cells));
  for (std::size_t m = 0; m < 4; ++m) {
    const double mode_area = static_cast<double>(check.mode_cells[m]) * grid.cellVolume();
    EXPECT_NEAR(mode_area, areas.per_branch, tolerance) << "mode " << analysis.modes()[m].name;
    EXPECT_EQ(check.wrong_mode_labelled[m], 0u) << "mode " << analysis.modes()[m].name;
    EXPECT_LE(check.unlabelled_mode[m], 2u) << "mode " << analysis.modes()[m].name;
    std::printf("[          ]   mode %s: %.6f m^2 (closed form %.6f), cells %llu, expected %llu\n",
                analysis.modes()[m].name.c_str(), mode_area, areas.per_branch,
                static_cast<unsigned long long>(check.mode_cells[m]),
                static_cast<unsigned long long>(check.expected_mode_cells[m]));
  }
  // The limit is a wall: walled faces are counted, as actuator limits.
  EXPECT_GT(analysis.singularityCounts().limit_entries, 0u);
  EXPECT_EQ(analysis.singularityCounts().cone_entries, 0u);
}

TEST(LimitedFiveBar, AreaIsTheClosedFormOfTheLimitedCranksReach) { expectLimitedFiveBarArea(-0.9, 0.95); }

// The same arc written one turn up: q counts modulo 2 pi.
TEST(LimitedFiveBar, ARangeOneTurnUpIsTheSameArc) { expectLimitedFiveBarArea(2.0 * M_PI - 0.9, 2.0 * M_PI + 0.95); }

// The closed form itself against a Monte-Carlo estimate of the same set (the limits tested
// at random points with the crank angles above), so that a slip in the derivation cannot
// pass for an engine error or hide one.
TEST(LimitedFiveBar, ClosedFormAgreesWithMonteCarlo) {
  const double low = -0.9, high = 0.95;
  std::mt19937_64 generator(16);
  // The box holds the reach: the elbow stays at x >= -0.1 + 0.2 cos(0.95) and |y| <=
  // 0.2 sin(0.95), so x >= -0.24 and |y| <= 0.42; the right leg keeps x <= 0.55.
  std::uniform_real_distribution<double> ux(-0.35, 0.55), uy(-0.45, 0.45);
  const double box = 0.9 * 0.9;
  const int samples = 1000000;
  int in = 0, in_p = 0;
  for (int k = 0; k < samples; ++k) {
    const double x = ux(generator), y = uy(generator);
    const CrankAngles left = crankAngles(kLeftBase, x, y), right = crankAngles(kRightBase, x, y);
    if (!left.assembled || !right.assembled) continue;
    const bool p = arcMargin(left.q[0], low, high) >= 0.0, n = arcMargin(left.q[1], low, high) >= 0.0;
    in += p || n;
    in_p += p;
  }
  const FiveBarAreas areas = limitedFiveBarAreas(high - low);
  const auto check = [&](int hits, double closed_form) {
    const double f = static_cast<double>(hits) / samples;
    const double estimate = box * f, sigma = box * std::sqrt(f * (1.0 - f) / samples);
    EXPECT_NEAR(estimate, closed_form, 4.0 * sigma);
    std::printf("[          ] Monte Carlo %.6f +/- %.6f m^2, closed form %.6f\n", estimate, sigma, closed_form);
  };
  check(in, areas.both_branches);
  check(in_p, areas.per_branch);
}

// ---------------------------------------------------------------------------------------
// 3. A linear delta: three vertical rails at 120 degrees, a carriage on each with a
// parallelogram of two rods to the effector, carriage stroke [0, H].

struct LinearDelta {
  double rail_radius = 0.2;  // rail (carriage joint midpoint) from the centre
  double effector = 0.04;    // effector joint midpoint from the TCP
  double half_pair = 0.025;  // half the spacing of a parallelogram's two rods
  double rod = 0.25;         // l
  double stroke = 0.6;       // H
  std::array<double, 3> tower_angles{M_PI / 2.0, M_PI / 2.0 + 2.0 * M_PI / 3.0, M_PI / 2.0 + 4.0 * M_PI / 3.0};
  double d() const { return rail_radius - effector; }  // D: the rail's horizontal distance from the TCP's axis
  Vector3d tower(int i) const {
    return Vector3d(d() * std::cos(tower_angles[i]), d() * std::sin(tower_angles[i]), 0.0);
  }
};

std::string linearDeltaYaml(const LinearDelta& delta, bool limits) {
  std::string yaml = "name: test_linear_delta\noutput_variables: [x, y, z, phi, theta, psi]\ninputs:\n";
  const char* names[3] = {"A", "B", "C"};
  for (const char* name : names) {
    yaml += std::string("  - {name: ") + name + (limits ? ", limits: [0.0, " + num(delta.stroke) + "]}\n" : "}\n");
  }
  yaml += "chains:\n";
  for (int i = 0; i < 3; ++i) {
    const Vector3d radial(std::cos(delta.tower_angles[i]), std::sin(delta.tower_angles[i]), 0.0);
    const Vector3d tangent = Vector3d::UnitZ().cross(radial);
    for (int side = 0; side < 2; ++side) {
      const Vector3d offset = (side == 0 ? -1.0 : 1.0) * delta.half_pair * tangent;
      yaml += std::string("  - {name: ") + names[i] + (side == 0 ? "a" : "b") + ", type: PSS, input: " + names[i] +
              ", fixed_node: " + vec(delta.rail_radius * radial + offset) +
              ", direction: [0, 0, 1], rod_length: " + num(delta.rod) +
              ", platform_node: " + vec(delta.effector * radial + offset) + "}\n";
    }
  }
  yaml += "reference: {position: [0.0, 0.0, 0.2], orientation: [0, 0, 0]}\n";
  return yaml;
}

// Both rods of a parallelogram are the rod from the carriage to the effector moved
// sideways, so for the TCP each pair is one rod of length l from the rail's line shifted
// in by the effector offset: the vertical line through D u_i (u_i the tower's radial unit
// vector, D = rail radius - effector offset). With s_i = sqrt(l^2 - |xy - D u_i|^2) (xy
// within l of every such line), carriage i sits at q_i = z + s_i (branch p, above the TCP)
// or z - s_i (n).
// A working mode keeps its strokes where every 0 <= q_i <= H.
struct DeltaPoint {
  bool reach = false;
  std::array<double, 3> s{};
};

DeltaPoint deltaPoint(const LinearDelta& delta, double x, double y) {
  DeltaPoint point;
  point.reach = true;
  for (int i = 0; i < 3; ++i) {
    const Vector3d t = delta.tower(i);
    const double horizontal2 = (x - t.x()) * (x - t.x()) + (y - t.y()) * (y - t.y());
    point.reach = point.reach && horizontal2 <= delta.rod * delta.rod;
    point.s[i] = std::sqrt(std::max(0.0, delta.rod * delta.rod - horizontal2));
  }
  return point;
}

// Mode bits: bit i set = chain pair i on branch n.
bool deltaModeHolds(const LinearDelta& delta, const DeltaPoint& point, double z, int mode) {
  if (!point.reach) return false;
  for (int i = 0; i < 3; ++i) {
    const double q = (mode >> i & 1) ? z - point.s[i] : z + point.s[i];
    if (q < 0.0 || q > delta.stroke) return false;
  }
  return true;
}

// The lowest and highest cell centre of the workspace in the grid column holding (x, y).
struct Column {
  std::int64_t cells = 0;
  double low = INFINITY, high = -INFINITY;
  bool contiguous = true;
};

Column workspaceColumn(const WorkspaceAnalysis& analysis, std::int64_t i, std::int64_t j) {
  const Grid& grid = analysis.grid();
  Column column;
  std::int64_t first = -1, last = -1;
  for (std::int64_t k = 0; k < grid.size(2); ++k) {
    if (!analysis.inside(grid.index(GridCell{i, j, k, 0, 0, 0}))) continue;
    if (first < 0) first = k;
    last = k;
    ++column.cells;
  }
  if (first >= 0) {
    column.low = grid.centre(2, first), column.high = grid.centre(2, last);
    column.contiguous = column.cells == last - first + 1;
  }
  return column;
}

// The grid column whose centre is nearest the axis x = y = 0.
std::array<std::int64_t, 2> centralColumn(const Grid& grid) {
  std::array<std::int64_t, 2> best{};
  for (int d = 0; d < 2; ++d) {
    double nearest = INFINITY;
    for (std::int64_t i = 0; i < grid.size(d); ++i) {
      if (std::abs(grid.centre(d, i)) < nearest) nearest = std::abs(grid.centre(d, i)), best[d] = i;
    }
  }
  return best;
}

class LinearDeltaStrokes : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    model_ = new RobotModel(parseRobotFile(linearDeltaYaml(LinearDelta{}, true), "test_linear_delta.yaml"));
    GridSpec spec = test::referenceGrid(*model_, kStep);
    ASSERT_TRUE(spec.bounds.empty());  // the strokes alone bound the box
    AnalysisOptions all, upright;
    all.start_mode = upright.start_mode = "ppp";
    upright.working_modes = {"ppp"};
    all_ = new WorkspaceAnalysis(analyseWorkspace(*model_, spec, all));
    upright_ = new WorkspaceAnalysis(analyseWorkspace(*model_, spec, upright));
  }
  static void TearDownTestSuite() {
    delete upright_;
    delete all_;
    delete model_;
  }
  static constexpr double kStep = 0.01;
  static const RobotModel* model_;
  static const WorkspaceAnalysis* all_;      // every working mode
  static const WorkspaceAnalysis* upright_;  // ppp alone: every carriage above the TCP
};
const RobotModel* LinearDeltaStrokes::model_ = nullptr;
const WorkspaceAnalysis* LinearDeltaStrokes::all_ = nullptr;
const WorkspaceAnalysis* LinearDeltaStrokes::upright_ = nullptr;

// Without the strokes the rails are unbounded lines: the same robot needs bounds.
TEST_F(LinearDeltaStrokes, WithoutStrokesTheBoxIsUnbounded) {
  const RobotModel free_model = parseRobotFile(linearDeltaYaml(LinearDelta{}, false), "free.yaml");
  EXPECT_THROW(Grid(free_model, test::referenceGrid(free_model, kStep)), InputError);
  EXPECT_NO_THROW(Grid(*model_, test::referenceGrid(*model_, kStep)));
}

// Closed form of the column over a point (x, y) of the reach:
// - ppp (carriages above the TCP): 0 <= z + s_i <= H for every i, so z in
//   [-min s_i, H - max s_i]; on the axis all s_i = s0 = sqrt(l^2 - D^2): [-s0, H - s0].
// - any working mode: carriage i fits on one of its branches where z in [-s_i, H - s_i]
//   (p) or [s_i, H + s_i] (n); with H >= 2 l >= 2 s_i the two overlap, so z in
//   [-s_i, H + s_i], and for all three z in [-min s_i, H + min s_i]. min s_i is largest on
//   the axis (the farthest rail is nearest there, at D), so the whole workspace spans
//   z in [-s0, H + s0].
// Cell centres sit at (k + 1/2) step: the extreme centres lie within one step inside.
TEST_F(LinearDeltaStrokes, ColumnOnTheAxisSpansTheClosedFormHeights) {
  const LinearDelta delta;
  ASSERT_GE(delta.stroke, 2.0 * delta.rod);
  const double s0 = std::sqrt(delta.rod * delta.rod - delta.d() * delta.d());
  const Grid& grid = all_->grid();
  const auto [i, j] = centralColumn(grid);
  const double x = grid.centre(0, i), y = grid.centre(1, j);
  const DeltaPoint point = deltaPoint(delta, x, y);
  ASSERT_TRUE(point.reach);
  const double min_s = *std::min_element(point.s.begin(), point.s.end());
  const double max_s = *std::max_element(point.s.begin(), point.s.end());
  const double eps = 1e-9;
  struct Case {
    const WorkspaceAnalysis* analysis;
    const char* name;
    double low, high;
  };
  for (const Case& c :
       {Case{all_, "all modes", -min_s, delta.stroke + min_s}, Case{upright_, "ppp", -min_s, delta.stroke - max_s}}) {
    const Column column = workspaceColumn(*c.analysis, i, j);
    ASSERT_GT(column.cells, 0) << c.name;
    EXPECT_TRUE(column.contiguous) << c.name;
    EXPECT_GE(column.low, c.low - eps) << c.name;
    EXPECT_LT(column.low, c.low + kStep + eps) << c.name;
    EXPECT_LE(column.high, c.high + eps) << c.name;
    EXPECT_GT(column.high, c.high - kStep - eps) << c.name;
    std::printf(
        "[          ] %s, column at (%.3f, %.3f): cells z %.3f .. %.3f, closed form z %.4f .. %.4f "
        "(on the axis: %.4f .. %.4f)\n",
        c.name, x, y, column.low, column.high, c.low, c.high, -s0,
        c.analysis == all_ ? delta.stroke + s0 : delta.stroke - s0);
  }
  // The whole workspace of every mode within [-s0, H + s0], reaching within a step of both
  // ends (the central column is off the axis by half a cell diagonal, 7 mm, where min s is
  // at most 7 mm * D / s0 = 6 mm lower).
  double low = INFINITY, high = -INFINITY;
  for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
    if (!all_->inside(cell)) continue;
    const double z = grid.centre(2, grid.cell(cell)[2]);
    low = std::min(low, z), high = std::max(high, z);
  }
  EXPECT_GE(low, -s0 - eps);
  EXPECT_LT(low, -s0 + kStep + 0.007);
  EXPECT_LE(high, delta.stroke + s0 + eps);
  EXPECT_GT(high, delta.stroke + s0 - kStep - 0.007);
  // The box the strokes give holds it with room to spare: a cell beyond each end.
  EXPECT_LT(grid.centre(2, 0), low);
  EXPECT_GT(grid.centre(2, grid.size(2) - 1), high);
}

// The volume against a Monte-Carlo estimate: random points of a box holding the reach,
// each tested with the strokes of every working mode (deltaModeHolds, no closed form).
TEST_F(LinearDeltaStrokes, VolumeMatchesMonteCarlo) {
  const LinearDelta delta;
  std::mt19937_64 generator(1616);
  const double half = delta.rod + 0.05;
  std::uniform_real_distribution<double> uxy(-half, half), uz(-delta.rod, delta.stroke + delta.rod);
  const double box = (2.0 * half) * (2.0 * half) * (delta.stroke + 2.0 * delta.rod);
  const int samples = 2000000;
  int any = 0, upright = 0;
  for (int k = 0; k < samples; ++k) {
    const double x = uxy(generator), y = uxy(generator), z = uz(generator);
    const DeltaPoint point = deltaPoint(delta, x, y);
    if (!point.reach) continue;
    bool some = false;
    for (int mode = 0; mode < 8 && !some; ++mode) some = deltaModeHolds(delta, point, z, mode);
    any += some;
    upright += deltaModeHolds(delta, point, z, 0);
  }
  const auto compare = [&](const WorkspaceAnalysis& analysis, int hits, const char* name) {
    const double f = static_cast<double>(hits) / samples;
    const double estimate = box * f, sigma = box * std::sqrt(f * (1.0 - f) / samples);
    // 2 %: the 10 mm cells along the boundary (the Monte-Carlo error is 0.2 %).
    EXPECT_NEAR(analysis.workspaceVolume(), estimate, 0.02 * estimate) << name;
    std::printf("[          ] %s: volume %.6f m^3, Monte Carlo %.6f +/- %.6f (%+.2f %%)\n", name,
                analysis.workspaceVolume(), estimate, sigma, 100.0 * (analysis.workspaceVolume() / estimate - 1.0));
  };
  compare(*all_, any, "all modes");
  compare(*upright_, upright, "ppp");
  // Cell by cell: the strokes tested at every cell centre give exactly the workspace cells.
  const Grid& grid = all_->grid();
  std::uint64_t expected_all = 0, expected_upright = 0, wrong_all = 0, wrong_upright = 0;
  for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
    const GridCell index = grid.cell(cell);
    const DeltaPoint point = deltaPoint(delta, grid.centre(0, index[0]), grid.centre(1, index[1]));
    const double z = grid.centre(2, index[2]);
    bool some = false;
    for (int mode = 0; mode < 8 && !some; ++mode) some = deltaModeHolds(delta, point, z, mode);
    const bool up = deltaModeHolds(delta, point, z, 0);
    expected_all += some, expected_upright += up;
    wrong_all += all_->inside(cell) != some;
    wrong_upright += upright_->inside(cell) != up;
  }
  EXPECT_EQ(wrong_all, 0u);
  EXPECT_EQ(wrong_upright, 0u);
  std::printf("[          ] cells: all modes %llu (%llu expected at their centres), ppp %llu (%llu)\n",
              static_cast<unsigned long long>(all_->voxelCount()), static_cast<unsigned long long>(expected_all),
              static_cast<unsigned long long>(upright_->voxelCount()),
              static_cast<unsigned long long>(expected_upright));
  EXPECT_GT(all_->singularityCounts().limit_entries, 0u);
}

// ---------------------------------------------------------------------------------------
// 4. A transition refused because its point breaks a cone.
//
// On the left leg's outer IKP boundary of the 5R (|P - c_L| = R + L) crank and rod are
// aligned: the rod points from a along the crank frame's +x. A fixed_end cone about -x of
// half-angle pi - 0.01 takes every rod direction except those within 0.01 rad of +x. At a
// point P with |P - c_L| = r the rod makes the angle pi - b with -x, b the elbow angle
// with cos b = (r^2 - L^2 - R^2) / (2 L R) (both branches alike): so only the band
// r > sqrt(L^2 + R^2 + 2 L R cos 0.01), within 5.6 micrometres of the outer circle, loses
// the leg. Grid cells there are rare, so the workspace keeps its cells beside that
// boundary, but the configuration at each transition point on it (the circle itself,
// b = 0) breaks the cone: those transitions must go. On the inner boundary (r = R - L) the
// rod points along -x, angle 0: those transitions stay.

constexpr double kThinCone = M_PI - 0.01;

// The cone angle of the left leg at (x, y), both branches.
double leftRodAngleFromMinusX(double x, double y) {
  const double r2 = std::pow(x - kLeftBase.x(), 2) + std::pow(y - kLeftBase.y(), 2);
  const double cos_b = (r2 - kCrank * kCrank - kRod * kRod) / (2.0 * kCrank * kRod);
  return std::acos(std::max(-1.0, std::min(1.0, -cos_b)));
}

enum class Boundary { LeftOuter, LeftInner, Right };

Boundary boundaryOf(const TransitionPoint& point) {
  if (point.chain != 0) return Boundary::Right;
  const double r = (point.position - kLeftBase).norm();
  return std::abs(r - (kRod + kCrank)) < std::abs(r - (kRod - kCrank)) ? Boundary::LeftOuter : Boundary::LeftInner;
}

struct TransitionCounts {
  std::array<int, 3> by_boundary{};  // transitions with a point on each boundary
  std::array<int, 3> points{};
  int only_left_outer = 0;  // transitions whose every point is on the left outer boundary
};

TransitionCounts countTransitions(const WorkspaceAnalysis& analysis) {
  TransitionCounts counts;
  const TransitionGraph& graph = analysis.transitions();
  for (const Transition& transition : graph.transitions) {
    std::array<bool, 3> seen{};
    for (std::uint32_t p : transition.points) {
      const int b = static_cast<int>(boundaryOf(graph.points[p]));
      seen[b] = true;
      ++counts.points[b];
    }
    for (int b = 0; b < 3; ++b) counts.by_boundary[b] += seen[b];
    counts.only_left_outer += seen[0] && !seen[1] && !seen[2];
  }
  return counts;
}

TEST(ConeTransitions, AConeThatBreaksTheSingularConfigurationRefusesItsTransitions) {
  const double step = 0.005;
  const RobotModel& plain_model = test::fiveBar();
  const std::string reference =
      "{position: [0.0, 0.3, 0.0], inputs: {left: 2.1603806695735628, right: 0.98121198401623033}}";
  const RobotModel coned_model = parseRobotFile(
      fiveBarYaml("{name: left}",
                  ",\n     joint_limits: {fixed_end: {axis: [-1, 0, 0], half_angle: " + num(kThinCone) + "}}",
                  reference),
      "five_bar_cone.yaml");
  const WorkspaceAnalysis plain = analyseWorkspace(plain_model, test::referenceGrid(plain_model, step), {});
  const WorkspaceAnalysis coned = analyseWorkspace(coned_model, test::referenceGrid(coned_model, step), {});
  ASSERT_EQ(plain.grid().cellCount(), coned.grid().cellCount());
  ASSERT_EQ(plain.modes().size(), coned.modes().size());

  // Transitions: those through the left outer circle are refused, the others stay.
  const TransitionCounts before = countTransitions(plain), after = countTransitions(coned);
  const int outer = static_cast<int>(Boundary::LeftOuter), inner = static_cast<int>(Boundary::LeftInner),
            right = static_cast<int>(Boundary::Right);
  ASSERT_GT(before.by_boundary[outer], 0);  // without the cone the test has something to refuse
  EXPECT_EQ(after.by_boundary[outer], 0);
  EXPECT_EQ(after.points[outer], 0);
  EXPECT_EQ(after.by_boundary[inner], before.by_boundary[inner]);
  EXPECT_EQ(after.by_boundary[right], before.by_boundary[right]);
  EXPECT_EQ(coned.transitions().transitions.size(),
            plain.transitions().transitions.size() - static_cast<std::size_t>(before.only_left_outer));
  int plain_summary = 0, coned_summary = 0;
  for (int am = 0; am < 2; ++am) {
    plain_summary += plain.assemblyModes()[am].transitions, coned_summary += coned.assemblyModes()[am].transitions;
  }
  EXPECT_LT(coned_summary, plain_summary);
  std::printf("[          ] transitions: %zu without the cone, %zu with it (assembly-mode summaries %d, %d)\n",
              plain.transitions().transitions.size(), coned.transitions().transitions.size(), plain_summary,
              coned_summary);
  std::printf(
      "[          ] transitions (points) through the left outer / left inner / right boundaries: without the "
      "cone %d (%d) / %d (%d) / %d (%d), with it %d (%d) / %d (%d) / %d (%d)\n",
      before.by_boundary[outer], before.points[outer], before.by_boundary[inner], before.points[inner],
      before.by_boundary[right], before.points[right], after.by_boundary[outer], after.points[outer],
      after.by_boundary[inner], after.points[inner], after.by_boundary[right], after.points[right]);
  // The configuration the test says a refused transition would pass through breaks the cone.
  for (const TransitionPoint& point : plain.transitions().points) {
    if (boundaryOf(point) != Boundary::LeftOuter) continue;
    EXPECT_GT(leftRodAngleFromMinusX(point.position.x(), point.position.y()), kThinCone);
  }

  // The workspace loses only the cells in the thin band; the regions on both sides of each
  // refused transition keep their cells beside the boundary, in both working modes.
  std::uint64_t band = 0;
  const Grid& grid = plain.grid();
  for (std::uint64_t cell = 0; cell < grid.cellCount(); ++cell) {
    const GridCell index = grid.cell(cell);
    band +=
        plain.inside(cell) && leftRodAngleFromMinusX(grid.centre(0, index[0]), grid.centre(1, index[1])) > kThinCone;
  }
  EXPECT_EQ(plain.voxelCount() - coned.voxelCount(), band);
  int kept_sides = 0, sides = 0;
  for (const Transition& transition : plain.transitions().transitions) {
    const int from = plain.regions()[transition.from_region].mode, to = plain.regions()[transition.to_region].mode;
    for (std::uint32_t p : transition.points) {
      const TransitionPoint& point = plain.transitions().points[p];
      if (boundaryOf(point) != Boundary::LeftOuter) continue;
      const GridCell index = grid.cell(point.cell);
      if (leftRodAngleFromMinusX(grid.centre(0, index[0]), grid.centre(1, index[1])) > kThinCone - 1e-9) continue;
      for (int mode : {from, to}) {
        if (plain.label(point.cell, mode) < 0) continue;
        ++sides;
        const std::int32_t label = coned.label(point.cell, mode);
        kept_sides += label >= 0 && coned.regions()[label].sign == transition.sign;
      }
    }
  }
  EXPECT_GT(sides, 0);
  EXPECT_EQ(kept_sides, sides);
  std::printf(
      "[          ] cells %llu without the cone, %llu with it (band of %llu at the cell centres); %d of %d "
      "region cells beside refused transition points kept\n",
      static_cast<unsigned long long>(plain.voxelCount()), static_cast<unsigned long long>(coned.voxelCount()),
      static_cast<unsigned long long>(band), kept_sides, sides);
}

// The walls of several working modes at one pose (RobotConstraints::walls, each chain's
// limits found once a branch where no rods are checked) are each mode's own wall
// (wallLimit of its margins): the hexaglide's rails and cones, turned and tilted poses
// breaking either; and a robot whose rods are checked (the per-mode path).
TEST(WallLimits, SeveralModesAtAPoseAreEachModesOwn) {
  for (const std::string robot : {"config/hexaglide_6pss.yaml", "config/rotary_delta.yaml"}) {
    const RobotModel model = loadRobotFile(test::sourcePath(robot));
    const RobotConstraints constraints(model);
    const std::vector<WorkingMode> modes = coupledWorkingModes(model);
    const std::uint64_t all = modes.size() >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << modes.size()) - 1;
    std::vector<WallLimit> walls(modes.size());
    int compared = 0, kinds[5] = {};
    for (int i = 0; i < 3000; ++i) {
      Pose pose = model.reference.pose;
      pose.position += test::uniformVector(-0.4, 0.4);
      if (model.dof() == 6) pose.euler_zyz += test::uniformVector(-0.6, 0.6);
      const IkpResult ikp = solveIkp(model, pose);
      if (!ikp.assembled) continue;
      const std::uint64_t wanted = i % 2 == 0 ? all : static_cast<std::uint64_t>(test::rng()()) & all;
      constraints.walls(pose, ikp, modes, wanted, walls.data());
      for (std::size_t m = 0; m < modes.size(); ++m) {
        if ((wanted >> m & 1u) == 0) continue;
        const WallLimit own = wallLimit(constraints.margins(pose, ikp, modes[m]));
        EXPECT_EQ(walls[m].kind, own.kind) << robot << " pose " << i << " mode " << modes[m].name;
        EXPECT_EQ(walls[m].chain, own.chain) << robot << " pose " << i << " mode " << modes[m].name;
        ++compared, ++kinds[static_cast<int>(own.kind)];
      }
    }
    std::printf("%-28s %d (pose, mode) walls compared: %d input range, %d cone, %d interference, %d none\n",
                robot.c_str(), compared, kinds[2], kinds[3], kinds[4], kinds[0]);
    EXPECT_GT(kinds[2], 100) << robot;
    // The hexaglide's walls are of both kinds its file sets; the rotary delta's rods meet.
    if (robot == "config/hexaglide_6pss.yaml") {
      EXPECT_GT(kinds[3], 100) << robot;
    } else {
      EXPECT_GT(kinds[4], 10) << robot;
    }
  }
}

}  // namespace
}  // namespace maximal_workspace
