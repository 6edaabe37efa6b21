// Closed-form IKP of each chain type against independent geometry: closure, existence,
// branch order, J_IKP by finite differences and at the IKP singularity.

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "maximal_workspace/model/pss_chain.h"
#include "maximal_workspace/model/rss_chain.h"
#include "test_support.h"

namespace maximal_workspace {
namespace {

constexpr int kSamples = 2000;

ChainCommon common(double rod_length) { return ChainCommon{"leg", "q", Eigen::Vector3d::Zero(), rod_length, {}}; }

PssChain randomPss() {
  return PssChain(common(test::uniform(0.2, 1.5)), test::uniformVector(-1.0, 1.0), test::randomUnitVector());
}

RssChain randomRss() {
  const Eigen::Vector3d axis = test::randomUnitVector();
  Eigen::Vector3d zero = test::randomUnitVector();
  while (zero.cross(axis).norm() < 0.2) zero = test::randomUnitVector();
  return RssChain(common(test::uniform(0.2, 1.5)), test::uniformVector(-1.0, 1.0), axis, test::uniform(0.1, 1.0), zero);
}

// Half the derivative of Eq. 1 with respect to q, by central differences.
double halfDfDqNumeric(const Chain& chain, const Eigen::Vector3d& p, double q) {
  const double h = 1e-6;
  auto f = [&](double x) { return (p - chain.intermediateNode(x)).squaredNorm() - chain.rodLength() * chain.rodLength(); };
  return 0.5 * (f(q + h) - f(q - h)) / (2.0 * h);
}

double ikpJacobianEntry(const Chain& chain, const Eigen::Vector3d& p, double q) {
  return -(p - chain.intermediateNode(q)).dot(chain.intermediateNodeRate(q));
}

// Both branches close the chain (|p - a| = R, a = a(q)) and J_IKP matches Eq. 1.
void expectBranchesClose(const Chain& chain, const Eigen::Vector3d& p, const ChainSolution& solution) {
  for (Branch b : {Branch::Positive, Branch::Negative}) {
    const ChainBranch& branch = solution.branch(b);
    EXPECT_NEAR((p - branch.a).norm(), chain.rodLength(), 1e-12);
    EXPECT_LT((chain.intermediateNode(branch.q) - branch.a).norm(), 1e-12);
    const double analytic = ikpJacobianEntry(chain, p, branch.q);
    const double numeric = halfDfDqNumeric(chain, p, branch.q);
    EXPECT_LE(std::abs(analytic - numeric), 1e-6 * std::max(1e-3, std::abs(analytic)));
  }
}

TEST(PssChain, BranchesCloseOnTheSliderLine) {
  int assembled = 0;
  for (int k = 0; k < kSamples; ++k) {
    const PssChain chain = randomPss();
    const Eigen::Vector3d p = test::uniformVector(-1.5, 1.5);
    const ChainSolution solution = chain.solve(p);
    if (!solution.assembled) continue;
    ++assembled;
    expectBranchesClose(chain, p, solution);
    for (Branch b : {Branch::Positive, Branch::Negative}) {
      // a lies on the line f + q d.
      EXPECT_LT((solution.branch(b).a - chain.fixedNode()).cross(chain.direction()).norm(), 1e-12);
    }
    // p is the + root: farther along d.
    EXPECT_GE(solution.branch(Branch::Positive).q, solution.branch(Branch::Negative).q);
  }
  EXPECT_GT(assembled, kSamples / 10);
}

TEST(PssChain, DiscriminantNegativeExactlyWhenTheSphereMissesTheLine) {
  int tested = 0;
  for (int k = 0; k < kSamples; ++k) {
    const PssChain chain = randomPss();
    const Eigen::Vector3d p = test::uniformVector(-1.5, 1.5);
    // The sphere of radius R about p meets the line iff p is within R of it.
    const double distance = (p - chain.fixedNode()).cross(chain.direction()).norm();
    if (std::abs(distance - chain.rodLength()) < 1e-9) continue;
    ++tested;
    const ChainSolution solution = chain.solve(p);
    EXPECT_EQ(solution.discriminant < 0.0, distance > chain.rodLength());
    EXPECT_EQ(solution.assembled, distance < chain.rodLength());
  }
  EXPECT_EQ(tested, kSamples);
}

// Over a box of platform nodes the discriminant's enclosure holds its value at every point
// of the box; and for a slider along an axis, where D = R^2 minus the squares of the two
// other offsets, it is that closed form's exact range (each square's range taken apart), to
// rounding: the offset along the slider, which D does not depend on, widens nothing.
// The discriminant's enclosure over a box of platform nodes about `centre` holds its value
// at points drawn in the box.
void expectDiscriminantEnclosed(const Chain& chain, const Eigen::Vector3d& centre) {
  const Eigen::Vector3d half = test::uniformVector(0.0, 0.05);
  IntervalPoint box;
  for (int i = 0; i < 3; ++i) box[i] = Interval(centre[i] - half[i], centre[i] + half[i]);
  const Interval enclosure = chain.discriminantEnclosure(box);
  for (int trial = 0; trial < 16; ++trial) {
    const Eigen::Vector3d p = centre + half.cwiseProduct(test::uniformVector(-1.0, 1.0));
    const double at_point = chain.solve(p).discriminant;
    EXPECT_LE(enclosure.lower(), at_point + 1e-12) << chain.type();
    EXPECT_GE(enclosure.upper(), at_point - 1e-12) << chain.type();
  }
}

TEST(PssChain, DiscriminantEnclosureHoldsTheBoxAndIsExactForASliderAlongAnAxis) {
  for (int k = 0; k < 200; ++k) {
    const PssChain chain = randomPss();
    expectDiscriminantEnclosed(chain, chain.fixedNode() + test::uniformVector(-1.5, 1.5));
  }
  const auto squareRange = [](double low, double high) {
    const double low_square = low > 0.0 ? low * low : high < 0.0 ? high * high : 0.0;
    return std::array<double, 2>{low_square, std::max(low * low, high * high)};
  };
  for (int axis = 0; axis < 3; ++axis) {
    const double rod = 0.5;
    const PssChain chain(common(rod), Eigen::Vector3d(-0.8, -0.29, 0.0), Eigen::Vector3d::Unit(axis));
    for (int k = 0; k < 50; ++k) {
      const Eigen::Vector3d centre = chain.fixedNode() + test::uniformVector(-0.6, 0.6);
      const double half = test::uniform(0.001, 0.05);
      IntervalPoint box;
      double lowest = rod * rod, highest = rod * rod;
      for (int i = 0; i < 3; ++i) {
        box[i] = Interval(centre[i] - half, centre[i] + half);
        if (i == axis) continue;
        const std::array<double, 2> range =
            squareRange(centre[i] - half - chain.fixedNode()[i], centre[i] + half - chain.fixedNode()[i]);
        lowest -= range[1];
        highest -= range[0];
      }
      const Interval enclosure = chain.discriminantEnclosure(box);
      EXPECT_NEAR(enclosure.lower(), lowest, 1e-12) << "slider along axis " << axis;
      EXPECT_NEAR(enclosure.upper(), highest, 1e-12) << "slider along axis " << axis;
    }
  }
}

TEST(PssChain, IkpJacobianVanishesOnTheReachBoundary) {
  int assembled = 0;
  for (int k = 0; k < 200; ++k) {
    const PssChain chain = randomPss();
    // A point at exactly R from the slider line.
    Eigen::Vector3d normal = test::randomUnitVector().cross(chain.direction()).normalized();
    const Eigen::Vector3d p = chain.fixedNode() + test::uniform(-1, 1) * chain.direction() + chain.rodLength() * normal;
    const ChainSolution solution = chain.solve(p);
    const double r2 = chain.rodLength() * chain.rodLength();
    EXPECT_LT(std::abs(solution.discriminant), 1e-12 * r2);
    if (!solution.assembled) continue;  // rounding may put it a hair outside
    ++assembled;
    EXPECT_LT(std::abs(ikpJacobianEntry(chain, p, solution.branch(Branch::Positive).q)), 1e-6 * chain.rodLength());
    EXPECT_NEAR(solution.branch(Branch::Positive).q, solution.branch(Branch::Negative).q, 1e-6);
  }
  EXPECT_GT(assembled, 20);
}

TEST(RssChain, BranchesCloseOnTheCrankCircle) {
  int assembled = 0;
  for (int k = 0; k < kSamples; ++k) {
    const RssChain chain = randomRss();
    const Eigen::Vector3d p = test::uniformVector(-1.5, 1.5);
    const ChainSolution solution = chain.solve(p);
    if (!solution.assembled) continue;
    ++assembled;
    expectBranchesClose(chain, p, solution);
    const Eigen::Vector3d v = chain.axis().cross(chain.crankZero());
    const Eigen::Vector3d w = p - chain.crankCentre();
    const double projection_angle = std::atan2(v.dot(w), chain.crankZero().dot(w));
    for (Branch b : {Branch::Positive, Branch::Negative}) {
      const Eigen::Vector3d crank = solution.branch(b).a - chain.crankCentre();
      EXPECT_NEAR(crank.norm(), chain.crankLength(), 1e-12);
      EXPECT_NEAR(crank.dot(chain.axis()), 0.0, 1e-12);
      // The + root turns positively about e from the projection of w, the - root negatively.
      const double turn = std::remainder(solution.branch(b).q - projection_angle, 2.0 * M_PI);
      EXPECT_TRUE(b == Branch::Positive ? turn >= -1e-9 : turn <= 1e-9) << "turn " << turn;
    }
  }
  EXPECT_GT(assembled, kSamples / 10);
}

TEST(RssChain, DiscriminantNegativeExactlyWhenTheSphereMissesTheCircle) {
  int tested = 0;
  for (int k = 0; k < 300; ++k) {
    const RssChain chain = randomRss();
    const Eigen::Vector3d p = test::uniformVector(-1.5, 1.5);
    // Nearest and farthest crank-circle points from p, by dense sampling of the circle.
    double nearest = INFINITY, farthest = 0.0;
    for (int s = 0; s < 20000; ++s) {
      const double distance = (p - chain.intermediateNode(2.0 * M_PI * s / 20000)).norm();
      nearest = std::min(nearest, distance);
      farthest = std::max(farthest, distance);
    }
    const double margin = std::min(std::abs(nearest - chain.rodLength()), std::abs(farthest - chain.rodLength()));
    if (margin < 1e-4) continue;  // too close to the boundary for the sampling to tell
    ++tested;
    const bool reachable = nearest < chain.rodLength() && chain.rodLength() < farthest;
    EXPECT_EQ(chain.solve(p).discriminant >= 0.0, reachable);
  }
  EXPECT_GT(tested, 250);
}

// The factored enclosure (the sphere against the crank circle's near and far points) holds
// the discriminant over boxes anywhere about the crank, the axis and the circle included;
// and a box whose points all lie at least 1 cm from the nearest point of the sphere's reach
// limit (the torus swept by the rod's far end) is decided.
TEST(RssChain, DiscriminantEnclosureHoldsTheBoxAndDecidesBoxesAwayFromTheReachLimit) {
  int decided = 0, clear = 0;
  for (int k = 0; k < 400; ++k) {
    const RssChain chain = randomRss();
    const double reach = chain.rodLength() + chain.crankLength();
    const Eigen::Vector3d centre = chain.crankCentre() + test::uniformVector(-1.2, 1.2) * reach;
    expectDiscriminantEnclosed(chain, centre);
    // Distance from the crank circle: the chain assembles where it lies within R of p.
    const Eigen::Vector3d w = centre - chain.crankCentre();
    const double along = w.dot(chain.axis()), across = (w - along * chain.axis()).norm();
    const double nearest = std::hypot(across - chain.crankLength(), along), farthest = std::hypot(across + chain.crankLength(), along);
    const double half = 0.005, diagonal = half * std::sqrt(3.0);
    // Within [nearest, farthest] of the circle lies R exactly when the chain assembles.
    const double clearance = std::min({std::abs(chain.rodLength() - nearest), std::abs(farthest - chain.rodLength())});
    if (clearance < diagonal + 0.01) continue;
    ++clear;
    IntervalPoint box;
    for (int i = 0; i < 3; ++i) box[i] = Interval(centre[i] - half, centre[i] + half);
    const Interval enclosure = chain.discriminantEnclosure(box);
    decided += enclosure.lower() > 0.0 || enclosure.upper() < 0.0;
  }
  EXPECT_GT(clear, 100);
  EXPECT_EQ(decided, clear);
}

TEST(RssChain, IkpJacobianVanishesOnTheReachBoundary) {
  int assembled = 0;
  for (int k = 0; k < 200; ++k) {
    const RssChain chain = randomRss();
    // The sphere about p touches the circle at a(q0) when p - a(q0) has length R and is
    // normal to the circle's tangent there: in the plane of the crank and the axis.
    const double q0 = test::uniform(-M_PI, M_PI), t = test::uniform(-M_PI, M_PI);
    const Eigen::Vector3d a0 = chain.intermediateNode(q0);
    const Eigen::Vector3d radial = (a0 - chain.crankCentre()).normalized();
    const Eigen::Vector3d p = a0 + chain.rodLength() * (std::cos(t) * radial + std::sin(t) * chain.axis());
    const ChainSolution solution = chain.solve(p);
    const double w_scale = 2.0 * chain.crankLength() * (p - chain.crankCentre()).norm();
    EXPECT_LT(std::abs(solution.discriminant), 1e-10 * w_scale * w_scale);
    if (!solution.assembled) continue;  // rounding may put it a hair outside
    ++assembled;
    const double jacobian = ikpJacobianEntry(chain, p, solution.branch(Branch::Positive).q);
    EXPECT_LT(std::abs(jacobian), 1e-4 * chain.rodLength() * chain.crankLength());
    EXPECT_LT(chain.inputDistance(solution.branch(Branch::Positive).q, q0), 1e-4);
  }
  EXPECT_GT(assembled, 20);
}

TEST(RssChain, PointOnTheAxisAtCrankDistanceAssemblesWithAnyInput) {
  const RssChain chain(common(0.5), Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.3, Eigen::Vector3d::UnitX());
  // |p - a(q)|^2 = 0.4^2 + 0.3^2 = 0.5^2 for every q.
  const Eigen::Vector3d p(0.0, 0.0, 0.4);
  const ChainSolution solution = chain.solve(p);
  ASSERT_TRUE(solution.assembled);
  expectBranchesClose(chain, p, solution);
}

// The batch form against the one-point form, for points on both sides of the reach
// boundary and a count that is not a multiple of any vector width. The branches must close
// the chain on their own: the batch kernels are written apart from the scalar ones.
void expectBatchMatchesPointByPoint(const Chain& chain, const std::vector<Eigen::Vector3d>& points) {
  const std::size_t n = points.size();
  std::vector<double> x(n), y(n), z(n), discriminant(n);
  std::vector<double> a[2][3];
  for (auto& branch : a) {
    for (auto& axis : branch) axis.assign(n, 0.0);
  }
  for (std::size_t i = 0; i < n; ++i) x[i] = points[i].x(), y[i] = points[i].y(), z[i] = points[i].z();
  NodeBatch nodes;
  nodes.discriminant = discriminant.data();
  for (int b = 0; b < 2; ++b) nodes.x[b] = a[b][0].data(), nodes.y[b] = a[b][1].data(), nodes.z[b] = a[b][2].data();
  chain.intermediateNodes(PointBatch{x.data(), y.data(), z.data(), n}, nodes);
  int assembled = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const ChainNodes one = chain.intermediateNodes(points[i]);
    EXPECT_NEAR(discriminant[i], one.discriminant, 1e-12 * std::max(1.0, std::abs(one.discriminant)));
    ASSERT_TRUE(std::isfinite(a[0][0][i]) && std::isfinite(a[1][2][i])) << "point " << i;
    if (!one.assembled) continue;
    ++assembled;
    for (int b = 0; b < 2; ++b) {
      const Eigen::Vector3d node(a[b][0][i], a[b][1][i], a[b][2][i]);
      EXPECT_LT((node - one.a[b]).norm(), 1e-12) << "point " << i << " branch " << b;
      EXPECT_NEAR((points[i] - node).norm(), chain.rodLength(), 1e-12);
    }
  }
  EXPECT_GT(assembled, static_cast<int>(n) / 10);
  EXPECT_LT(assembled, static_cast<int>(n));
}

std::vector<Eigen::Vector3d> pointsAround(const Eigen::Vector3d& centre, double spread, int count) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) points.push_back(centre + test::uniformVector(-spread, spread));
  return points;
}

