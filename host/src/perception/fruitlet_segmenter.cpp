#include "fvp/host/perception/fruitlet_segmenter.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace fvp::host {

std::vector<HueRange> SegmentationConfig::defaultFruitletHues() {
  // OpenCV hue = degrees / 2. Reds to yellows: 340..70 deg; cyans to magentas: 170..330
  // deg. The gap 72..168 deg is the leaves' green (95..130 deg) with margins.
  return {{170, 35}, {85, 165}};
}

void SegmentationConfig::validate() const {
  auto fail = [](const std::string& field, const std::string& expected) {
    throw std::invalid_argument("segmentation config: " + field + ": expected " + expected);
  };
  if (fruitlet_hues.empty()) fail("fruitlet_hues", "at least one hue range");
  for (const auto& r : fruitlet_hues)
    if (r.min_h < 0 || r.min_h > 179 || r.max_h < 0 || r.max_h > 179)
      fail("fruitlet_hues", "OpenCV hues in [0, 179], got [" + std::to_string(r.min_h) + ", " +
                                std::to_string(r.max_h) + "]");
  if (min_saturation < 0 || min_saturation > 255) fail("min_saturation", "a value in [0, 255]");
  if (min_value < 0 || min_value > 255) fail("min_value", "a value in [0, 255]");
  if (open_kernel_px < 0 || open_kernel_px > 31) fail("open_kernel_px", "a size in [0, 31]");
  if (close_kernel_px < 0 || close_kernel_px > 31) fail("close_kernel_px", "a size in [0, 31]");
}

FruitletSegmenter::FruitletSegmenter(SegmentationConfig config) : config_(std::move(config)) {
  config_.validate();
  hue_lut_ = cv::Mat::zeros(1, 256, CV_8U);
  for (const auto& r : config_.fruitlet_hues)
    for (int h = 0; h < 180; ++h) {
      const bool in =
          r.min_h <= r.max_h ? (h >= r.min_h && h <= r.max_h) : (h >= r.min_h || h <= r.max_h);
      if (in) hue_lut_.at<uchar>(h) = 255;
    }
}

cv::Mat FruitletSegmenter::segment(const cv::Mat& image_bgr) const {
  if (image_bgr.empty() || image_bgr.type() != CV_8UC3)
    throw std::invalid_argument("FruitletSegmenter::segment: expected a CV_8UC3 BGR image");
  cv::Mat hsv;
  cv::cvtColor(image_bgr, hsv, cv::COLOR_BGR2HSV);  // 8-bit: H in [0, 180), S, V in [0, 255]
  cv::Mat channels[3];
  cv::split(hsv, channels);
  cv::Mat mask, sv;
  cv::LUT(channels[0], hue_lut_, mask);
  cv::inRange(hsv, cv::Scalar(0, config_.min_saturation, config_.min_value),
              cv::Scalar(255, 255, 255), sv);
  cv::bitwise_and(mask, sv, mask);
  if (config_.open_kernel_px > 1)
    cv::morphologyEx(mask, mask, cv::MORPH_OPEN,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE,
                                               {config_.open_kernel_px, config_.open_kernel_px}));
  if (config_.close_kernel_px > 1)
    cv::morphologyEx(mask, mask, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE,
                                               {config_.close_kernel_px, config_.close_kernel_px}));
  return mask;
}

}  // namespace fvp::host
