// The pose errors: off by default; deterministic per seed and not touching the world drawn
// from the same seed; each error's magnitude as configured (statistics over many seeds); the
// arm's error smooth over the workspace; and the simulated camera rendering from the true
// pose while telling the robot the other, so that the reconstructed cloud is moved by
// exactly T_told T_true^-1.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fvp/host/perception/cloud_projector.h"
#include "fvp/robot/sim/pose_error_model.h"
#include "fvp/robot/sim/simulated_camera.h"
#include "fvp/robot/sim/world.h"
#include "small_intrinsics.h"

namespace fvp::robot::sim {
namespace {

constexpr int kSeeds = 400;

Eigen::Isometry3d somePose(double a) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::AngleAxisd(a, Eigen::Vector3d(0.3, -1.0, 0.2).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.1 + a, -0.3, 1.0 + 0.5 * a);
  return T;
}

double rmsOf(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x * x;
  return std::sqrt(sum / double(v.size()));
}

TEST(PoseErrorModel, OffByDefault) {
  const PoseErrorModel model(WorldConfig{}, 7);
  EXPECT_FALSE(model.enabled());
  EXPECT_TRUE(model.truePose(somePose(0.4), 3).isApprox(somePose(0.4), 1e-15));
}

TEST(PoseErrorModel, DeterministicPerSeedAndTheWorldUnchanged) {
  WorldConfig c;
  c.hand_eye_translation_sigma_m = 0.0015;
  c.arm_position_error_m = 0.001;
  c.view_rotation_sigma_deg = 0.05;
  const PoseErrorModel a(c, 5), b(c, 5), other(c, 6);
  EXPECT_TRUE(a.truePose(somePose(0.2), 4).isApprox(b.truePose(somePose(0.2), 4), 0.0));
  EXPECT_FALSE(a.truePose(somePose(0.2), 4).isApprox(other.truePose(somePose(0.2), 4), 1e-9));
  // The world drawn from the same seed does not depend on the error settings.
  const World exact = World::generate(WorldConfig{}, 5), with_errors = World::generate(c, 5);
  ASSERT_EQ(exact.fruitlets().size(), with_errors.fruitlets().size());
  for (std::size_t i = 0; i < exact.fruitlets().size(); ++i)
    EXPECT_EQ(exact.fruitlets()[i].center_m, with_errors.fruitlets()[i].center_m);
}

TEST(PoseErrorModel, HandEyeAloneIsOneMountErrorOfTheConfiguredSize) {
  WorldConfig c;
  c.hand_eye_translation_sigma_m = 0.0015;
  c.hand_eye_rotation_sigma_deg = 0.3;
  std::vector<double> axes, angles_deg;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const PoseErrorModel model(c, seed);
    const Eigen::Isometry3d& H = model.T_camera_told_camera_true();
    // The same H for every pose and view: T_true = T_told H.
    for (int view : {0, 7})
      EXPECT_TRUE(
          model.truePose(somePose(0.1 * view), view).isApprox(somePose(0.1 * view) * H, 1e-12));
    for (int a = 0; a < 3; ++a) axes.push_back(H.translation()[a]);
    angles_deg.push_back(Eigen::AngleAxisd(H.rotation()).angle() * 180.0 / std::numbers::pi);
  }
  // Per axis RMS sigma; the angle's RMS sqrt(3) sigma (three components).
  EXPECT_NEAR(rmsOf(axes), 0.0015, 0.0015 * 0.1);
  EXPECT_NEAR(rmsOf(angles_deg), std::sqrt(3.0) * 0.3, std::sqrt(3.0) * 0.3 * 0.1);
}