// How many of `trials` straight moves between two platform nodes where the chain
// assembles (drawn about `centre`, `spread` wide) leave its reach on the way (sampled at
// 64 points).
int movesLeavingTheReach(const Chain& chain, const Eigen::Vector3d& centre, double spread, int trials) {
  int leaving = 0;
  for (int k = 0; k < trials; ++k) {
    Eigen::Vector3d ends[2];
    for (Eigen::Vector3d& end : ends) {
      do end = centre + test::uniformVector(-spread, spread);
      while (!chain.intermediateNodes(end).assembled);
    }
    for (int s = 1; s < 64; ++s) {
      if (!chain.intermediateNodes(ends[0] + (s / 64.0) * (ends[1] - ends[0])).assembled) {
        ++leaving;
        break;
      }
    }
  }
  return leaving;
}

// The thin layers' check skips the chains whose discriminant is concave along a
// translation (workspace/thin_layers.h): none of their moves may leave the reach, and a
// chain that says otherwise has moves that do.
TEST(ChainReach, ConcaveDiscriminantMeansStraightMovesStayAssembled) {
  for (int k = 0; k < 20; ++k) {
    const PssChain pss = randomPss();
    ASSERT_TRUE(pss.concaveDiscriminant());
    EXPECT_EQ(movesLeavingTheReach(pss, pss.fixedNode(), 1.5 * pss.rodLength(), 200), 0);
    // Concave: above the chord at the midpoint.
    const Eigen::Vector3d a = test::uniformVector(-1.5, 1.5), b = test::uniformVector(-1.5, 1.5);
    const double chord = 0.5 * (pss.solve(a).discriminant + pss.solve(b).discriminant);
    EXPECT_GE(pss.solve(0.5 * (a + b)).discriminant, chord - 1e-12);
  }
  int leaving = 0;
  for (int k = 0; k < 20; ++k) {
    const RssChain rss = randomRss();
    ASSERT_FALSE(rss.concaveDiscriminant());
    leaving += movesLeavingTheReach(rss, rss.crankCentre(), rss.rodLength() + rss.crankLength(), 200);
  }
  EXPECT_GT(leaving, 0) << "a crank's reach is a shell about its circle, not a convex set";
}

