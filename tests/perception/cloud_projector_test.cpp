#include "fvp/host/perception/cloud_projector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace fvp::host {
namespace {

Eigen::Isometry3d somePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.4, -1.2, 0.9);
  return T;
}

TEST(CloudProjector, ProjectsExactlyIntoTheWorldFrame) {
  StereoIntrinsics K;
  K.width_px = 64;
  K.height_px = 48;
  K.cx_px = 31.5;
  K.cy_px = 23.5;
  cv::Mat disparity(K.height_px, K.width_px, CV_32F);
  cv::Mat mask = cv::Mat::zeros(disparity.size(), CV_8U);
  for (int v = 0; v < K.height_px; ++v)
    for (int u = 0; u < K.width_px; ++u) disparity.at<float>(v, u) = 100.0f + u + 0.25f * v;
  mask(cv::Rect(10, 10, 5, 4)).setTo(255);
  const Eigen::Isometry3d T = somePose();
  const LabeledClouds c = CloudProjector().project(disparity, mask, K, T);
  ASSERT_EQ(c.roi_points_m.size(), 20u);
  ASSERT_EQ(c.other_points_m.size(), static_cast<std::size_t>(K.width_px * K.height_px - 20));
  EXPECT_EQ(c.stats.roi_points, 20);
  EXPECT_EQ(c.stats.droppedDisparities(), 0);
  EXPECT_TRUE(c.sensor_origin_m.isApprox(T.translation()));
  // Row-major order: the first ROI point is pixel (10, 10).
  const double d = disparity.at<float>(10, 10);
  const Eigen::Vector3d expected = T * K.unproject(10, 10, K.fx_px * K.baseline_m / d);
  EXPECT_LT((c.roi_points_m[0].cast<double>() - expected).norm(), 1e-6);
  // And it reprojects to its pixel with the right depth.
  const Eigen::Vector3d p_cam = T.inverse() * c.roi_points_m[0].cast<double>();
  EXPECT_NEAR(K.project(p_cam)->x(), 10.0, 1e-4);
  EXPECT_NEAR(K.project(p_cam)->y(), 10.0, 1e-4);
  EXPECT_NEAR(K.fx_px * K.baseline_m / p_cam.z(), d, 1e-4);
  const Eigen::Vector3d last =
      T * K.unproject(K.width_px - 1, K.height_px - 1,
                      K.depthFromDisparity(disparity.at<float>(K.height_px - 1, K.width_px - 1)));
  EXPECT_LT((c.other_points_m.back().cast<double>() - last).norm(), 1e-6);
}

TEST(CloudProjector, InvalidDisparitiesAreDroppedAndCounted) {
  StereoIntrinsics K;
  K.width_px = 8;
  K.height_px = 2;
  cv::Mat d(2, 8, CV_32F, cv::Scalar(150.0f));
  d.at<float>(0, 0) = std::numeric_limits<float>::quiet_NaN();
  d.at<float>(0, 1) = std::numeric_limits<float>::infinity();
  d.at<float>(0, 2) = 0.0f;
  d.at<float>(0, 3) = -1.0f;
  d.at<float>(0, 4) = -std::numeric_limits<float>::infinity();
  d.at<float>(1, 0) = 1e-9f;    // 0.05e9 m away: beyond max depth
  d.at<float>(1, 1) = 1000.0f;  // 5.5 cm: nearer than min depth
  ProjectionConfig config;
  config.min_depth_m = 0.1;
  config.max_depth_m = 5.0;
  cv::Mat mask(2, 8, CV_8U, cv::Scalar(255));
  const LabeledClouds c = CloudProjector(config).project(d, mask, K, Eigen::Isometry3d::Identity());
  EXPECT_EQ(c.stats.nonfinite, 3);
  EXPECT_EQ(c.stats.nonpositive, 2);
  EXPECT_EQ(c.stats.out_of_range, 2);
  EXPECT_EQ(c.stats.droppedDisparities(), 7);
  EXPECT_EQ(c.roi_points_m.size(), 9u);
  EXPECT_TRUE(c.other_points_m.empty());
  for (const auto& p : c.roi_points_m) EXPECT_TRUE(p.allFinite());
}

// Outside the full-resolution rectangle one sample per coarse block, at the block's centre.
TEST(CloudProjector, CoarseSamplesOnePointPerBlock) {
  StereoIntrinsics K;
  K.width_px = 16;
  K.height_px = 8;
  K.cx_px = 7.5;
  K.cy_px = 3.5;
  cv::Mat d(8, 16, CV_32F, cv::Scalar(200.0f));
  SampleGrid grid{cv::Rect(4, 2, 4, 4), 2};
  const LabeledClouds c =
      CloudProjector().project(d, cv::Mat(), K, Eigen::Isometry3d::Identity(), grid);
  // 16 full-resolution samples + (32 coarse blocks - the 4 blocks inside the rectangle).
  EXPECT_EQ(c.other_points_m.size(), 16u + 28u);
  const double z = K.fx_px * K.baseline_m / 200.0;
  const Eigen::Vector3d first = K.unproject(0.5, 0.5, z);  // block (0,0)'s centre
  EXPECT_LT((c.other_points_m.front().cast<double>() - first).norm(), 1e-7);
}

}  // namespace
}  // namespace fvp::host
