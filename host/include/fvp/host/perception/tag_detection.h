// One detected AprilTag with its pose.
//
// Tag frame (libapriltag's estimate_tag_pose convention, which the simulator follows): origin
// at the tag centre; x to the right and y down as the tag is printed (code bit columns and
// rows); z = x cross y points INTO the printed face, i.e. away from a viewer looking at it.
// Corner k of the black border square is at (s/2) * {(-1, 1), (1, 1), (1, -1), (-1, -1)}[k]
// in the tag's x-y plane, s = tag_size_m.
#pragma once

#include <Eigen/Geometry>
#include <array>

namespace fvp::host {

struct TagDetection {
  int tag_id = -1;
  int hamming = 0;                            ///< corrected bit errors
  float decision_margin = 0.0f;               ///< libapriltag's confidence
  std::array<Eigen::Vector2d, 4> corners_px;  ///< left image, in the order above
  Eigen::Vector2d center_px = Eigen::Vector2d::Zero();
  Eigen::Isometry3d T_camera_tag = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_world_tag = Eigen::Isometry3d::Identity();
  double object_space_error = 0.0;  ///< of estimate_tag_pose, m^2
};

}  // namespace fvp::host
