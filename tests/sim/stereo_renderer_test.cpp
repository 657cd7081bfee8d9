#include "fvp/robot/sim/stereo_renderer.h"

#include "fvp/robot/sim/object_ids.h"
#include "fvp/robot/sim/occlusion_statistic.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numeric>
#include <opencv2/imgproc.hpp>

namespace fvp::robot::sim {
namespace {

// Reduced-resolution camera with the real focal length: same pixel scale, fewer pixels.
host::StereoIntrinsics smallIntrinsics(int width, int height) {
  host::StereoIntrinsics in;
  in.width_px = width;
  in.height_px = height;
  in.cx_px = 0.5 * (width - 1);
  in.cy_px = 0.5 * (height - 1);
  return in;
}

Fruitlet sphere(const Eigen::Vector3d& center_m, double radius_m) {
  Fruitlet f;
  f.index = 0;
  f.center_m = center_m;
  f.radius_m = radius_m;
  f.rgb = {0.8, 0.2, 0.05};
  return f;
}

// A camera pose away from the world origin, looking along a tilted direction, so the test
// exercises the world <-> camera transforms.
Eigen::Isometry3d tiltedCamera() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.7, -0.2, 1.1);
  return T;
}

struct SilhouetteStats {
  long predicted_px = 0;
  long rendered_px = 0;
  long mismatched_px = 0;
  double max_mismatch_edge_px = 0.0;  ///< distance of mismatched pixel centres from the edge
  double max_depth_error_m = 0.0;
};

// Compares the ground-truth layers with the exact cone of rays tangent to the sphere.
SilhouetteStats compareSphere(const RenderedView& view, const Eigen::Vector3d& c_camera,
                              double radius_m) {
  SilhouetteStats stats;
  const host::StereoIntrinsics& in = view.frame.intrinsics;
  const double half_angle = std::asin(radius_m / c_camera.norm());
  const Eigen::Vector3d axis = c_camera.normalized();
  for (int v = 0; v < in.height_px; ++v) {
    for (int u = 0; u < in.width_px; ++u) {
      const Eigen::Vector3d ray = in.unproject(u, v, 1.0);
      const double angle = std::acos(std::clamp(ray.normalized().dot(axis), -1.0, 1.0));
      const bool predicted = angle < half_angle;
      const bool rendered = view.ground_truth.object_id.at<std::int32_t>(v, u) == kFirstFruitletId;
      stats.predicted_px += predicted;
      stats.rendered_px += rendered;
      if (predicted != rendered) {
        ++stats.mismatched_px;
        // Angular distance to the edge in pixels (focal length x angle; the sphere is small).
        stats.max_mismatch_edge_px =
            std::max(stats.max_mismatch_edge_px, std::abs(angle - half_angle) * in.fx_px);
      }
      if (rendered) {
        // Exact depth: nearest root of |t * ray - c| = radius, ray has unit z.
        const double a = ray.squaredNorm(), b = -2.0 * ray.dot(c_camera);
        const double c = c_camera.squaredNorm() - radius_m * radius_m;
        const double disc = std::max(0.0, b * b - 4.0 * a * c);
        const double z = (-b - std::sqrt(disc)) / (2.0 * a);
        stats.max_depth_error_m = std::max(stats.max_depth_error_m,
                                           std::abs(view.ground_truth.depth_m.at<float>(v, u) - z));
      }
    }
  }
  return stats;
}

TEST(StereoRenderer, SphereSilhouetteAndDepthAreExact) {
  constexpr double kRadiusM = 0.008;
  const Eigen::Isometry3d T_world_camera = tiltedCamera();
  RenderConfig config;
  config.intrinsics = smallIntrinsics(480, 360);
  config.noise_sigma = 0.0;
  // On the optical axis (a circle) and off axis (an ellipse), at 0.3 m.
  for (const Eigen::Vector3d& c_camera :
       {Eigen::Vector3d(0.0, 0.0, 0.3), Eigen::Vector3d(0.045, -0.03, 0.3)}) {
    const World world =
        World::fromParts({sphere(T_world_camera * c_camera, kRadiusM)}, {}, {}, std::nullopt);
    const StereoRenderer renderer(world, config);
    const RenderedView view = renderer.renderWithGroundTruth(T_world_camera);
    const SilhouetteStats stats = compareSphere(view, c_camera, kRadiusM);
    std::cout << "sphere at " << c_camera.transpose() << ": predicted " << stats.predicted_px
              << " px, rendered " << stats.rendered_px << " px, mismatched " << stats.mismatched_px
              << " (max " << stats.max_mismatch_edge_px << " px from the edge), max depth error "
              << stats.max_depth_error_m * 1e3 << " mm\n";
    EXPECT_GT(stats.predicted_px, 2000);
    EXPECT_LE(stats.max_mismatch_edge_px, 1.0);
    EXPECT_LE(std::abs(stats.rendered_px - stats.predicted_px), 2);
    EXPECT_LT(stats.max_depth_error_m, 1e-4);

    // The shaded image's silhouette (anti-aliased, no noise): pixels with any light, as an
    // equivalent radius, against the exact cone. The Lambertian limb is dark, so allow the
    // edge to lose up to 1 px.
    cv::Mat grey;
    cv::cvtColor(view.frame.left_bgr, grey, cv::COLOR_BGR2GRAY);
    const double lit_px = cv::countNonZero(grey > 0);
    const double radius_px_image = std::sqrt(lit_px / M_PI);
    const double radius_px_exact = std::sqrt(stats.predicted_px / M_PI);
    std::cout << "image silhouette radius " << radius_px_image << " px vs exact " << radius_px_exact
              << " px\n";
    EXPECT_NEAR(radius_px_image, radius_px_exact, 1.0);
  }
}

