// The exact sign of det J_DKP (issue 20): wherever the default analysis decides a sign
// (|measure| at least kMeasureTolerance), it is the sign an evaluation in long double
// gives, on poses bisected onto the DKP singular surfaces and stepped off them by 1e-14
// to 1e-5 of a segment. The long double evaluation is written here from the geometry:
// each chain's IKP (PSS and RSS closed forms), the twist-form rows, their normalisation
// and a determinant by Gaussian elimination with partial pivoting.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "maximal_workspace/kinematics/pose_classifier.h"
#include "maximal_workspace/model/pss_chain.h"
#include "maximal_workspace/model/rss_chain.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

using Real = long double;
using Vec = std::array<Real, 3>;

Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Real dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// R = Rz(phi) Ry(theta) Rz(psi) applied to a platform point, plus the TCP.
Vec toBase(const Pose& pose, const Vec& r) {
  const Real phi = pose.euler_zyz[0], theta = pose.euler_zyz[1], psi = pose.euler_zyz[2];
  const Vec z1 = {std::cos(psi) * r[0] - std::sin(psi) * r[1], std::sin(psi) * r[0] + std::cos(psi) * r[1], r[2]};
  const Vec y = {std::cos(theta) * z1[0] + std::sin(theta) * z1[2], z1[1], -std::sin(theta) * z1[0] + std::cos(theta) * z1[2]};
  const Vec z2 = {std::cos(phi) * y[0] - std::sin(phi) * y[1], std::sin(phi) * y[0] + std::cos(phi) * y[1], y[2]};
  return {z2[0] + Real(pose.position.x()), z2[1] + Real(pose.position.y()), z2[2] + Real(pose.position.z())};
}

// The intermediate node of a chain's branch (0: p, 1: n) for platform node p; false when
// the chain cannot be assembled.
bool node(const Chain& chain, const Vec& p, int branch, Vec* a) {
  const Real sign = branch == 0 ? 1 : -1;
  const Real rod = chain.rodLength();
  if (const auto* pss = dynamic_cast<const PssChain*>(&chain)) {
    const Vec f = vec(pss->fixedNode()), d = vec(pss->direction()), w = sub(p, f);
    const Real disc = dot(d, w) * dot(d, w) - dot(w, w) + rod * rod;
    if (disc < 0) return false;
    const Real q = dot(d, w) + sign * std::sqrt(disc);
    *a = {f[0] + q * d[0], f[1] + q * d[1], f[2] + q * d[2]};
    return true;
  }
  const auto& rss = dynamic_cast<const RssChain&>(chain);
  const Vec c = vec(rss.crankCentre()), u = vec(rss.crankZero()), v = cross(vec(rss.axis()), u), w = sub(p, c);
  const Real L = rss.crankLength(), A = 2 * L * dot(u, w), B = 2 * L * dot(v, w), C = dot(w, w) + L * L - rod * rod;
  const Real disc = A * A + B * B - C * C;
  if (disc < 0) return false;
  const Real s = std::sqrt(disc), rho2 = A * A + B * B;
  const Real cos_q = (A * C - sign * B * s) / rho2, sin_q = (B * C + sign * A * s) / rho2;
  *a = {c[0] + L * (cos_q * u[0] + sin_q * v[0]), c[1] + L * (cos_q * u[1] + sin_q * v[1]),
        c[2] + L * (cos_q * u[2] + sin_q * v[2])};
  return true;
}

// det J' / prod |rows|, J' the twist form with rotational columns over the characteristic
// length; false when some chain cannot be assembled.
bool longDoubleMeasure(const RobotModel& model, const WorkingMode& mode, const Pose& pose, Real* measure) {
  const int n = model.dof();
  const bool spatial = model.hasOutputVariable(OutputVariable::Theta);
  std::vector<std::vector<Real>> rows;
  const Vec tcp = vec(pose.position);
  for (int c = 0; c < model.chainCount(); ++c) {
    const Vec p = toBase(pose, vec(model.chains[c]->platformNode()));
    Vec a{};
    if (!node(*model.chains[c], p, mode.branch(c) == Branch::Negative, &a)) return false;
    const Vec g = sub(p, a), moment = cross(sub(p, tcp), g);
    std::vector<Real> row;
    for (OutputVariable variable : model.output_variables) {
      const int v = static_cast<int>(variable);
      row.push_back(v < 3 ? g[v] : moment[spatial ? v - 3 : 2] / Real(model.characteristic_length));
    }
    Real norm = 0;
    for (Real x : row) norm += x * x;
    for (Real& x : row) x /= std::sqrt(norm);
    rows.push_back(row);
  }
  Real det = 1;
  for (int k = 0; k < n; ++k) {
    int pivot = k;
    for (int i = k + 1; i < n; ++i) {
      if (std::abs(rows[i][k]) > std::abs(rows[pivot][k])) pivot = i;
    }
    if (pivot != k) std::swap(rows[pivot], rows[k]), det = -det;
    det *= rows[k][k];
    if (rows[k][k] == 0) break;
    for (int i = k + 1; i < n; ++i) {
      const Real factor = rows[i][k] / rows[k][k];
      for (int j = k; j < n; ++j) rows[i][j] -= factor * rows[k][j];
    }
  }
  *measure = det;
  return true;
}

