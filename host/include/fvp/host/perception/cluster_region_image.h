// Where the Cluster Region sphere appears in the left image: the fine-resolution band of
// the stereo matcher. Kept out of core/cluster_region.h so that the region stays OpenCV-free.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "fvp/host/core/cluster_region.h"
#include "fvp/host/core/stereo_intrinsics.h"

namespace fvp::host {

/// Bounding rectangle of the sphere's image in the left camera (exact tangents; clipped;
/// the whole image if the sphere reaches the camera plane; empty if it is out of view).
cv::Rect clusterRegionImageBounds(const ClusterRegion& region, const StereoIntrinsics& intrinsics,
                                  const Eigen::Isometry3d& T_world_camera);

}  // namespace fvp::host
