#pragma once
// Distance between two line segments. A rod of the robot is a capsule (its axis segment
// swept by a sphere of the rod's radius), so two rods interfere exactly when the distance
// between their axis segments is below the sum of their radii: no mesh, no GJK, and a
// closed form that also runs over batches of poses.

#include <cstddef>

#include <Eigen/Core>

namespace maximal_workspace {

// Squared distance between segments [a0, a1] and [b0, b1], closed form (closest parameters
// clamped to the segments); degenerate (zero-length) and parallel segments allowed.
double segmentDistanceSquared(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& b0,
                              const Eigen::Vector3d& b1);

// Endpoints of a batch of segments, as coordinate arrays.
struct SegmentBatch {
  const double *x0, *y0, *z0, *x1, *y1, *z1;
};

// out[i] = segmentDistanceSquared of segment i of `a` and segment i of `b` moved by
// `b_shift`: a branch-free loop the compiler vectorises. (The shift lets a couple's second
// rod, its first rod translated, be checked without copying it.)
void segmentDistancesSquared(std::size_t count, const SegmentBatch& a, const SegmentBatch& b, double* out,
                             const Eigen::Vector3d& b_shift = Eigen::Vector3d::Zero());

}  // namespace maximal_workspace
