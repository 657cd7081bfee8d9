// HSV segmentation of fruitlets (paper, "Perception"): any hue of the fruitlet palette counts
// as fruitlet; leaves (green), bark (brown) and the tag (black/white) are rejected by hue or
// saturation. Hue and saturation do not change with the flash's inverse-square falloff, so
// the value threshold only has to reject the dark noise floor: keep it low (docs/design.md §10:
// the flash falls off 4x from 0.2 to 0.4 m).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace fvp::host {

/// An inclusive range of OpenCV 8-bit hue (0..179, i.e. degrees / 2). min_h > max_h wraps
/// through 0 (reds).
struct HueRange {
  int min_h = 0;
  int max_h = 0;
};

// Defaults match the simulator's palette (robot/sim/src/world.cpp kPaletteSrgb: red 0,
// orange 30, yellow 53, cyan 186, blue 226, magenta 305 degrees, saturation >= 0.9) against
// its leaves (hue 95-130 degrees), greyish bark (saturation <= 0.45), black/white tag and
// black background, with margins for anti-aliased edges and sensor noise.
inline constexpr int kDefaultMinSaturation = 140;  ///< 0..255 (0.55): above bark's 0.45
inline constexpr int kDefaultMinValue = 20;        ///< 0..255: above the dark noise floor
inline constexpr int kDefaultOpenKernelPx = 3;     ///< removes isolated noise pixels
inline constexpr int kDefaultCloseKernelPx = 3;    ///< fills single-pixel holes

struct SegmentationConfig {
  std::vector<HueRange> fruitlet_hues = defaultFruitletHues();
  int min_saturation = kDefaultMinSaturation;
  int min_value = kDefaultMinValue;
  int open_kernel_px = kDefaultOpenKernelPx;    ///< 0 or 1: no opening
  int close_kernel_px = kDefaultCloseKernelPx;  ///< 0 or 1: no closing

  static std::vector<HueRange> defaultFruitletHues();
  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
};

class FruitletSegmenter {
 public:
  explicit FruitletSegmenter(SegmentationConfig config = {});
  const SegmentationConfig& config() const { return config_; }

  /// CV_8U mask of the same size as the CV_8UC3 BGR image: 255 fruitlet, 0 otherwise.
  cv::Mat segment(const cv::Mat& image_bgr) const;

 private:
  SegmentationConfig config_;
  cv::Mat hue_lut_;  ///< 1x256 CV_8U: 255 where the hue belongs to a fruitlet range
};

}  // namespace fvp::host
