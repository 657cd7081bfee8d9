#include "fvp/host/core/segment_distance.h"

#include <algorithm>
#include <array>
#include <limits>

namespace fvp::host {

Eigen::Vector3d closestPointOnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                      const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return a + t * ab;
}

double pointSegmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b) {
  return (closestPointOnSegment(p, a, b) - p).norm();
}

double segmentSegmentDistance(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1,
                              const Eigen::Vector3d& p2, const Eigen::Vector3d& q2) {
  constexpr double kEps = 1e-15;
  const Eigen::Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= kEps && e <= kEps) return r.norm();
  if (a <= kEps) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= kEps) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;
      s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return (p1 + s * d1 - (p2 + t * d2)).norm();
}

double squaredSegmentBoxDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& box_min, const Eigen::Vector3d& box_max) {
  const Eigen::Vector3d d = b - a;
  // The parameters in (0, 1) where the segment crosses a face's plane end the pieces.
  std::array<double, 8> ends{};
  int count = 0;
  ends[count++] = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    if (d[axis] == 0.0) continue;
    for (const double plane : {box_min[axis], box_max[axis]}) {
      const double t = (plane - a[axis]) / d[axis];
      if (t > 0.0 && t < 1.0) ends[count++] = t;
    }
  }
  ends[count++] = 1.0;
  std::sort(ends.begin(), ends.begin() + count);
  double best = std::numeric_limits<double>::infinity();
  for (int piece = 0; piece + 1 < count; ++piece) {
    const double t0 = ends[piece], t1 = ends[piece + 1];
    const Eigen::Vector3d mid = a + (0.5 * (t0 + t1)) * d;
    // On this piece each axis is below, inside or above the box throughout: the squared
    // distance is the sum over the outside axes of (a + t d - face)^2, a parabola in t.
    double quadratic = 0.0, linear = 0.0;
    Eigen::Vector3d face = Eigen::Vector3d::Zero(), outside = Eigen::Vector3d::Zero();
    for (int axis = 0; axis < 3; ++axis) {
      if (mid[axis] < box_min[axis]) {
        face[axis] = box_min[axis];
      } else if (mid[axis] > box_max[axis]) {
        face[axis] = box_max[axis];
      } else {
        continue;
      }
      outside[axis] = 1.0;
      quadratic += d[axis] * d[axis];
      linear += d[axis] * (a[axis] - face[axis]);
    }
    const double t = quadratic > 0.0 ? std::clamp(-linear / quadratic, t0, t1) : t0;
    // At t = 1 the point is b itself, not a + d rounded.
    const Eigen::Vector3d point = t == 1.0 ? b : Eigen::Vector3d(a + t * d);
    best = std::min(best, ((point - face).cwiseProduct(outside)).squaredNorm());
  }
  return best;
}

}  // namespace fvp::host
