#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <opencv2/imgproc.hpp>

#include "fvp/host/perception/fruitlet_segmenter.h"
#include "fvp/host/perception/stereo_frame.h"
#include "synthetic_scenes.h"

namespace fvp::host {
namespace {

double linearToSrgb(double c) {
  c = std::clamp(c, 0.0, 1.0);
  return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
}
double srgbToLinear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// Flat-shaded discs of the six palette colours over leaves (green), bark (grey-brown), a
// black/white patch and a black background, dimmed by up to 4x (flash falloff 0.2 -> 0.4 m)
// and textured, with sensor noise.
TEST(FruitletSegmenter, SyntheticPaletteDiscsAgainstClutter) {
  const cv::Size size(640, 360);
  cv::Mat linear(size, CV_32FC3, cv::Scalar::all(0.0));
  // Scene colours in sRGB (B, G, R order below).
  const cv::Scalar leaf(0.10, 0.55, 0.25), leaf2(0.25, 0.50, 0.15), bark(0.25, 0.33, 0.42);
  cv::rectangle(linear, cv::Rect(0, 0, 640, 180), leaf, cv::FILLED);
  cv::rectangle(linear, cv::Rect(0, 180, 320, 180), leaf2, cv::FILLED);
  cv::rectangle(linear, cv::Rect(320, 180, 200, 180), bark, cv::FILLED);
  cv::rectangle(linear, cv::Rect(540, 200, 50, 50), cv::Scalar::all(0.95), cv::FILLED);
  cv::rectangle(linear, cv::Rect(555, 215, 20, 20), cv::Scalar::all(0.05), cv::FILLED);
  const std::vector<cv::Scalar> palette_bgr = {{0.06, 0.06, 0.90}, {0.02, 0.50, 1.00},
                                               {0.05, 0.85, 0.95}, {0.90, 0.80, 0.03},
                                               {0.95, 0.30, 0.10}, {0.80, 0.05, 0.88}};
  cv::Mat truth = cv::Mat::zeros(size, CV_8U);
  for (int i = 0; i < 12; ++i) {
    const cv::Point c(60 + (i % 6) * 100, 90 + (i / 6) * 180);
    cv::circle(linear, c, 25 + 3 * (i % 4), palette_bgr[i % 6], cv::FILLED, cv::LINE_8);
    cv::circle(truth, c, 25 + 3 * (i % 4), 255, cv::FILLED, cv::LINE_8);
  }
  // sRGB -> linear, flash falloff (1 .. 1/4) and texture, back to sRGB 8-bit + noise.
  const cv::Mat texture = test::randomTexture(size, 5);
  cv::Mat image(size, CV_8UC3);
  cv::RNG rng(9);
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u) {
      const double falloff = 1.0 / std::pow(1.0 + u / double(size.width), 2.0);
      const cv::Vec3f t = texture.at<cv::Vec3f>(v, u);
      const double tex = 0.7 + 0.3 * (t[0] - 20.0) / 215.0;
      for (int ch = 0; ch < 3; ++ch) {
        const double lin = srgbToLinear(linear.at<cv::Vec3f>(v, u)[ch]) * falloff * tex;
        image.at<cv::Vec3b>(v, u)[ch] =
            cv::saturate_cast<uchar>(255.0 * linearToSrgb(lin) + rng.gaussian(2.0));
      }
    }
  const cv::Mat mask = FruitletSegmenter().segment(image);
  ASSERT_EQ(mask.type(), CV_8U);
  const double inter = cv::countNonZero(mask & truth), uni = cv::countNonZero(mask | truth);
  std::cout << "[ measured ] synthetic palette discs: IoU " << inter / uni << "\n";
  EXPECT_GE(inter / uni, 0.95);
}

TEST(FruitletSegmenter, BadConfigNamesTheField) {
  SegmentationConfig config;
  config.min_saturation = 300;
  try {
    FruitletSegmenter s(config);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("min_saturation"), std::string::npos);
  }
}

}  // namespace
}  // namespace fvp::host
