// The guided stereo kernels (kernels/fvp_stereo.h) on every backend: a textured pair with
// a depth edge and known integer disparities, guided by a reduced map that is up to a
// guide pixel off; every backend's disparities equal the cpu reference's.
#include "fvp/host/perception/guided_stereo.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <random>

#include "backend_fixture.h"

namespace fvp::host {
namespace {

using GuidedStereoBackends = fvp::testing::BackendFixture;

constexpr int kWidth = 400, kHeight = 120;
constexpr int kFar = 60, kNear = 90;         // disparities of the two planes
const cv::Rect kNearRect(200, 30, 120, 60);  // the near plane, in the left image

// A pair whose left pixel (x, y) lies at disparity truth(x, y): the near plane occludes
// the far one in the right image. Texture: blurred uniform noise (a seeded generator).
struct Pair {
  cv::Mat left, right;
  cv::Mat truth;  ///< CV_32S disparity of each left pixel
};

Pair texturedPair(std::uint32_t seed) {
  const int source_width = kWidth + kNear;
  cv::Mat far(kHeight, source_width, CV_8U), near(kHeight, source_width, CV_8U);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> grey(0, 255);
  for (cv::Mat* m : {&far, &near})
    for (int v = 0; v < m->rows; ++v)
      for (int u = 0; u < m->cols; ++u) m->at<std::uint8_t>(v, u) = std::uint8_t(grey(rng));
  cv::GaussianBlur(far, far, cv::Size(3, 3), 0.8);
  cv::GaussianBlur(near, near, cv::Size(3, 3), 0.8);
  Pair p{cv::Mat(kHeight, kWidth, CV_8U), cv::Mat(kHeight, kWidth, CV_8U),
         cv::Mat(kHeight, kWidth, CV_32S)};
  // Left column u shows surface point u of its plane; right column x shows the surface
  // point x + d of the near plane where that lands in the near rectangle, else of the far.
  for (int v = 0; v < kHeight; ++v)
    for (int u = 0; u < kWidth; ++u) {
      const bool near_left = kNearRect.contains(cv::Point(u, v));
      p.left.at<std::uint8_t>(v, u) = (near_left ? near : far).at<std::uint8_t>(v, u);
      p.truth.at<int>(v, u) = near_left ? kNear : kFar;
      const bool near_right = kNearRect.contains(cv::Point(u + kNear, v));
      p.right.at<std::uint8_t>(v, u) =
          near_right ? near.at<std::uint8_t>(v, u + kNear) : far.at<std::uint8_t>(v, u + kFar);
    }
  return p;
}

// The reduced map (scale 2) of the truth, off by `offset_px` of its own pixels.
cv::Mat guideOf(const cv::Mat& truth, float offset_px) {
  cv::Mat guide(truth.rows / 2, truth.cols / 2, CV_32F);
  for (int v = 0; v < guide.rows; ++v)
    for (int u = 0; u < guide.cols; ++u)
      guide.at<float>(v, u) = truth.at<int>(2 * v, 2 * u) / 2.0f + offset_px;
  return guide;
}

GuidedBandRules rules() {
  GuidedBandRules r;
  r.min_disparity_px = 0;
  r.max_disparity_px = 159;
  return r;
}

const cv::Rect kBand(120, 10, 260, 100);

// Pixels of the band the right camera sees (not occluded by the near plane), and of them
// how many come out within half a pixel of the truth (the subpixel fit is not exact), and how
// many wrong by more than 1.
struct Score {
  int visible = 0, matched = 0, close = 0, wrong = 0;
};
Score score(const Pair& pair, const cv::Mat& found) {
  Score s;
  for (int v = 0; v < kBand.height; ++v)
    for (int u = 0; u < kBand.width; ++u) {
      const int x = kBand.x + u, y = kBand.y + v;
      const int d = pair.truth.at<int>(y, x);
      // Far pixels whose right-image point the near plane covers are occluded.
      if (d == kFar && kNearRect.contains(cv::Point(x - kFar + kNear, y))) continue;
      ++s.visible;
      const int got = found.at<int>(v, u);
      if (got < 0) continue;
      ++s.matched;
      s.close += std::abs(got - 16 * d) <= 8;
      s.wrong += std::abs(got - 16 * d) > 16;
    }
  return s;
}

TEST_P(GuidedStereoBackends, FindsBothPlanesOfADepthEdgeAndEqualsTheCpuReference) {
  const Pair pair = texturedPair(7);
  for (const float offset : {0.0f, -1.0f, 1.0f}) {
    const cv::Mat guide = guideOf(pair.truth, offset);
    const cv::Mat found =
        GuidedStereo(*backend_).compute(pair.left, pair.right, kBand, guide, 2, rules());
    const cv::Mat reference =
        GuidedStereo(*cpu_).compute(pair.left, pair.right, kBand, guide, 2, rules());
    ASSERT_EQ(found.size(), kBand.size());
    EXPECT_EQ(cv::countNonZero(found != reference), 0) << "guide offset " << offset;
    const Score s = score(pair, found);
    std::cout << "[ measured ] guide off by " << offset << " px: " << s.matched << " of "
              << s.visible << " visible pixels matched, " << s.close << " within 1/2 px, "
              << s.wrong << " off by > 1 px\n";
    // The census window straddles the edge on 2 px each side of it: those may go either way.
    EXPECT_GE(s.matched, s.visible * 98 / 100) << "guide offset " << offset;
    EXPECT_GE(s.close, s.visible * 95 / 100) << "guide offset " << offset;
    EXPECT_LE(s.wrong, s.visible / 100) << "guide offset " << offset;
  }
}

TEST_P(GuidedStereoBackends, PixelsWithoutAGuideOrBeyondItAreNotMatched) {
  const Pair pair = texturedPair(11);
  cv::Mat guide = guideOf(pair.truth, 0.0f);
  guide(cv::Rect(0, 0, guide.cols, 20)).setTo(0.0f);  // rows 0-39: no guide
  // Rows 80-119: a guide 4 full pixels too near: the truth lies one disparity below both
  // windows, so the search runs into a window's end. (A guide wrong by many pixels gives
  // noise to choose from, as any search over the wrong disparities would: the coarse pass's
  // own uniqueness and left-right checks keep such guides out.)
  guide(cv::Rect(0, 40, guide.cols, 20)) += 2.0f;
  const cv::Mat found =
      GuidedStereo(*backend_).compute(pair.left, pair.right, kBand, guide, 2, rules());
  int unguided = 0, outside_or_invalid = 0, matched_beyond = 0;
  for (int v = 0; v < kBand.height; ++v)
    for (int u = 0; u < kBand.width; ++u) {
      const int y = kBand.y + v, got = found.at<int>(v, u);
      // Rows 0-33 see no guide at all: the 7 x 7 guide neighbourhood of rows 34-39 reaches
      // row 40's.
      if (y < 34) unguided += got == FVP_STEREO_UNGUIDED;
      if (y >= 82) {
        outside_or_invalid += got == FVP_STEREO_OUTSIDE || got == FVP_STEREO_INVALID;
        matched_beyond += got >= 0;
      }
    }
  EXPECT_EQ(unguided, (34 - kBand.y) * kBand.width);
  // Beyond the windows the search mostly finds its own edge and rejects the pixel (measured
  // 94 %; the rest come out inside the windows, wrong, as any search of the wrong
  // disparities would).
  const int beyond = (kBand.br().y - 82) * kBand.width;
  EXPECT_GE(outside_or_invalid, beyond * 90 / 100);
  EXPECT_LE(matched_beyond, beyond / 10);
}

// One object over bands of different sizes (its buffers kept and grown between passes)
// gives what a fresh object gives each time.
TEST_P(GuidedStereoBackends, KeptBuffersGiveWhatFreshOnesGive) {
  const Pair pair = texturedPair(13);
  const cv::Mat guide = guideOf(pair.truth, 0.0f);
  GuidedStereo kept(*backend_);
  for (const cv::Rect band : {kBand, cv::Rect(60, 4, 330, 112), cv::Rect(200, 30, 80, 40), kBand}) {
    const cv::Mat again = kept.compute(pair.left, pair.right, band, guide, 2, rules());
    const cv::Mat fresh =
        GuidedStereo(*backend_).compute(pair.left, pair.right, band, guide, 2, rules());
    ASSERT_EQ(again.size(), band.size());
    EXPECT_EQ(cv::countNonZero(again != fresh), 0) << "band " << band;
  }
}

TEST(GuidedStereo, BadInputIsAnErrorNamingTheField) {
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  const Pair pair = texturedPair(3);
  const cv::Mat guide = guideOf(pair.truth, 0.0f);
  GuidedStereo stereo(*cpu);
  EXPECT_THROW(stereo.compute(pair.left, pair.right, cv::Rect(300, 0, 200, 10), guide, 2, rules()),
               std::invalid_argument);
  GuidedBandRules narrow = rules();
  narrow.max_disparity_px = 10;
  EXPECT_THROW(stereo.compute(pair.left, pair.right, kBand, guide, 2, narrow),
               std::invalid_argument);
  EXPECT_THROW(GuidedStereo(*cpu, GuidedStereoConfig{10, 5}), std::invalid_argument);
}

FVP_INSTANTIATE_FOR_ALL_BACKENDS(GuidedStereoBackends);

}  // namespace
}  // namespace fvp::host
