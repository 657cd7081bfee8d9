// Ambient light: the sun's direction is drawn per seed within its elevations and off by
// default; daylight brightens the scene and the sky; a leaf over a fruitlet shades it from an
// overhead sun.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "fvp/robot/sim/object_ids.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"
#include "small_intrinsics.h"

namespace fvp::robot::sim {
namespace {

TEST(AmbientLight, OffByDefaultAndTheSunsDirectionIsDrawnPerSeed) {
  EXPECT_EQ(renderConfigFor(WorldConfig{}, {}, 3).sun_irradiance, 0.0);
  WorldConfig c;
  c.sun_strength = 0.5;
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    const RenderConfig r = renderConfigFor(c, {}, seed);
    EXPECT_EQ(r.sun_irradiance, 0.5);
    EXPECT_DOUBLE_EQ(r.sky_irradiance, kSkyToSunRatio * 0.5);
    EXPECT_NEAR(r.sun_direction_world.norm(), 1.0, 1e-12);
    const double elevation_deg = std::asin(r.sun_direction_world.z()) * 180.0 / std::numbers::pi;
    EXPECT_GE(elevation_deg, 20.0 - 1e-9);
    EXPECT_LE(elevation_deg, 70.0 + 1e-9);
    EXPECT_TRUE(r.sun_direction_world.isApprox(renderConfigFor(c, {}, seed).sun_direction_world));
  }
  EXPECT_FALSE(renderConfigFor(c, {}, 1).sun_direction_world.isApprox(
      renderConfigFor(c, {}, 2).sun_direction_world));
}

TEST(AmbientLight, DaylightBrightensTheSceneAndTheSky) {
  const World world = World::generate(WorldConfig{}, 1);
  RenderConfig night;
  night.intrinsics = test::smallIntrinsics(288, 216, 220.0);
  night.noise_sigma = 0.0;
  WorldConfig sunny;
  sunny.sun_strength = 0.5;
  const RenderConfig day = renderConfigFor(sunny, night, 1);
  const RenderedView dark =
      StereoRenderer(world, night).renderWithGroundTruth(world.startCameraPose());
  const RenderedView lit =
      StereoRenderer(world, day).renderWithGroundTruth(world.startCameraPose());
  const cv::Mat sky = dark.ground_truth.object_id == kBackgroundId;
  ASSERT_GT(cv::countNonZero(sky), 100);
  EXPECT_LT(cv::mean(dark.frame.left_bgr, sky)[1], 5.0);  // anti-aliased silhouettes only
  EXPECT_GT(cv::mean(lit.frame.left_bgr, sky)[1], 50.0);
  EXPECT_GT(cv::mean(lit.frame.left_bgr)[1], cv::mean(dark.frame.left_bgr)[1] + 10.0);
}

TEST(AmbientLight, ALeafShadesAFruitletFromAnOverheadSun) {
  Fruitlet f;
  f.center_m = Eigen::Vector3d(0.0, 0.0, 1.0);
  f.radius_m = 0.006;
  Leaf leaf;
  leaf.half_length_m = 0.04;
  leaf.half_width_m = 0.03;
  leaf.T_world_leaf.translation() = Eigen::Vector3d(0.0, 0.0, 1.03);  // 3 cm above it
  RenderConfig r;
  r.intrinsics = test::smallIntrinsics(288, 216, 800.0);  // the fruitlet ~30 px across
  r.noise_sigma = 0.0;
  r.flash_power = 0.0;  // daylight alone
  r.sun_irradiance = 1.0;
  r.sun_direction_world = Eigen::Vector3d::UnitZ();
  r.sky_irradiance = 0.2;
  const auto brightness = [&](std::vector<Leaf> leaves) {
    const World world = World::fromParts({f}, std::move(leaves), {}, std::nullopt);
    const RenderedView v = StereoRenderer(world, r).renderWithGroundTruth(world.startCameraPose());
    const cv::Mat fruitlet = v.ground_truth.object_id == kFirstFruitletId;
    EXPECT_GT(cv::countNonZero(fruitlet), 200);
    cv::Mat grey;
    cv::cvtColor(v.frame.left_bgr, grey, cv::COLOR_BGR2GRAY);
    return cv::mean(grey, fruitlet)[0];
  };
  // The start view looks along +y, level: the leaf above is out of its sight, only its
  // shadow falls on the fruitlet.
  EXPECT_LT(brightness({leaf}), 0.8 * brightness({}));
}

}  // namespace
}  // namespace fvp::robot::sim