// The discriminant's gradient enclosure over a box (the certified volumes' shares of a
// cell) holds the central-difference gradient at points of the box, and over a point it is
// that gradient.
void expectGradientEnclosed(const Chain& chain, const Eigen::Vector3d& centre, double half) {
  IntervalPoint box;
  for (int k = 0; k < 3; ++k) box[k] = Interval(centre[k] - half, centre[k] + half);
  const IntervalPoint over_box = chain.discriminantGradientEnclosure(box);
  const double h = 1e-6;
  for (int trial = 0; trial < 8; ++trial) {
    const Eigen::Vector3d p = centre + test::uniformVector(-half, half);
    const IntervalPoint at_point = chain.discriminantGradientEnclosure(pointInterval(p));
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(k);
      const double numeric = (chain.solve(p + step).discriminant - chain.solve(p - step).discriminant) / (2.0 * h);
      const double tolerance = 1e-6 * std::max(1.0, std::abs(numeric));
      EXPECT_NEAR(median(at_point[k]), numeric, tolerance) << chain.type() << " axis " << k;
      EXPECT_LE(over_box[k].lower(), numeric + tolerance) << chain.type() << " axis " << k;
      EXPECT_GE(over_box[k].upper(), numeric - tolerance) << chain.type() << " axis " << k;
    }
  }
}

