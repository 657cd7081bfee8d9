// The one question the viewpoint planner asks of the arm before scoring a candidate.
#pragma once

#include <Eigen/Geometry>

namespace fvp::robot {

class Reachability {
 public:
  virtual ~Reachability() = default;
  /// Whether the arm can put its camera at this pose (position, and viewing direction =
  /// the camera's z axis). A quick, conservative-enough filter, not a guarantee: the motion
  /// planner has the last word.
  virtual bool reachable(const Eigen::Isometry3d& T_world_camera) const = 0;
};

}  // namespace fvp::robot
