// One captured stereo view: what a real camera gives (the rectified pair, its pose and
// intrinsics) plus, in simulation only, exact ground-truth layers for tests/ablations.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "fvp/host/core/stereo_intrinsics.h"

namespace fvp::host {

/// Object ids of the simulator's id layer (CV_32S): 0 is background/sky.
inline constexpr int kBackgroundId = 0;
inline constexpr int kFirstFruitletId = 1;  ///< fruitlet i has id kFirstFruitletId + i
inline constexpr int kMaxFruitlets = 64;
inline constexpr int kFirstLeafId = 100;  ///< leaf k has id kFirstLeafId + k
inline constexpr int kTreeId = 10000;     ///< trunk and branches
inline constexpr int kTagId = 20000;      ///< the AprilTag and its backing plate
inline bool isFruitletId(int id) {
  return id >= kFirstFruitletId && id < kFirstFruitletId + kMaxFruitlets;
}

struct StereoFrame {
  cv::Mat left_bgr;   ///< CV_8UC3, rectified left image
  cv::Mat right_bgr;  ///< CV_8UC3, rectified right image
  StereoIntrinsics intrinsics;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();  ///< left camera pose
  // Optional outside perception, used as given when present (a robot's segmentation network
  // and stereo matcher); HSV segmentation and SGBM run only when these are empty.
  cv::Mat fruitlet_mask;  ///< CV_8U, left image size, nonzero = fruitlet
  cv::Mat disparity_px;   ///< CV_32F, left image size, left-image disparity in pixels, 0 invalid

  // Simulation-only ground truth of the left image (empty for real captures).
  cv::Mat gt_depth_m;    ///< CV_32F z-depth per pixel, 0 where nothing was hit
  cv::Mat gt_object_id;  ///< CV_32S object id of the surface seen at the pixel centre
};

}  // namespace fvp::host
