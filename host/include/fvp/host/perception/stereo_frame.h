// One captured stereo view: what a real camera gives (the rectified pair, its pose and
// intrinsics) and, when the robot has them, its own segmentation and disparity. Nothing
// here is simulator vocabulary: the simulator's exact layers (depth, object ids) travel
// beside the frame (robot/sim/stereo_renderer.h, RenderedView).
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "fvp/host/core/stereo_intrinsics.h"

namespace fvp::host {

struct StereoFrame {
  cv::Mat left_bgr;   ///< CV_8UC3, rectified left image
  cv::Mat right_bgr;  ///< CV_8UC3, rectified right image
  StereoIntrinsics intrinsics;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();  ///< left camera pose
  // Optional outside perception, used as given when present (a robot's segmentation network
  // and stereo matcher); HSV segmentation and SGBM run only when these are empty.
  /// Left image size. CV_8U: nonzero = fruitlet (fruitlets are told apart where their
  /// pixels are). CV_16U: an instance segmentation, 0 = background and each nonzero id one
  /// fruitlet (ids need not agree between views): touching fruitlets stay apart.
  cv::Mat fruitlet_mask;
  cv::Mat disparity_px;  ///< CV_32F, left image size, left-image disparity in pixels, 0 invalid
};

}  // namespace fvp::host