TEST(StereoRenderer, RightCameraSeesExpectedDisparity) {
  const Eigen::Vector3d c_camera(0.01, 0.0, 0.25);
  const Eigen::Isometry3d T_world_camera = tiltedCamera();
  RenderConfig config;
  config.intrinsics = smallIntrinsics(640, 240);
  config.noise_sigma = 0.0;
  const World world =
      World::fromParts({sphere(T_world_camera * c_camera, 0.006)}, {}, {}, std::nullopt);
  const host::StereoFrame frame = StereoRenderer(world, config).render(T_world_camera);
  const auto centroid_u = [](const cv::Mat& bgr) {
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    const cv::Moments m = cv::moments(grey > 0, true);
    return m.m10 / m.m00;
  };
  const double disparity_px = centroid_u(frame.left_bgr) - centroid_u(frame.right_bgr);
  const double expected_px = config.intrinsics.fx_px * config.intrinsics.baseline_m / c_camera.z();
  EXPECT_NEAR(disparity_px, expected_px, 1.0);
}

TEST(StereoRenderer, DeterministicAcrossThreadCountsAndNoiseDiffersPerView) {
  const World world = World::generate(WorldConfig{}, 11);
  RenderConfig config;
  config.intrinsics = smallIntrinsics(240, 180);
  config.intrinsics.fx_px = config.intrinsics.fy_px = 300.0;
  config.threads = 1;
  const RenderedView one_view =
      StereoRenderer(world, config).renderWithGroundTruth(world.startCameraPose());
  const host::StereoFrame& one = one_view.frame;
  config.threads = 2;
  const StereoRenderer renderer(world, config);
  const RenderedView two_view = renderer.renderWithGroundTruth(world.startCameraPose());
  const host::StereoFrame& two = two_view.frame;
  EXPECT_EQ(cv::norm(one.left_bgr, two.left_bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(one.right_bgr, two.right_bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(one_view.ground_truth.depth_m, two_view.ground_truth.depth_m, cv::NORM_INF),
            0.0);
  Eigen::Isometry3d moved = world.startCameraPose();
  moved.translation().x() += 1e-9;
  const host::StereoFrame other = renderer.render(moved);
  EXPECT_GT(cv::norm(one.left_bgr, other.left_bgr, cv::NORM_L1), 0.0);
}

// Adaptive anti-aliasing against supersampling every pixel, both measured against a 16-sample
// reference of a generated world's start view: it must be as close to the reference as
// uniform 4-sample supersampling (it shades fewer rays, not a different picture).
TEST(StereoRenderer, AdaptiveAntialiasingMatchesFullSupersampling) {
  const World world = World::generate(WorldConfig{}, 3);
  RenderConfig config;
  config.intrinsics = smallIntrinsics(720, 540);
  config.intrinsics.fx_px = config.intrinsics.fy_px = 550.0;
  config.noise_sigma = 0.0;
  const auto renderWith = [&](int spp, bool adaptive, double* seconds) {
    config.samples_per_pixel = spp;
    config.adaptive_antialiasing = adaptive;
    const StereoRenderer renderer(world, config);
    const RenderedView view = renderer.renderWithGroundTruth(world.startCameraPose());
    if (seconds != nullptr) *seconds = renderer.lastRenderSeconds();
    return view;
  };
  double full_s = 0.0, adaptive_s = 0.0;
  const RenderedView reference = renderWith(16, false, nullptr);
  const RenderedView full = renderWith(4, false, &full_s);
  const RenderedView adaptive = renderWith(4, true, &adaptive_s);
  const auto meanAbs = [](const cv::Mat& a, const cv::Mat& b) {
    return cv::norm(a, b, cv::NORM_L1) / static_cast<double>(a.total() * a.channels());
  };
  for (const bool left : {true, false}) {
    const cv::Mat& ref = left ? reference.frame.left_bgr : reference.frame.right_bgr;
    const double full_error = meanAbs(left ? full.frame.left_bgr : full.frame.right_bgr, ref);
    const double adaptive_error =
        meanAbs(left ? adaptive.frame.left_bgr : adaptive.frame.right_bgr, ref);
    std::cout << (left ? "left" : "right") << ": mean |error| vs 16 spp: full 4 spp " << full_error
              << ", adaptive " << adaptive_error << " grey levels\n";
    EXPECT_LT(adaptive_error, 1.5 * full_error + 0.05);
  }
  std::cout << "render time: full 4 spp " << full_s << " s, adaptive " << adaptive_s << " s\n";
  // The ground truth does not depend on the shading.
  EXPECT_EQ(cv::norm(full.ground_truth.depth_m, adaptive.ground_truth.depth_m, cv::NORM_INF), 0.0);
}

TEST(StereoRenderer, FlashExposureNotSaturatedAt20cmAndBrightAt40cm) {
  RenderConfig config;
  config.intrinsics = smallIntrinsics(160, 120);
  config.noise_sigma = 0.0;
  for (const double distance_m : {0.2, 0.4}) {
    // The brightest palette colour (orange, sRGB red channel 1.0) facing the camera.
    Fruitlet f = sphere({0.0, 0.0, distance_m}, 0.008);
    f.rgb = {1.0, 0.214, 0.0};
    const World world = World::fromParts({f}, {}, {}, std::nullopt);
    const host::StereoFrame frame =
        StereoRenderer(world, config).render(Eigen::Isometry3d::Identity());
    std::vector<cv::Mat> channels;
    cv::split(frame.left_bgr, channels);
    double max_red = 0.0;
    cv::minMaxLoc(channels[2], nullptr, &max_red);
    const int c = 60, r = 80;  // image centre: the sphere's nearest point
    const cv::Mat centre = channels[2](cv::Rect(r - 2, c - 2, 5, 5));
    const double centre_red = cv::mean(centre)[0];
    std::cout << distance_m << " m: max red " << max_red << ", centre red " << centre_red << "\n";
    EXPECT_LT(max_red, 255.0);
    EXPECT_GT(centre_red, distance_m < 0.3 ? 180.0 : 90.0);
  }
}

TEST(StereoRenderer, IdsCoverEveryObjectKindInAGeneratedWorld) {
  const World world = World::generate(WorldConfig{}, 2);
  RenderConfig config;
  config.intrinsics = smallIntrinsics(360, 270);
  config.intrinsics.fx_px = config.intrinsics.fy_px = 275.0;  // 1/4 resolution, same view
  const StereoRenderer renderer(world, config);
  RenderOptions options;
  options.images = false;
  const RenderedView frame_view = renderer.renderWithGroundTruth(world.startCameraPose(), options);
  EXPECT_TRUE(frame_view.frame.left_bgr.empty());
  bool fruitlet = false, leaf = false, tag = false;
  for (int v = 0; v < frame_view.ground_truth.object_id.rows; ++v) {
    for (int u = 0; u < frame_view.ground_truth.object_id.cols; ++u) {
      const int id = frame_view.ground_truth.object_id.at<std::int32_t>(v, u);
      fruitlet |= isFruitletId(id);
      leaf |= id >= kFirstLeafId && id < kTreeId;
      tag |= id == kTagId;
      const float depth = frame_view.ground_truth.depth_m.at<float>(v, u);
      EXPECT_EQ(id == kBackgroundId, depth == 0.0f);
    }
  }
  EXPECT_TRUE(fruitlet);
  EXPECT_TRUE(leaf);
  EXPECT_TRUE(tag);
}

// Full resolution, default settings: the number to report (render time per pair) and the
// start view's leaf occlusion over a few seeds.
TEST(StereoRenderer, FullResolutionStartViewTimingAndOcclusion) {
  const World world = World::generate(WorldConfig{}, 1);
  const StereoRenderer renderer(world);
  const host::StereoFrame frame = renderer.render(world.startCameraPose());
  const double seconds = renderer.lastRenderSeconds();
  std::cout << "full-resolution pair + ground truth: " << seconds << " s ("
            << renderer.config().samples_per_pixel << " spp)\n";
  RecordProperty("render_seconds_per_pair", std::to_string(seconds));
  EXPECT_EQ(frame.left_bgr.cols, host::kDefaultImageWidthPx);
  EXPECT_EQ(frame.left_bgr.rows, host::kDefaultImageHeightPx);
  EXPECT_GT(seconds, 0.0);

  double fraction_sum = 0.0;
  int fruitlets = 0;
  for (std::uint64_t seed = 0; seed < 8; ++seed) {
    const World w = World::generate(WorldConfig{}, seed);
    RenderConfig config;
    config.intrinsics = smallIntrinsics(720, 540);
    config.intrinsics.fx_px = config.intrinsics.fy_px = 550.0;
    const StereoRenderer renderer(w, config);
    RenderOptions ids;
    ids.images = false;
    const cv::Mat with_leaves =
        renderer.renderWithGroundTruth(w.startCameraPose(), ids).ground_truth.object_id;
    ids.with_leaves = false;
    const cv::Mat without_leaves =
        renderer.renderWithGroundTruth(w.startCameraPose(), ids).ground_truth.object_id;
    const auto stat = OcclusionStatistic::compute(with_leaves, without_leaves);
    fraction_sum += stat.meanVisibleFraction() * stat.fruitletsInView();
    fruitlets += stat.fruitletsInView();
  }
  ASSERT_GT(fruitlets, 0);
  std::cout << "mean visible fraction of fruitlets in the start view (8 seeds): "
            << fraction_sum / fruitlets << "\n";
}

}  // namespace
}  // namespace fvp::robot::sim
