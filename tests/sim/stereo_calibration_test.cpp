// Stereo calibration errors: a longer true baseline scales every disparity the system
// measures (its frames keep the nominal baseline), and a vertical misalignment moves the right
// image down by exactly its rows.
#include <gtest/gtest.h>

#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"
#include "small_intrinsics.h"

namespace fvp::robot::sim {
namespace {

RenderConfig smallRig(const WorldConfig& world) {
  RenderConfig rc = renderConfigFor(world);
  rc.intrinsics = test::smallIntrinsics(288, 216, 220.0);
  rc.samples_per_pixel = 1;  // one ray through each pixel centre: shifts are exact
  rc.noise_sigma = 0.0;
  return rc;
}

TEST(StereoCalibration, ALongerBaselineScalesEveryDisparityTheSystemMeasures) {
  const World world = World::generate(WorldConfig{}, 1);
  WorldConfig longer;
  longer.stereo_baseline_error = 0.01;
  const StereoRenderer nominal(world, smallRig(WorldConfig{})), built(world, smallRig(longer));
  RenderOptions exact;
  exact.exact_disparity = true;
  const auto a = nominal.render(world.startCameraPose(), exact);
  const auto b = built.render(world.startCameraPose(), exact);
  // The frame keeps the nominal baseline: the system converts with it and sees the scene
  // 1 % nearer.
  EXPECT_DOUBLE_EQ(b.intrinsics.baseline_m, a.intrinsics.baseline_m);
  int compared = 0;
  for (int v = 0; v < a.disparity_px.rows; v += 7)
    for (int u = 0; u < a.disparity_px.cols; u += 7)
      if (const float d = a.disparity_px.at<float>(v, u); d > 0.0f) {
        EXPECT_NEAR(b.disparity_px.at<float>(v, u), 1.01f * d, 1e-3f * d);
        ++compared;
      }
  EXPECT_GT(compared, 100);
  // The right camera moved (the flash, at the rig's centre, too: the left image's shading
  // changes a little, its geometry not at all: the exact depths above are the left's).
  EXPECT_GT(cv::norm(a.right_bgr, b.right_bgr, cv::NORM_INF), 0.0);
}

TEST(StereoCalibration, AVerticalMisalignmentMovesTheRightImageDownByItsRows) {
  const World world = World::generate(WorldConfig{}, 1);
  WorldConfig misaligned;
  misaligned.stereo_vertical_misalignment_px = 2.0;
  const StereoRenderer nominal(world, smallRig(WorldConfig{})), built(world, smallRig(misaligned));
  const auto a = nominal.render(world.startCameraPose());
  const auto b = built.render(world.startCameraPose());
  EXPECT_EQ(cv::norm(a.left_bgr, b.left_bgr, cv::NORM_INF), 0.0);
  // Row v of the misaligned right image is row v - 2 of the nominal one.
  const int rows = a.right_bgr.rows - 2;
  const cv::Mat shifted = b.right_bgr.rowRange(2, 2 + rows),
                reference = a.right_bgr.rowRange(0, rows);
  EXPECT_EQ(cv::norm(shifted, reference, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a.right_bgr, b.right_bgr, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace fvp::robot::sim
