// Where the Cluster Region sphere appears in the left image: the fine-resolution band of
// the stereo matcher. Kept out of core/cluster_region.h so that the region stays OpenCV-free.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <optional>

#include "fvp/host/core/cluster_region.h"
#include "fvp/host/core/stereo_intrinsics.h"
#include "fvp/host/perception/stereo_matcher.h"

namespace fvp::host {

/// Bounding rectangle of the sphere's image in the left camera (exact tangents; clipped;
/// the whole image if the sphere reaches the camera plane; empty if it is out of view).
cv::Rect clusterRegionImageBounds(const ClusterRegion& region, const StereoIntrinsics& intrinsics,
                                  const Eigen::Isometry3d& T_world_camera);

/// The fine pass's search window: every disparity from the far side of the sphere grown by
/// depth_margin_m (less pad_px) up, so everything nearer than the region's far side (the
/// region and what hides it) is matched at full resolution, and what lies behind it is left
/// to the coarse pass. nullopt when the grown sphere is wholly behind the camera or its far
/// side at the camera plane.
std::optional<DisparityWindow> clusterRegionDisparityWindow(const ClusterRegion& region,
                                                            const StereoIntrinsics& intrinsics,
                                                            const Eigen::Isometry3d& T_world_camera,
                                                            double depth_margin_m, int pad_px);

}  // namespace fvp::host
