// One captured image as sizing needs it.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "fvp/host/core/stereo_intrinsics.h"

namespace fvp::host::sizing {

/// A view's fruitlet segments as the sizer reads them: the connected components of the mask
/// (8-connected), or one segment per instance id where the view has instance ids.
struct ViewSegments {
  cv::Mat labels;            ///< CV_32S, 0 = background
  cv::Mat stats, centroids;  ///< as cv::connectedComponentsWithStats gives them
};

struct SizingView {
  cv::Mat fruitlet_mask;  ///< CV_8U, nonzero = fruitlet
  cv::Mat disparity_px;   ///< CV_32F, 0 = invalid
  StereoIntrinsics intrinsics;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  /// CV_16U instance ids when the segmentation gave them (0 = background); else empty, and
  /// fruitlets are told apart by the mask's connected components.
  cv::Mat fruitlet_instances;
};

/// The segments of a view's mask, or of its instance ids where it has them.
ViewSegments segmentsOf(const SizingView& view);

}  // namespace fvp::host::sizing