Pose between(const Pose& a, const Pose& b, double t) {
  Pose pose = a;
  pose.position = a.position + t * (b.position - a.position);
  pose.euler_zyz = a.euler_zyz + t * (b.euler_zyz - a.euler_zyz);
  return pose;
}

struct SignCheck {
  int decided = 0, near_zero = 0, disagreements = 0;
  long double largest_error = 0;
};

// Segments between random assembled poses; where working mode m's measure changes sign
// along one, the root is bisected and poses around it are checked.
SignCheck checkAroundSurfaces(const RobotModel& model, const std::vector<WorkingMode>& modes, bool orientation_fixed,
                              double spread, double turn, int segments) {
  const PoseClassifier classifier(model, modes, model.reference.pose, orientation_fixed);
  std::vector<double> at_a(modes.size()), at_b(modes.size()), at(modes.size());
  SignCheck check;
  const auto random_pose = [&] {
    Pose pose = model.reference.pose;
    pose.position += test::uniformVector(-spread, spread);
    if (!orientation_fixed) pose.euler_zyz += test::uniformVector(-turn, turn);
    return pose;
  };
  for (int s = 0; s < segments; ++s) {
    const Pose a = random_pose(), b = random_pose();
    if (!classifier.classify(a, at_a.data()) || !classifier.classify(b, at_b.data())) continue;
    for (std::size_t m = 0; m < modes.size(); ++m) {
      if ((at_a[m] > 0) == (at_b[m] > 0)) continue;
      double low = 0, high = 1;  // the measure has a's sign at low
      bool assembled = true;
      for (int k = 0; k < 60 && assembled; ++k) {
        const double middle = 0.5 * (low + high);
        assembled = classifier.classify(between(a, b, middle), at.data());
        ((at[m] > 0) == (at_a[m] > 0) ? low : high) = middle;
      }
      if (!assembled) continue;  // the segment leaves the workspace before the surface
      for (double offset : {0.0, 1e-14, -1e-14, 1e-12, -1e-12, 1e-10, -1e-10, 1e-8, -1e-8, 1e-6, -1e-6, 1e-5, -1e-5}) {
        const Pose pose = between(a, b, low + offset);
        Real exact = 0;
        if (!classifier.classify(pose, at.data()) || !longDoubleMeasure(model, modes[m], pose, &exact)) continue;
        check.largest_error = std::max(check.largest_error, std::abs(exact - Real(at[m])));
        const int sign = bandedSign(at[m], 0.0);
        if (sign == 0) continue;
        ++check.decided;
        check.near_zero += std::abs(at[m]) < 1e-6;
        check.disagreements += (exact > 0 ? 1 : -1) != sign;
      }
    }
  }
  return check;
}

void expectTrustedSigns(const SignCheck& check, const char* what) {
  std::printf("%s: %d signs decided (%d with |measure| < 1e-6), %d against long double; largest difference %.3Lg\n",
              what, check.decided, check.near_zero, check.disagreements, check.largest_error);
  EXPECT_EQ(check.disagreements, 0) << what;
  EXPECT_GT(check.near_zero, 200) << what << ": too few poses near the surfaces to tell";
  EXPECT_LT(check.largest_error, kMeasureTolerance / 10) << what << ": the tolerance has no room to spare";
}

TEST(MeasureSign, DeltaLikeFactorisedPathAgreesWithLongDouble) {
  const RobotModel& model = test::deltaLike();
  expectTrustedSigns(checkAroundSurfaces(model, coupledWorkingModes(model), true, 0.3, 0.0, 3000), "delta-like, factorised");
}

TEST(MeasureSign, DeltaLikeGenericPathAgreesWithLongDouble) {
  const RobotModel& model = test::deltaLike();
  expectTrustedSigns(checkAroundSurfaces(model, uncoupledWorkingModes(model), false, 0.3, 0.3, 400),
                     "delta-like uncoupled, turning, shared minors");
}

TEST(MeasureSign, FiveBarAgreesWithLongDouble) {
  const RobotModel& model = test::fiveBar();
  expectTrustedSigns(checkAroundSurfaces(model, coupledWorkingModes(model), true, 0.3, 0.0, 3000), "five-bar");
}

}  // namespace
}  // namespace maximal_workspace
