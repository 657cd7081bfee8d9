// Synthetic test images that need no renderer: textured fronto-parallel stereo planes with
// exact sub-pixel disparities, and an AprilTag drawn from libapriltag's own code bits at a
// known pose.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

#include "fvp/host/core/stereo_intrinsics.h"

namespace fvp::test {

/// A smooth random BGR texture (band-limited noise, good for SGBM).
cv::Mat randomTexture(cv::Size size, std::uint64_t seed);

/// A fronto-parallel rectangle of the left image at a constant disparity (in front of all
/// later-listed planes is NOT assumed: the largest disparity wins, as depth ordering does).
struct DisparityPlane {
  cv::Rect left_region;  ///< pixels of the left image it covers
  double disparity_px;
};

struct SyntheticPair {
  cv::Mat left, right;   ///< CV_8UC3
  cv::Mat disparity_px;  ///< CV_32F exact disparity of the left image (0: background)
};

/// Background at background_disparity_px everywhere, planes on top. Noise: Gaussian sigma in
/// grey levels.
SyntheticPair makeStereoPair(const host::StereoIntrinsics& K, double background_disparity_px,
                             const std::vector<DisparityPlane>& planes, double noise_sigma,
                             std::uint64_t seed);

/// Left image of a tag36h11 tag (id) of edge tag_size_m (black border) on a white plate of
/// plate_scale * tag_size_m, over a textured background, 4x4 supersampled, with noise.
cv::Mat renderTagImage(const host::StereoIntrinsics& K, const Eigen::Isometry3d& T_camera_tag,
                       int tag_id, double tag_size_m, double plate_scale, double noise_sigma,
                       std::uint64_t seed);

}  // namespace fvp::test