TEST(ChainReach, DiscriminantGradientMatchesFiniteDifferencesAndItsEnclosureHoldsIt) {
  for (int k = 0; k < 50; ++k) {
    const PssChain pss = randomPss();
    expectGradientEnclosed(pss, pss.fixedNode() + test::uniformVector(-1.2, 1.2) * pss.rodLength(), 0.01);
    const RssChain rss = randomRss();
    const double reach = rss.rodLength() + rss.crankLength();
    expectGradientEnclosed(rss, rss.crankCentre() + test::uniformVector(-1.2, 1.2) * reach, 0.01);
  }
}

TEST(PssChain, BatchMatchesPointByPoint) {
  for (int k = 0; k < 20; ++k) {
    const PssChain chain = randomPss();
    expectBatchMatchesPointByPoint(chain, pointsAround(chain.fixedNode(), 1.2 * chain.rodLength(), 333));
  }
}

TEST(RssChain, BatchMatchesPointByPoint) {
  for (int k = 0; k < 20; ++k) {
    const RssChain chain = randomRss();
    std::vector<Eigen::Vector3d> points =
        pointsAround(chain.crankCentre(), chain.rodLength() + chain.crankLength(), 333);
    expectBatchMatchesPointByPoint(chain, points);
  }
  // On the axis (A = B = 0) the batch kernel takes q = 0 for both branches, as solve does.
  const RssChain chain(common(0.5), Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.3, Eigen::Vector3d::UnitX());
  std::vector<Eigen::Vector3d> points = {Eigen::Vector3d(0.0, 0.0, 0.4), Eigen::Vector3d(0.1, 0.2, 0.3),
                                         Eigen::Vector3d(0.0, 0.0, 2.0)};
  expectBatchMatchesPointByPoint(chain, points);
}

}  // namespace
}  // namespace maximal_workspace