TEST(PoseErrorModel, TheArmsErrorHasTheConfiguredRmsAndIsSmooth) {
  WorldConfig c;
  c.arm_position_error_m = 0.001;
  std::vector<double> axes, steps;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const PoseErrorModel model(c, seed);
    for (int i = 0; i < 5; ++i) {
      const Eigen::Vector3d p(-0.5 + 0.23 * i, -0.3 + 0.07 * i, 0.8 + 0.11 * i);
      const Eigen::Vector3d e = model.armError_m(p);
      for (int a = 0; a < 3; ++a) axes.push_back(e[a]);
      // One centimetre further along x.
      const Eigen::Vector3d moved = model.armError_m(p + Eigen::Vector3d(0.01, 0.0, 0.0));
      for (int a = 0; a < 3; ++a) steps.push_back(moved[a] - e[a]);
      // Only a translation: the told pose moved by the field's value at its position.
      EXPECT_TRUE(model.truePose(somePose(0.3), 2).linear().isApprox(somePose(0.3).linear()));
    }
  }
  EXPECT_NEAR(rmsOf(axes), 0.001, 0.0001);
  // Over 1 cm a wave of 0.5 m moves by about 2 pi 0.01 / 0.5 / sqrt(3) = 7 % of its size
  // (the directions spread over the three axes): smooth, not constant.
  EXPECT_GT(rmsOf(steps), 0.03 * 0.001);
  EXPECT_LT(rmsOf(steps), 0.15 * 0.001);
}

TEST(PoseErrorModel, EachViewHasItsOwnRepeatabilityNoise) {
  WorldConfig c;
  c.view_translation_sigma_m = 0.0001;
  std::vector<double> axes;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const PoseErrorModel model(c, seed);
    EXPECT_TRUE(model.viewNoise(3).isApprox(model.viewNoise(3), 0.0));
    EXPECT_FALSE(model.viewNoise(3).isApprox(model.viewNoise(4), 1e-12));
    for (int a = 0; a < 3; ++a) axes.push_back(model.viewNoise(seed % 9).translation()[a]);
  }
  EXPECT_NEAR(rmsOf(axes), 0.0001, 0.00001);
}

TEST(PoseErrorModel, TheCameraRendersFromTheTruePoseAndTheCloudMovesByExactlyTheError) {
  WorldConfig c;
  c.hand_eye_translation_sigma_m = 0.002;
  c.hand_eye_rotation_sigma_deg = 0.5;
  const World world = World::generate(WorldConfig{}, 1);
  RenderConfig rc;
  rc.intrinsics = test::smallIntrinsics(288, 216, 220.0);
  const StereoRenderer renderer(world, rc);
  SimClock clock(SimClock::Mode::kFixed);
  const PoseErrorModel model(c, 11);
  SimulatedCamera camera(renderer, clock, &model);
  const Eigen::Isometry3d told = world.startCameraPose();
  const host::StereoFrame seen = camera.capture(told).frame;
  const Eigen::Isometry3d truth = told * model.T_camera_told_camera_true();
  ASSERT_GT((truth.translation() - told.translation()).norm(), 1e-4);
  EXPECT_TRUE(camera.lastTruePose().isApprox(truth, 1e-12));
  EXPECT_TRUE(seen.T_world_camera.isApprox(told, 0.0));
  // The images are those of the true pose, pixel for pixel.
  const host::StereoFrame from_truth = renderer.render(truth);
  EXPECT_EQ(cv::norm(seen.left_bgr, from_truth.left_bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(seen.right_bgr, from_truth.right_bgr, cv::NORM_INF), 0.0);
  // So the cloud the robot reconstructs with the pose it was told is the true one moved by
  // T_told T_true^-1, exactly.
  const cv::Mat disparity(rc.intrinsics.height_px, rc.intrinsics.width_px, CV_32F,
                          cv::Scalar(40.0f));
  const host::CloudProjector projector;
  const auto told_cloud = projector.project(disparity, {}, seen.intrinsics, told);
  const auto true_cloud = projector.project(disparity, {}, from_truth.intrinsics, truth);
  ASSERT_EQ(told_cloud.other_points_m.size(), true_cloud.other_points_m.size());
  ASSERT_GT(told_cloud.other_points_m.size(), 1000u);
  const Eigen::Isometry3d shift = told * truth.inverse();
  for (std::size_t i = 0; i < told_cloud.other_points_m.size(); i += 97)
    EXPECT_LT((told_cloud.other_points_m[i].cast<double>() -
               shift * true_cloud.other_points_m[i].cast<double>())
                  .norm(),
              1e-6);
}

}  // namespace
}  // namespace fvp::robot::sim
