// A camera pose looking at a point: the OpenCV optical frame (x right, y down, z forward)
// with the image's "down" as close to world -z as possible, so views stay upright.
#pragma once

#include <Eigen/Geometry>

namespace fvp::host {

inline Eigen::Isometry3d lookAtPose(const Eigen::Vector3d& eye_m, const Eigen::Vector3d& target_m) {
  const Eigen::Vector3d z = (target_m - eye_m).normalized();
  Eigen::Vector3d y = -Eigen::Vector3d::UnitZ() + z.z() * z;
  if (y.norm() < 1e-9) y = Eigen::Vector3d::UnitY();  // looking straight up or down
  y.normalize();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = y.cross(z);
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = eye_m;
  return T;
}

}  // namespace fvp::host
