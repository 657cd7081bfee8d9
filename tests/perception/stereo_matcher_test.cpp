#include "fvp/host/perception/stereo_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>

#include "synthetic_scenes.h"

namespace fvp::host {
namespace {

constexpr double kDepthM = 0.3;

StereoIntrinsics smallCamera() {
  StereoIntrinsics K;  // full focal length and baseline, narrower image: quicker tests
  K.width_px = 960;
  K.height_px = 240;
  K.cx_px = 0.5 * (K.width_px - 1);
  K.cy_px = 0.5 * (K.height_px - 1);
  return K;
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST(StereoMatcher, DefaultsAreTheReferenceConfiguration) {
  const SgbmConfig c;
  EXPECT_EQ(c.num_disparities, 320);
  EXPECT_EQ(c.block_size, 3);
  EXPECT_EQ(c.p1, 216);
  EXPECT_EQ(c.p2, 864);
  EXPECT_EQ(c.disp12_max_diff, 1);
  EXPECT_EQ(c.pre_filter_cap, 63);
  EXPECT_EQ(c.uniqueness_ratio, 10);
  EXPECT_EQ(c.speckle_window_size, 100);
  EXPECT_EQ(c.speckle_range, 2);
  EXPECT_EQ(c.mode, cv::StereoSGBM::MODE_SGBM);
  const SgbmConfig half = c.scaled(2);
  EXPECT_EQ(half.num_disparities, 160);
  EXPECT_EQ(half.speckle_window_size, 25);
  SgbmConfig bad;
  bad.num_disparities = 100;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

// A dark band (black sky: sensor noise only, 2 grey levels) above a textured scene. SGBM
// alone fills it with disparities from its neighbours; the matcher keeps none of them and
// counts them, and keeps the lit scene's.
TEST(StereoMatcher, DarkWindowsGetNoDisparity) {
  const StereoIntrinsics K = smallCamera();
  auto pair = test::makeStereoPair(K, K.fx_px * K.baseline_m / 0.5, {}, 2.0, 11);
  const int dark_rows = 80;
  cv::RNG rng(3);
  for (cv::Mat* image : {&pair.left, &pair.right}) {
    cv::Mat band = (*image)(cv::Rect(0, 0, K.width_px, dark_rows));
    rng.fill(band, cv::RNG::NORMAL, 2.0, 2.0);  // black plus the noise, clipped at 0
  }
  const auto validIn = [&](const cv::Mat& d, int v0, int v1) {
    int n = 0;
    for (int v = v0; v < v1; ++v)
      for (int u = 400; u < K.width_px; ++u) n += d.at<float>(v, u) > 0.0f;
    return n;
  };
  StereoMatcherConfig blind_to_dark;
  blind_to_dark.sgbm.min_signal = 0;
  const DisparityResult guessed =
      StereoMatcher(blind_to_dark).compute(pair.left, pair.right, cv::Rect());
  const DisparityResult r = StereoMatcher().compute(pair.left, pair.right, cv::Rect());
  // Rows clear of the band's edge by the coarse window (3 coarse px = 6 full-resolution px).
  std::cout << "dark band: " << validIn(guessed.disparity_px, 0, dark_rows - 8)
            << " disparities without the guard, " << validIn(r.disparity_px, 0, dark_rows - 8)
            << " with it; no_signal " << r.stats.no_signal << "\n";
  EXPECT_GT(validIn(guessed.disparity_px, 0, dark_rows - 8), 1000);
  EXPECT_EQ(validIn(r.disparity_px, 0, dark_rows - 8), 0);
  EXPECT_GT(r.stats.no_signal, 0);
  // The lit part keeps what it had.
  EXPECT_EQ(validIn(r.disparity_px, dark_rows + 8, K.height_px),
            validIn(guessed.disparity_px, dark_rows + 8, K.height_px));
  SgbmConfig bad;
  bad.min_signal = 256;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

// A textured patch at 0.3 m over a background at 0.5 m: the fine band recovers its depth.
TEST(StereoMatcher, FineBandDepthErrorAtPointThreeMetres) {
  const StereoIntrinsics K = smallCamera();
  const double d_true = K.fx_px * K.baseline_m / kDepthM;  // 183.33 px
  const cv::Rect patch(500, 60, 200, 120);
  const auto pair =
      test::makeStereoPair(K, K.fx_px * K.baseline_m / 0.5, {{patch, d_true}}, 2.0, 7);
  StereoMatcher matcher;
  const DisparityResult r = matcher.compute(pair.left, pair.right, patch);
  EXPECT_EQ(r.fine_rect, patch);
  EXPECT_EQ(r.coarse_scale, 2);
  std::vector<double> depth_err_m;
  const cv::Rect inner(patch.x + 4, patch.y + 4, patch.width - 8, patch.height - 8);
  for (int v = inner.y; v < inner.br().y; ++v)
    for (int u = inner.x; u < inner.br().x; ++u) {
      const float d = r.disparity_px.at<float>(v, u);
      if (d > 0) depth_err_m.push_back(std::abs(K.depthFromDisparity(d) - kDepthM));
    }
  ASSERT_GT(depth_err_m.size(), inner.area() * 0.95);
  const double med_mm = median(depth_err_m) * 1e3;
  std::cout << "[ measured ] synthetic plane at 0.3 m: median |depth error| " << med_mm
            << " mm over " << depth_err_m.size() << " px, SGBM " << r.stats.sgbm_s * 1e3 << " ms\n";
  EXPECT_LE(med_mm, 1.0);
}

// The left-most numDisparities columns have no match: invalid (0) and counted as blind.
TEST(StereoMatcher, BlindLeftBandIsInvalidAndCounted) {
  const StereoIntrinsics K = smallCamera();
  const auto pair = test::makeStereoPair(K, 100.0, {}, 2.0, 11);
  StereoMatcherConfig config;
  config.coarse_scale = 1;  // everything at full resolution
  const DisparityResult r = StereoMatcher(config).compute(pair.left, pair.right, {});
  EXPECT_EQ(r.stats.fine_samples, static_cast<std::int64_t>(K.width_px) * K.height_px);
  EXPECT_EQ(cv::countNonZero(r.disparity_px.colRange(0, 320)), 0);
  EXPECT_EQ(r.stats.blind_band, 320LL * K.height_px);
  // Elsewhere the background's 100 px is found nearly everywhere.
  const cv::Mat rest = r.disparity_px.colRange(330, K.width_px);
  EXPECT_GT(cv::countNonZero(cv::abs(rest - 100.0) < 0.5), rest.total() * 0.95);
}

// Objects at or beyond the top of the search range (nearer than ~0.17 m) come out at
// 318-319 px instead of invalid (docs/design.md section 10): they are rejected and counted.
TEST(StereoMatcher, SaturatedDisparitiesAreRejected) {
  const StereoIntrinsics K = smallCamera();
  const cv::Rect near_patch(600, 50, 200, 140);
  StereoMatcherConfig config;
  config.coarse_scale = 1;
  SgbmConfig raw = config.sgbm;
  raw.saturation_margin_px = 0;
  for (double d : {319.0, 340.0}) {
    const auto pair = test::makeStereoPair(K, 100.0, {{near_patch, d}}, 2.0, 13);
    const DisparityResult r = StereoMatcher(config).compute(pair.left, pair.right, {});
    double max_d = 0;
    cv::minMaxLoc(r.disparity_px, nullptr, &max_d);
    EXPECT_LT(max_d, 318.0) << "patch at " << d << " px";
    PerceptionStats raw_stats;
    const cv::Mat unrejected = StereoMatcher::runSgbm(pair.left, pair.right, raw, &raw_stats);
    const long at_top = cv::countNonZero(unrejected(near_patch) >= 318.0);
    std::cout << "[ measured ] patch at " << d << " px: " << at_top << " of " << near_patch.area()
              << " px at >= 318 px without rejection; rejected as saturated " << r.stats.saturated
              << ", SGBM-invalid " << r.stats.sgbm_invalid << "\n";
    EXPECT_EQ(raw_stats.saturated, 0);
    if (d == 319.0) {
      EXPECT_GT(at_top, near_patch.area() / 2);
      EXPECT_GE(r.stats.saturated, at_top);
    }
  }
}

// The band + coarse assembly: full resolution inside the band (identical to a whole-image
// pass up to strip-boundary effects), coarse samples elsewhere within a pixel of the truth.
TEST(StereoMatcher, BandAndCoarsePassesMatchTheFullPass) {
  const StereoIntrinsics K = smallCamera();
  const cv::Rect patch(520, 40, 220, 150);
  const auto pair = test::makeStereoPair(K, 90.0, {{patch, 183.3}}, 2.0, 17);
  StereoMatcherConfig full_cfg;
  full_cfg.coarse_scale = 1;
  full_cfg.threads = 1;
  const DisparityResult full = StereoMatcher(full_cfg).compute(pair.left, pair.right, {});
  StereoMatcherConfig band_cfg;
  band_cfg.threads = 2;
  const DisparityResult band = StereoMatcher(band_cfg).compute(pair.left, pair.right, patch);
  const cv::Mat a = full.disparity_px(patch), b = band.disparity_px(patch);
  const long both = cv::countNonZero((a > 0) & (b > 0));
  const long close = cv::countNonZero((a > 0) & (b > 0) & (cv::abs(a - b) <= 0.25));
  EXPECT_GT(both, patch.area() * 0.9);
  EXPECT_GT(close, both * 0.97);
  // Coarse samples outside the band: background 90 px.
  long coarse_ok = 0, coarse_valid = 0;
  for (int v = 0; v < K.height_px; v += 2)
    for (int u = 340; u < K.width_px; u += 2) {
      if (patch.contains({u, v})) continue;
      const float d = band.disparity_px.at<float>(v, u);
      if (d > 0) {
        ++coarse_valid;
        coarse_ok += std::abs(d - pair.disparity_px.at<float>(v, u)) <= 1.0;
      }
    }
  EXPECT_GT(coarse_ok, coarse_valid * 0.9);
  EXPECT_GT(band.stats.coarse_samples, 0);
  EXPECT_EQ(band.stats.fine_samples, patch.area());
  std::cout << "[ measured ] " << K.width_px << "x" << K.height_px << ": full pass (1 thread) "
            << full.stats.sgbm_s * 1e3 << " ms, band + half-res coarse (2 threads) "
            << band.stats.sgbm_s * 1e3 << " ms\n";
}

// The fine pass searched over a window of disparities (a Cluster Region's depth span): inside
// the window the same disparities as the whole range, and what lies outside it (a leaf in
// front, the background behind) keeps the coarse pass's value instead of a wrong fine one.
TEST(StereoMatcher, WindowedBandMatchesTheFullRangeAndKeepsWhatLiesOutside) {
  const StereoIntrinsics K = smallCamera();
  const cv::Rect band(480, 30, 300, 180);
  const cv::Rect fruit(500, 40, 220, 150), leaf(700, 60, 70, 100);
  // The leaf is listed with the larger disparity, so it covers the fruit where they overlap.
  const auto pair = test::makeStereoPair(K, 90.0, {{fruit, 183.3}, {leaf, 262.0}}, 2.0, 29);
  const DisparityResult full = StereoMatcher().compute(pair.left, pair.right, band);
  const DisparityWindow window{170, 200};
  const DisparityResult windowed = StereoMatcher().compute(pair.left, pair.right, band, window);
  EXPECT_EQ(windowed.stats.fine_samples, band.area());
  EXPECT_GT(windowed.stats.window_from_coarse, 0);
  EXPECT_GT(windowed.stats.outside_window, 0);  // both ends of the window cut the range
  EXPECT_EQ(full.stats.outside_window + full.stats.window_from_coarse, 0);

  // The fruit away from its edges and from where the leaf hides it in the right image (left
  // columns 438 + 183 .. 508 + 183): the same as the whole range.
  const cv::Rect fruit_inner(fruit.x + 6, fruit.y + 6, 110, fruit.height - 12);
  const cv::Mat a = full.disparity_px(fruit_inner), b = windowed.disparity_px(fruit_inner);
  const long both = cv::countNonZero((a > 0) & (b > 0));
  EXPECT_GT(both, fruit_inner.area() * 0.95);
  EXPECT_GT(cv::countNonZero((a > 0) & (b > 0) & (cv::abs(a - b) <= 0.25)), both * 0.97);

  // Outside the window: the leaf (in front) and the background (behind) inside the band are
  // within the coarse pass's precision of the truth, and nothing of them lands in the window.
  for (const cv::Rect& outside : {cv::Rect(leaf.x + 6, leaf.y + 6, leaf.width - 12, 88),
                                  cv::Rect(band.x + 4, fruit.br().y + 4, band.width - 8, 12)}) {
    const cv::Mat d = windowed.disparity_px(outside);
    const cv::Mat truth = pair.disparity_px(outside);
    const long valid = cv::countNonZero(d > 0);
    const long close = cv::countNonZero((d > 0) & (cv::abs(d - truth) <= 2.0));
    const long in_window = cv::countNonZero((d >= window.min_px) & (d <= window.max_px));
    std::cout << "[ measured ] outside the window at " << truth.at<float>(0, 0) << " px: " << valid
              << " of " << outside.area() << " valid, " << close << " within 2 px, " << in_window
              << " in the window\n";
    EXPECT_GT(valid, outside.area() * 0.8);
    EXPECT_GT(close, valid * 0.95);
    EXPECT_EQ(in_window, 0);
  }
  std::cout << "[ measured ] band " << band.width << "x" << band.height << ": whole range "
            << full.stats.sgbm_s * 1e3 << " ms, window of " << window.max_px - window.min_px + 1
            << " px " << windowed.stats.sgbm_s * 1e3 << " ms (both with the coarse pass)\n";
}

// A window as wide as the range, or one on an image with no coarse pass, searches the whole
// range: the result is the plain band's, bit for bit.
TEST(StereoMatcher, WindowAsWideAsTheRangeChangesNothing) {
  const StereoIntrinsics K = smallCamera();
  const cv::Rect band(520, 40, 220, 150);
  const auto pair = test::makeStereoPair(K, 90.0, {{band, 183.3}}, 2.0, 31);
  const cv::Mat plain = StereoMatcher().compute(pair.left, pair.right, band).disparity_px;
  const cv::Mat wide =
      StereoMatcher().compute(pair.left, pair.right, band, DisparityWindow{-5, 400}).disparity_px;
  EXPECT_EQ(cv::countNonZero(plain != wide), 0);
  StereoMatcherConfig one_pass;
  one_pass.coarse_scale = 1;
  const cv::Mat a = StereoMatcher(one_pass).compute(pair.left, pair.right, {}).disparity_px;
  const cv::Mat b = StereoMatcher(one_pass)
                        .compute(pair.left, pair.right, {}, DisparityWindow{170, 200})
                        .disparity_px;
  EXPECT_EQ(cv::countNonZero(a != b), 0);
}

// A band near the image's left edge: the right image cannot be shifted by the whole window
// start. The window's search (170..201) reaches columns from 170 + 32 on (the whole range's
// only from 320): there, where the coarse pass is blind, the fine values stand.
TEST(StereoMatcher, WindowedBandNearTheLeftEdge) {
  const StereoIntrinsics K = smallCamera();
  const cv::Rect band(150, 40, 250, 150);
  const auto pair = test::makeStereoPair(K, 90.0, {{band, 183.3}}, 2.0, 37);
  const DisparityResult r =
      StereoMatcher().compute(pair.left, pair.right, band, DisparityWindow{170, 200});
  const cv::Mat matched = r.disparity_px(cv::Rect(210, 50, 180, 130));
  EXPECT_GT(cv::countNonZero(cv::abs(matched - 183.3) <= 0.5), matched.total() * 0.95);
  EXPECT_EQ(cv::countNonZero(r.disparity_px(cv::Rect(150, 40, 40, 150))), 0);
  EXPECT_GT(r.stats.blind_band, 0);
}

// A trial must be reproducible on any machine: the disparities may not depend on how many
// cores split the work.
TEST(StereoMatcher, DisparityIsTheSameForEveryThreadCount) {
  const StereoIntrinsics K = smallCamera();
  const cv::Rect patch(520, 40, 220, 150);
  const auto pair = test::makeStereoPair(K, 90.0, {{patch, 183.3}}, 2.0, 23);
  cv::Mat reference;
  for (int threads : {1, 2, 3, 8}) {
    StereoMatcherConfig cfg;
    cfg.threads = threads;
    const cv::Mat d = StereoMatcher(cfg).compute(pair.left, pair.right, patch).disparity_px;
    if (reference.empty()) {
      reference = d;
      continue;
    }
    EXPECT_EQ(cv::countNonZero(d != reference), 0) << threads << " threads";
  }
}

// The guided kernels' fine pass (guided_fine) on the same synthetic plane: its depth as
// well as SGBM's, every band sample counted once, and the same result for every thread
// count (the kernels' work split does not change their output).
TEST(StereoMatcher, GuidedFinePassRecoversThePlaneAsSgbmDoes) {
  const StereoIntrinsics K = smallCamera();
  const double d_true = K.fx_px * K.baseline_m / kDepthM;
  const cv::Rect patch(500, 60, 200, 120);
  const auto pair =
      test::makeStereoPair(K, K.fx_px * K.baseline_m / 0.5, {{patch, d_true}}, 2.0, 7);
  const cv::Rect inner(patch.x + 4, patch.y + 4, patch.width - 8, patch.height - 8);
  std::vector<double> err_m[2];
  cv::Mat guided_reference;
  for (const int threads : {0, 1}) {
    StereoMatcherConfig config;
    config.threads = threads;
    config.guided_fine = true;
    const DisparityResult r = StereoMatcher(config).compute(pair.left, pair.right, patch);
    EXPECT_EQ(r.stats.fine_samples, patch.area());
    if (threads == 1) {
      EXPECT_EQ(cv::countNonZero(r.disparity_px != guided_reference), 0);
      continue;
    }
    guided_reference = r.disparity_px;
    const DisparityResult sgbm = StereoMatcher().compute(pair.left, pair.right, patch);
    for (const DisparityResult* result : {&sgbm, &r})
      for (int v = inner.y; v < inner.br().y; ++v)
        for (int u = inner.x; u < inner.br().x; ++u)
          if (const float d = result->disparity_px.at<float>(v, u); d > 0)
            err_m[result == &r].push_back(std::abs(K.depthFromDisparity(d) - kDepthM));
  }
  std::cout << "[ measured ] synthetic plane at 0.3 m: median |depth error| SGBM "
            << median(err_m[0]) * 1e3 << " mm over " << err_m[0].size() << " px, guided "
            << median(err_m[1]) * 1e3 << " mm over " << err_m[1].size() << " px\n";
  ASSERT_GT(err_m[1].size(), inner.area() * 0.95);
  EXPECT_LE(median(err_m[1]), median(err_m[0]) + 1e-4);
}

TEST(StereoMatcher, GuidedFinePassNeedsTheCoarsePass) {
  StereoMatcherConfig config;
  config.guided_fine = true;
  config.coarse_pass = false;
  EXPECT_THROW(StereoMatcher{config}, std::invalid_argument);
  config.coarse_pass = true;
  config.coarse_scale = 1;
  EXPECT_THROW(StereoMatcher{config}, std::invalid_argument);
}

TEST(StereoMatcher, RejectsMismatchedImages) {
  cv::Mat a(100, 400, CV_8UC3, cv::Scalar::all(0)), b(100, 300, CV_8UC3, cv::Scalar::all(0));
  EXPECT_THROW(StereoMatcher().compute(a, b, {}), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::host
