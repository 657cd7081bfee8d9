#include "fvp/host/perception/apriltag_detector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "fvp/host/perception/cluster_region_image.h"
#include "synthetic_scenes.h"

namespace fvp::host {
namespace {

double angleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / M_PI;
}

// A tag drawn from libapriltag's own code bits at 0.3 m, tilted: pose within 2 mm and 2 deg,
// in the documented frame (x right, y down as printed, z into the tag).
TEST(AprilTagDetector, SyntheticTagPoseAtPointThreeMetres) {
  StereoIntrinsics K;
  Eigen::Isometry3d T_camera_tag = Eigen::Isometry3d::Identity();
  T_camera_tag.linear() = (Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
                           Eigen::AngleAxisd(-0.15, Eigen::Vector3d::UnitX()) *
                           Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()))
                              .toRotationMatrix();
  T_camera_tag.translation() = Eigen::Vector3d(0.02, -0.015, 0.3);
  const cv::Mat image = test::renderTagImage(K, T_camera_tag, 0, 0.03, 1.5, 2.0, 3);
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  T_world_camera.translation() = Eigen::Vector3d(1, 2, 3);
  AprilTagDetector detector;
  const auto det = detector.detect(image, K, T_world_camera);
  ASSERT_TRUE(det.has_value());
  EXPECT_EQ(det->tag_id, 0);
  const double pos_mm = (det->T_camera_tag.translation() - T_camera_tag.translation()).norm() * 1e3;
  const double rot_deg = angleDeg(det->T_camera_tag.linear(), T_camera_tag.linear());
  std::cout << "[ measured ] synthetic tag at 0.3 m: position error " << pos_mm
            << " mm, rotation error " << rot_deg << " deg\n";
  EXPECT_LE(pos_mm, 2.0);
  EXPECT_LE(rot_deg, 2.0);
  EXPECT_TRUE(det->T_world_tag.isApprox(T_world_camera * det->T_camera_tag));
  // Corner 0 is the tag-frame corner (-s/2, +s/2, 0).
  const auto c0 = K.project(T_camera_tag * Eigen::Vector3d(-0.015, 0.015, 0.0));
  EXPECT_LT((det->corners_px[0] - *c0).norm(), 1.0);
}

TEST(AprilTagDetector, WrongIdIsNotReported) {
  StereoIntrinsics K;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0, 0, 0.3);
  const cv::Mat image = test::renderTagImage(K, T, 5, 0.03, 1.5, 2.0, 4);
  AprilTagDetector detector;  // looks for id 0
  EXPECT_FALSE(detector.detect(image, K, Eigen::Isometry3d::Identity()).has_value());
  const auto all = detector.detectAll(image, K, Eigen::Isometry3d::Identity());
  ASSERT_EQ(all.size(), 1u);
  EXPECT_EQ(all[0].tag_id, 5);
}

TEST(ClusterRegion, FromTagAndImageBounds) {
  Eigen::Isometry3d T_world_tag = Eigen::Isometry3d::Identity();
  T_world_tag.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T_world_tag.translation() = Eigen::Vector3d(1, 2, 3);
  ClusterRegionConfig config;
  config.center_offset_tag_m = Eigen::Vector3d(0.0, 0.05, 0.0);
  config.radius_m = 0.04;
  const ClusterRegion region = ClusterRegion::fromTag(T_world_tag, config);
  EXPECT_TRUE(region.center_m().isApprox(Eigen::Vector3d(1, 2, 3.05)));
  EXPECT_TRUE(region.contains(Eigen::Vector3d(1, 2.03, 3.05)));
  EXPECT_FALSE(region.contains(Eigen::Vector3d(1, 2.05, 3.05)));
  // Seen from 0.3 m straight on: about 2 * 0.04 / 0.3 * 1100 = 293 px wide, centred.
  StereoIntrinsics K;
  const ClusterRegion ahead(Eigen::Vector3d(0, 0, 0.3), 0.04);
  const cv::Rect r = clusterRegionImageBounds(ahead, K, Eigen::Isometry3d::Identity());
  EXPECT_NEAR(r.width, 2 * 1100 * std::tan(std::asin(0.04 / 0.3)), 3);  // exact tangents
  EXPECT_NEAR(r.height, r.width, 2);
  EXPECT_NEAR(r.x + 0.5 * r.width, K.cx_px, 2);
  EXPECT_EQ(clusterRegionImageBounds(ClusterRegion(Eigen::Vector3d(0, 0, -1), 0.1), K,
                                     Eigen::Isometry3d::Identity()),
            cv::Rect());
  EXPECT_EQ(clusterRegionImageBounds(ClusterRegion(Eigen::Vector3d(0, 0, 0.05), 0.1), K,
                                     Eigen::Isometry3d::Identity()),
            cv::Rect(0, 0, K.width_px, K.height_px));
  config.radius_m = -1;
  EXPECT_THROW(ClusterRegion::fromTag(T_world_tag, config), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::host
