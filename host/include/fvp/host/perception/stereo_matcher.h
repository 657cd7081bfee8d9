// Disparity by OpenCV StereoSGBM (docs/design.md §8 reference configuration), computed where it is
// needed: a full-resolution pass over the requested fine rectangle (the Cluster Region's image
// band) and a cheaper reduced-resolution pass for everything else (the coarse map). Both are
// split into a fixed number of overlapping row strips run on all cores (OpenCV's MODE_SGBM is
// single-threaded; a fixed count keeps the result the same on every machine). Pitfalls handled
// (docs/design.md §10): saturated disparities at the top of the search range (objects nearer
// than ~0.17 m) are rejected, and the left band where SGBM has no match is marked invalid; both
// are counted. Given a disparity window (the Cluster Region's depth span), the fine pass searches
// only that window; what the coarse pass places wholly outside it keeps the coarse value.
#pragma once

#include <memory>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <optional>

#include "fvp/host/perception/guided_stereo.h"

#include "fvp/host/core/perception_stats.h"

namespace fvp::host {

inline constexpr int kDefaultNumDisparities = 320;
inline constexpr int kDefaultBlockSize = 3;
inline constexpr int kDefaultP1 = 216;  ///< 8 * channels * block^2 for BGR input
inline constexpr int kDefaultP2 = 864;  ///< 32 * channels * block^2
inline constexpr int kDefaultDisp12MaxDiff = 1;
inline constexpr int kDefaultPreFilterCap = 63;
inline constexpr int kDefaultUniquenessRatio = 10;
inline constexpr int kDefaultSpeckleWindowSize = 100;
inline constexpr int kDefaultSpeckleRange = 2;
inline constexpr int kDefaultSgbmMode = cv::StereoSGBM::MODE_SGBM;
/// Disparities >= num_disparities - margin are saturated (SGBM clamps near objects there).
inline constexpr int kDefaultSaturationMarginPx = 2;
/// The brightest value (any channel, 8-bit) a matching window must exceed to be matched:
/// five sigmas of the sensor's dark noise (2 grey levels) above black. A window darker than
/// that holds nothing the flash lit, and SGBM fills it from its neighbours' disparities:
/// over the black sky above a tree that put points in mid-air 0.2-0.4 m from the camera.
inline constexpr int kDefaultMinSignal = 10;
inline constexpr int kDefaultCoarseScale = 2;  ///< coarse pass at 1/2 resolution
inline constexpr int kDefaultStripOverlapPx =
    24;  ///< rows above and below each strip for SGBM's paths to settle

/// OpenCV StereoSGBM parameters at full resolution.
struct SgbmConfig {
  int min_disparity = 0;
  int num_disparities = kDefaultNumDisparities;  ///< multiple of 16
  int block_size = kDefaultBlockSize;            ///< odd
  int p1 = kDefaultP1;
  int p2 = kDefaultP2;
  int disp12_max_diff = kDefaultDisp12MaxDiff;
  int pre_filter_cap = kDefaultPreFilterCap;
  int uniqueness_ratio = kDefaultUniquenessRatio;
  int speckle_window_size = kDefaultSpeckleWindowSize;
  int speckle_range = kDefaultSpeckleRange;
  int mode = kDefaultSgbmMode;
  int saturation_margin_px = kDefaultSaturationMarginPx;
  int min_signal = kDefaultMinSignal;  ///< 0..255; 0: match dark windows too

  /// The same matcher for images downscaled by `scale`: the disparity range shrinks (rounded
  /// up to a multiple of 16), the speckle window by scale^2.
  SgbmConfig scaled(int scale) const;
  void validate() const;  ///< throws std::invalid_argument naming the field
};

struct StereoMatcherConfig {
  SgbmConfig sgbm;
  int coarse_scale = kDefaultCoarseScale;  ///< 1: the whole image at full resolution
  bool coarse_pass = true;                 ///< false: no disparity outside the fine rect
  int strip_overlap_px = kDefaultStripOverlapPx;
  int threads = 0;  ///< 0: std::thread::hardware_concurrency()
  /// The fine pass by the guided kernels (guided_stereo.h) on the matcher's backend, after
  /// the coarse pass and guided by it, instead of SGBM (the disparity window is then not
  /// used: the guide narrows each pixel's search). Needs the coarse pass.
  bool guided_fine = false;
  GuidedStereoConfig guided;
  void validate() const;
};

/// Full-resolution disparities [min_px, max_px] the fine pass searches (both inclusive),
/// widened to a multiple of 16 (at least 2 * saturation_margin_px + 16) around its centre;
/// max_px < min_px: the whole range.
struct DisparityWindow {
  int min_px = 0;
  int max_px = 0;
};

/// A full-size disparity map assembled from the fine and the coarse pass.
struct DisparityResult {
  /// CV_32F, pixels of the full-resolution left image; 0 = no valid disparity.
  cv::Mat disparity_px;
  /// Where disparity_px comes from the full-resolution pass (possibly empty).
  cv::Rect fine_rect;
  /// Outside fine_rect each coarse pixel is replicated over a coarse_scale^2 block (nearest
  /// upsampling); the block whose top-left is (u, v), u and v multiples of coarse_scale, is
  /// one sample centred at (u + (s-1)/2, v + (s-1)/2).
  int coarse_scale = 1;
  PerceptionStats stats;  ///< disparity-stage counts and sgbm_s
};

class StereoMatcher {
 public:
  /// backend: where guided_fine's kernels run (not owned; null: a cpu backend of the
  /// matcher's own). The matcher keeps device buffers on it, so it must outlive the matcher
  /// and its copies; copies share those buffers and match one at a time.
  explicit StereoMatcher(StereoMatcherConfig config = {}, accel::Backend* backend = nullptr);
  const StereoMatcherConfig& config() const { return config_; }

  /// left/right: rectified CV_8UC3 (or CV_8UC1) images of equal size. fine_rect: the region
  /// wanted at full resolution (clipped to the image; empty: none). With coarse_scale 1 the
  /// whole image is computed at full resolution.
  ///
  /// fine_window: search the fine pass only over these disparities (clipped to the
  /// configured range; nullopt, or no coarse pass: the whole range). The right image is
  /// shifted by the window's start, so the fine strips need only the window's width of
  /// columns on either side. A fine sample at a window edge inside the range is rejected
  /// (outside_window). One that no valid coarse sample within one coarse pixel confirms,
  /// where the coarse pass places the pixel outside the window, takes the coarse value
  /// (window_from_coarse): what lies beyond the window stays in the map, not forced into it.
  DisparityResult compute(const cv::Mat& left, const cv::Mat& right, cv::Rect fine_rect,
                          std::optional<DisparityWindow> fine_window = std::nullopt) const;

  /// One plain SGBM call on a (sub)image pair: CV_32F pixels, 0 where invalid, saturated
  /// or blind (the counts are added to stats when given).
  static cv::Mat runSgbm(const cv::Mat& left, const cv::Mat& right, const SgbmConfig& config,
                         PerceptionStats* stats = nullptr);

 private:
  /// guided_fine's pass with its device buffers kept across views; one compute at a time.
  struct GuidedPass;

  StereoMatcherConfig config_;
  std::shared_ptr<accel::Backend> own_backend_;  ///< when none was given
  accel::Backend* backend_ = nullptr;
  std::shared_ptr<GuidedPass> guided_;  ///< guided_fine only; copies share it
};

}  // namespace fvp::host
