// A capsule (a segment swept by a sphere): the link geometry of the arm for collision checks.
#pragma once

#include <Eigen/Core>

#include "fvp/host/core/segment_distance.h"

namespace fvp::robot {

struct Capsule {
  Eigen::Vector3d a_m = Eigen::Vector3d::Zero();  ///< segment end points, world frame
  Eigen::Vector3d b_m = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
};

using host::segmentSegmentDistance;

/// True when the two capsules overlap (surfaces closer than 0).
inline bool capsulesOverlap(const Capsule& c, const Capsule& d) {
  return segmentSegmentDistance(c.a_m, c.b_m, d.a_m, d.b_m) < c.radius_m + d.radius_m;
}

}  // namespace fvp::robot
