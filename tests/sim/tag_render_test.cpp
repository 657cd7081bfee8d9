#include <apriltag/apriltag.h>
#include <apriltag/apriltag_pose.h>
#include <apriltag/tag36h11.h>
#include <gtest/gtest.h>

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

// Smoke test: libapriltag finds the rendered tag in the start view's left image with the
// right id, and its pose agrees with the world's (frame convention check; the accuracy test
// belongs to perception).
TEST(TagRender, DetectedInStartViewWithRightIdAndPose) {
  std::unique_ptr<apriltag_family_t, decltype(&tag36h11_destroy)> family(tag36h11_create(),
                                                                         &tag36h11_destroy);
  std::unique_ptr<apriltag_detector_t, decltype(&apriltag_detector_destroy)> detector(
      apriltag_detector_create(), &apriltag_detector_destroy);
  apriltag_detector_add_family(detector.get(), family.get());
  detector->nthreads = 2;

  for (const std::uint64_t seed : {1u, 2u}) {
    WorldConfig config;
    config.tag_id = 7 * static_cast<int>(seed);
    const World world = World::generate(config, seed);
    RenderOptions options;
    const StereoRenderer renderer(world);
    const host::StereoFrame frame = renderer.render(world.startCameraPose(), options);
    cv::Mat grey;
    cv::cvtColor(frame.left_bgr, grey, cv::COLOR_BGR2GRAY);
    image_u8_t image{grey.cols, grey.rows, static_cast<int32_t>(grey.step), grey.data};
    zarray_t* detections = apriltag_detector_detect(detector.get(), &image);
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

}  // namespace
}  // namespace fvp::robot::sim
