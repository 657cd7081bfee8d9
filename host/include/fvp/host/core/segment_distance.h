// Distances between points and segments, for the simulator's placement checks and the arm's
// capsule collision checks.
#pragma once

#include <Eigen/Core>

namespace fvp::host {

/// The point of segment [a, b] nearest to p (a for a zero-length segment).
Eigen::Vector3d closestPointOnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                      const Eigen::Vector3d& b);

/// Shortest distance from p to the segment [a, b].
double pointSegmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b);

/// Shortest distance between the segments [p1, q1] and [p2, q2] (Ericson, Real-Time
/// Collision Detection, 5.1.9).
double segmentSegmentDistance(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1,
                              const Eigen::Vector3d& p2, const Eigen::Vector3d& q2);

/// Squared shortest distance between the segment [a, b] and the axis-aligned box [box_min,
/// box_max] (0 when they meet), exact: along the segment it is a convex piecewise quadratic whose
/// pieces end where the segment crosses a face's plane, minimised piece by piece.
double squaredSegmentBoxDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& box_min, const Eigen::Vector3d& box_max);

}  // namespace fvp::host
