// Disparity -> depth (z = fx * b / d) -> left-camera point -> world point (T_world_camera).
// Non-finite, zero/negative and out-of-range disparities are dropped and counted.
#pragma once

#include <Eigen/Geometry>
#include <limits>
#include <opencv2/core.hpp>

#include "fvp/host/core/labeled_clouds.h"
#include "fvp/host/core/stereo_intrinsics.h"

namespace fvp::host {

struct ProjectionConfig {
  double min_depth_m = 0.0;
  double max_depth_m = std::numeric_limits<double>::infinity();
};

/// Which pixels of a full-size disparity map are samples: every pixel inside full_res_rect,
/// and outside it one pixel per coarse_step^2 block (see DisparityResult).
struct SampleGrid {
  cv::Rect full_res_rect;  ///< empty with coarse_step 1: every pixel
  int coarse_step = 1;
  static SampleGrid everyPixel() { return {}; }
};

class CloudProjector {
 public:
  explicit CloudProjector(ProjectionConfig config = {}) : config_(config) {}

  /// disparity_px: CV_32F (pixels) of the left image; roi_mask: CV_8U, nonzero = ROI (may be
  /// empty: no ROI). The returned stats hold only the projection counts and projection_s.
  LabeledClouds project(const cv::Mat& disparity_px, const cv::Mat& roi_mask,
                        const StereoIntrinsics& intrinsics, const Eigen::Isometry3d& T_world_camera,
                        const SampleGrid& grid = SampleGrid::everyPixel()) const;

 private:
  ProjectionConfig config_;
};

}  // namespace fvp::host
