#include <apriltag/apriltag.h>
#include <apriltag/apriltag_pose.h>
#include <apriltag/tag36h11.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <opencv2/imgproc.hpp>

#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/tag_image.h"

namespace fvp::robot::sim {
namespace {

TEST(TagImage, MatchesLibapriltagsOwnImage) {
  std::unique_ptr<apriltag_family_t, decltype(&tag36h11_destroy)> family(tag36h11_create(),
                                                                         &tag36h11_destroy);
  EXPECT_EQ(tag36h11CodeCount(), 587);
  for (const int id : {0, 1, 42, 586}) {
    const cv::Mat ours = tag36h11Image(id);
    image_u8_t* theirs = apriltag_to_image(family.get(), id);
    ASSERT_EQ(ours.rows, theirs->height);
    ASSERT_EQ(ours.cols, theirs->width);
    for (int r = 0; r < ours.rows; ++r) {
      for (int c = 0; c < ours.cols; ++c) {
        EXPECT_EQ(ours.at<std::uint8_t>(r, c), theirs->buf[r * theirs->stride + c])
            << "id " << id << " cell " << r << ", " << c;
      }
    }
    // Debian's libapriltag 3.3 does not export image_u8_destroy; the image is two callocs.
    std::free(theirs->buf);
    std::free(theirs);
  }
  EXPECT_THROW(tag36h11Image(587), std::out_of_range);
}

// libapriltag's tag36h11 detector, as the tests here use it.
struct Tag36h11Detector {
  std::unique_ptr<apriltag_family_t, decltype(&tag36h11_destroy)> family{tag36h11_create(),
                                                                         &tag36h11_destroy};
  std::unique_ptr<apriltag_detector_t, decltype(&apriltag_detector_destroy)> detector{
      apriltag_detector_create(), &apriltag_detector_destroy};
  Tag36h11Detector() {
    apriltag_detector_add_family(detector.get(), family.get());
    detector->nthreads = 2;
  }
  // The detections in a BGR image (free with apriltag_detections_destroy).
  zarray_t* detect(const cv::Mat& bgr) const {
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    image_u8_t image{grey.cols, grey.rows, static_cast<int32_t>(grey.step), grey.data};
    return apriltag_detector_detect(detector.get(), &image);
  }
};

// Smoke test: libapriltag finds the rendered tag in the start view's left image with the
// right id, and its pose agrees with the world's (frame convention check; the accuracy test
// belongs to perception).
TEST(TagRender, DetectedInStartViewWithRightIdAndPose) {
  const Tag36h11Detector tags;

  for (const std::uint64_t seed : {1u, 2u}) {
    WorldConfig config;
    config.tag_id = 7 * static_cast<int>(seed);
    const World world = World::generate(config, seed);
    RenderOptions options;
    const StereoRenderer renderer(world);
    const host::StereoFrame frame = renderer.render(world.startCameraPose(), options);
    zarray_t* detections = tags.detect(frame.left_bgr);
    ASSERT_EQ(zarray_size(detections), 1) << "seed " << seed;
    apriltag_detection_t* detection = nullptr;
    zarray_get(detections, 0, &detection);
    EXPECT_EQ(detection->id, config.tag_id);

    apriltag_detection_info_t info{detection,
                                   world.tag().tag_size_m,
                                   frame.intrinsics.fx_px,
                                   frame.intrinsics.fy_px,
                                   frame.intrinsics.cx_px,
                                   frame.intrinsics.cy_px};
    apriltag_pose_t pose;
    estimate_tag_pose(&info, &pose);
    Eigen::Isometry3d T_camera_tag = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) T_camera_tag.linear()(r, c) = MATD_EL(pose.R, r, c);
      T_camera_tag.translation()[r] = MATD_EL(pose.t, r, 0);
    }
    const Eigen::Isometry3d T_camera_tag_true =
        world.startCameraPose().inverse() * world.tag().T_world_tag;
    const double position_error_m =
        (T_camera_tag.translation() - T_camera_tag_true.translation()).norm();
    const double angle_error_deg =
        Eigen::AngleAxisd(T_camera_tag.linear().transpose() * T_camera_tag_true.linear()).angle() *
        180.0 / M_PI;
    std::cout << "seed " << seed << ": tag " << detection->id << " position error "
              << position_error_m * 1e3 << " mm, angle error " << angle_error_deg << " deg\n";
    EXPECT_LT(position_error_m, 0.005);
    EXPECT_LT(angle_error_deg, 5.0);
    // Debian's libapriltag 3.3 does not export matd_destroy; a matd_t is one calloc.
    std::free(pose.R);
    std::free(pose.t);
    apriltag_detections_destroy(detections);
  }
}

// The detected corners' pixel error on the simulator's renders, the measurement behind the
// pose graph's tag_corner_sigma_px (cluster_pose_graph.h): each corner against the true
// corner projected through the exact pose, over the start views of eight worlds.
TEST(TagRender, CornerPixelErrorIsBelowThePoseGraphsSigma) {
  const Tag36h11Detector tags;
  double sum_sq = 0.0;
  int corners = 0;
  Eigen::Vector2d mean_d = Eigen::Vector2d::Zero();
  for (const std::uint64_t seed : {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u}) {
    const World world = World::generate(WorldConfig{}, seed);
    const StereoRenderer renderer(world);
    const host::StereoFrame frame = renderer.render(world.startCameraPose(), RenderOptions{});
    zarray_t* detections = tags.detect(frame.left_bgr);
    ASSERT_EQ(zarray_size(detections), 1) << "seed " << seed;
    apriltag_detection_t* detection = nullptr;
    zarray_get(detections, 0, &detection);
    const double h = 0.5 * world.tag().tag_size_m;
    const Eigen::Isometry3d T_camera_tag =
        world.startCameraPose().inverse() * world.tag().T_world_tag;
    for (int k = 0; k < 4; ++k) {
      // libapriltag's pixel centres are at +0.5 (the detector takes it off: apriltag_detector.cpp).
      const Eigen::Vector2d seen(detection->p[k][0] - 0.5, detection->p[k][1] - 0.5);
      double nearest = 1e9;  // against the nearest true corner: no order assumed
      Eigen::Vector2d nearest_d = Eigen::Vector2d::Zero();
      for (const Eigen::Vector2d& c : {Eigen::Vector2d(-h, h), Eigen::Vector2d(h, h),
                                       Eigen::Vector2d(h, -h), Eigen::Vector2d(-h, -h)}) {
        const auto px = frame.intrinsics.project(T_camera_tag * Eigen::Vector3d(c.x(), c.y(), 0));
        ASSERT_TRUE(px.has_value());
        if ((*px - seen).norm() < nearest) {
          nearest = (*px - seen).norm();
          nearest_d = seen - *px;
        }
      }
      sum_sq += nearest * nearest;
      mean_d += nearest_d;
      ++corners;
    }
    apriltag_detections_destroy(detections);
  }
  const double rms_px = std::sqrt(sum_sq / corners);
  std::cout << "tag corner pixel error over " << corners << " corners: RMS " << rms_px
            << " px, mean " << (mean_d / corners).transpose() << " px\n";
  EXPECT_LT(rms_px, 0.5);
}

}  // namespace
}  // namespace fvp::robot::sim
