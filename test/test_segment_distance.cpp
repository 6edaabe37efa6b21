// The closed-form segment distance (kinematics/segment_distance.h) against FCL's capsule
// distance, against distances worked out by hand, and batch against scalar.

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include <fcl/narrowphase/distance.h>
#include <gtest/gtest.h>

#include "kinematics/segment_distance.h"

namespace maximal_workspace {
namespace {

using Eigen::Vector3d;

struct SegmentPair {
  Vector3d a0, a1, b0, b1;
};

// The crafted cases, each with its distance worked out by hand.
struct Crafted {
  const char* name;
  SegmentPair pair;
  double distance;
};
const std::vector<Crafted> kCrafted = {
    {"skew perpendicular", {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0.3}, {0, 1, 0.3}}, 0.3},
    {"parallel overlapping", {{0, 0, 0}, {1, 0, 0}, {0.5, 0.2, 0}, {1.5, 0.2, 0}}, 0.2},
    {"parallel disjoint", {{0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 1, 0}}, std::sqrt(2.0)},
    {"parallel disjoint reversed", {{0, 0, 0}, {1, 0, 0}, {3, 1, 0}, {2, 1, 0}}, std::sqrt(2.0)},
    {"antiparallel overlapping", {{0, 0, 0}, {1, 0, 0}, {0.8, 0, 0.1}, {0.2, 0, 0.1}}, 0.1},
    {"collinear disjoint", {{0, 0, 0}, {1, 0, 0}, {1.25, 0, 0}, {2, 0, 0}}, 0.25},
    {"crossing", {{-1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {1, -1, 0}}, 0.0},
    {"T-junction", {{-1, 0, 0}, {1, 0, 0}, {0, 0.5, 0}, {0, 2, 0}}, 0.5},
    {"point beside segment", {{0.3, 0.4, 0}, {0.3, 0.4, 0}, {0, 0, 0}, {1, 0, 0}}, 0.4},
    {"point beyond segment end", {{0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {2, 1, 0}}, std::sqrt(2.0)},
    {"both points", {{0, 0, 0}, {0, 0, 0}, {1, 2, 2}, {1, 2, 2}}, 3.0},
};

// Random pairs: lengths 0.01..1 m from points in a 1 m box; every fifth pair nearly
// parallel (angles 1e-12..1e-2 rad), where the closed form is at its weakest.
std::vector<SegmentPair> randomPairs(int count) {
  std::mt19937 random(20240611);
  std::uniform_real_distribution<double> box(0.0, 1.0), length(0.01, 1.0), exponent(-12.0, -2.0);
  std::normal_distribution<double> normal;
  auto direction = [&] { return Vector3d(normal(random), normal(random), normal(random)).normalized(); };
  std::vector<SegmentPair> pairs;
  for (int i = 0; i < count; ++i) {
    const Vector3d a0(box(random), box(random), box(random)), b0(box(random), box(random), box(random));
    const Vector3d da = direction();
    Vector3d db = direction();
    if (i % 5 == 0) db = (da + std::pow(10.0, exponent(random)) * da.cross(db).normalized()).normalized();
    pairs.push_back({a0, a0 + length(random) * da, b0, b0 + length(random) * db});
  }
  return pairs;
}

// FCL's distance between capsules of radius r about the two segments, plus both radii:
// its own distance between the segments.
double fclSegmentDistance(const SegmentPair& pair, double r) {
  auto capsule = [r](const Vector3d& p0, const Vector3d& p1, fcl::Transform3d& pose) {
    const Vector3d axis = p1 - p0;
    pose = fcl::Transform3d::Identity();
    pose.translation() = 0.5 * (p0 + p1);
    if (axis.norm() > 0.0) pose.linear() = Eigen::Quaterniond::FromTwoVectors(Vector3d::UnitZ(), axis).matrix();
    return fcl::Capsuled(r, axis.norm());
  };
  fcl::Transform3d pose_a, pose_b;
  const fcl::Capsuled a = capsule(pair.a0, pair.a1, pose_a), b = capsule(pair.b0, pair.b1, pose_b);
  fcl::DistanceRequestd request;  // GST_LIBCCD by default: capsule pairs go to its exact capsule-capsule routine
  fcl::DistanceResultd result;
  return fcl::distance(&a, pose_a, &b, pose_b, request, result) + 2.0 * r;
}

double ours(const SegmentPair& p) { return segmentDistanceSquared(p.a0, p.a1, p.b0, p.b1); }

TEST(SegmentDistance, CraftedCasesMatchHandWorkedDistances) {
  for (const Crafted& c : kCrafted) {
    const SegmentPair& p = c.pair;
    EXPECT_NEAR(std::sqrt(ours(p)), c.distance, 1e-12) << c.name;
    // Symmetric in the segments and in each segment's direction.
    EXPECT_NEAR(segmentDistanceSquared(p.b1, p.b0, p.a0, p.a1), ours(p), 1e-14) << c.name;
    EXPECT_NEAR(segmentDistanceSquared(p.a1, p.a0, p.b1, p.b0), ours(p), 1e-14) << c.name;
  }
}

TEST(SegmentDistance, SeparatedPairsMatchFcl) {
  const double r = 0.001;
  std::vector<SegmentPair> pairs = randomPairs(4000);
  for (const Crafted& c : kCrafted) pairs.push_back(c.pair);
  double max_difference = 0.0;
  int compared = 0;
  for (const SegmentPair& p : pairs) {
    const double distance = std::sqrt(ours(p));
    ASSERT_TRUE(std::isfinite(distance));
    if (distance <= 2.0 * r + 1e-4) continue;  // FCL reports penetrating capsules differently
    const double difference = std::abs(distance - fclSegmentDistance(p, r));
    EXPECT_LT(difference, 1e-6) << p.a0.transpose() << " " << p.a1.transpose() << " / " << p.b0.transpose() << " "
                                << p.b1.transpose();
    max_difference = std::max(max_difference, difference);
    ++compared;
  }
  EXPECT_GT(compared, 3900);
  std::cout << "compared " << compared << " pairs with FCL, max |difference| " << max_difference << " m\n";
}

TEST(SegmentDistance, BatchEqualsScalar) {
  std::vector<SegmentPair> pairs = randomPairs(3001);  // not a multiple of the vector width
  for (const Crafted& c : kCrafted) pairs.push_back(c.pair);
  const std::size_t n = pairs.size();
  std::vector<double> coordinates(12 * n), out(n, -1.0);
  auto column = [&](int k) { return coordinates.data() + k * n; };
  for (std::size_t i = 0; i < n; ++i) {
    const Vector3d* points[4] = {&pairs[i].a0, &pairs[i].a1, &pairs[i].b0, &pairs[i].b1};
    for (int k = 0; k < 12; ++k) column(k)[i] = (*points[k / 3])[k % 3];
  }
  const SegmentBatch a{column(0), column(1), column(2), column(3), column(4), column(5)};
  const SegmentBatch b{column(6), column(7), column(8), column(9), column(10), column(11)};
  segmentDistancesSquared(n, a, b, out.data());
  for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(out[i], ours(pairs[i]), 1e-12) << "pair " << i;
}

}  // namespace
}  // namespace maximal_workspace
