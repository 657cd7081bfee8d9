// The full-resolution stereo pass as compute kernels (kernels/fvp_stereo.h): semi-global
// matching guided by the reduced-resolution pass, on any backend (cpu, opencl, vulkan give
// the same disparities). Each band pixel searches two windows of 8 disparities around what
// the reduced pass found near it, not the whole range; the census cost, 8 paths, SGBM's
// uniqueness, subpixel and left-right rules, then OpenCV's speckle filter on the host.
#pragma once

#include <memory>
#include <opencv2/core.hpp>

// C++17 consumers (the ROS nodes) include this: the backend stays a declaration here.
namespace fvp::accel {
class Backend;
class DeviceBuffer;
}  // namespace fvp::accel

namespace fvp::host {

/// OpenCV's CUDA StereoSGM defaults for its 62-bit census (P1 10, P2 120), scaled to the
/// 24 bits of a 5 x 5 census: the same penalties relative to a full mismatch.
inline constexpr int kDefaultGuidedP1 = 6;
inline constexpr int kDefaultGuidedP2 = 77;

struct GuidedStereoConfig {
  int p1 = kDefaultGuidedP1;
  int p2 = kDefaultGuidedP2;
  void validate() const;  ///< throws std::invalid_argument naming the field
};

/// What one band pass needs besides the images: the searched range and SGBM's rules.
struct GuidedBandRules {
  int min_disparity_px = 0;
  int max_disparity_px = 0;  ///< inclusive
  int uniqueness_ratio = 10;
  int disp12_max_diff = 1;  ///< < 0: no left-right check
  int speckle_window_size = 100;
  int speckle_range = 2;
};

/// Keeps its device buffers from one compute() to the next, reallocated when a band needs
/// more (a GPU allocation costs ~0.8 ms, and a view's pass needs eight buffers of ~40 MB in
/// all): one object per stream of views, not thread-safe.
class GuidedStereo {
 public:
  GuidedStereo(accel::Backend& backend, GuidedStereoConfig config = {});
  ~GuidedStereo();
  GuidedStereo(const GuidedStereo&) = delete;
  GuidedStereo& operator=(const GuidedStereo&) = delete;

  /// left_grey / right_grey: rectified CV_8UC1 images of equal size; band: the left
  /// pixels to match (inside the image); guide_px: CV_32F disparities of the pair reduced
  /// `guide_scale` times (> 0 where found), guide pixel (u, v) covering full pixels
  /// [u * scale, (u + 1) * scale). Returns the band's CV_32S disparities * 16, or
  /// FVP_STEREO_INVALID (uniqueness, left-right check, speckle), FVP_STEREO_OUTSIDE (the
  /// match lies outside the pixel's windows), FVP_STEREO_UNGUIDED (no guide near).
  cv::Mat compute(const cv::Mat& left_grey, const cv::Mat& right_grey, cv::Rect band,
                  const cv::Mat& guide_px, int guide_scale, const GuidedBandRules& rules);

  /// compute()'s output in SGBM's CV_16S fixed point: every code below 0 becomes SGBM's
  /// invalid value, (min_disparity_px - 1) * 16.
  static cv::Mat sgbmFixedPoint(const cv::Mat& found, int min_disparity_px);

 private:
  /// buffers_[slot], at least size_bytes (reallocated, contents lost, when smaller).
  accel::DeviceBuffer& buffer(int slot, std::size_t size_bytes);

  accel::Backend& backend_;
  GuidedStereoConfig config_;
  std::unique_ptr<accel::DeviceBuffer> buffers_[8];
};

}  // namespace fvp::host
