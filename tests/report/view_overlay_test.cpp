// The per-view overlay: the mask's contour, the fitted ellipses and the tag's axes land where
// their pixels are, at the overlay's scale; the ellipses of a sizing are picked by view.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "fvp/host/report/view_overlay.h"
#include "small_intrinsics.h"

namespace fvp::host::report {
namespace {

int countColour(const cv::Mat& image, const cv::Scalar& bgr) {
  cv::Mat hit;
  cv::inRange(image, bgr - cv::Scalar(30, 30, 30), bgr + cv::Scalar(30, 30, 30), hit);
  return cv::countNonZero(hit);
}

TEST(ViewOverlay, DrawsTheContourTheEllipseAndTheTagAxesAtTheOverlaysScale) {
  const StereoIntrinsics in = test::smallIntrinsics(640, 480, 600.0);
  const cv::Mat grey(in.height_px, in.width_px, CV_8UC3, cv::Scalar(90, 90, 90));
  cv::Mat mask = cv::Mat::zeros(in.height_px, in.width_px, CV_8U);
  cv::circle(mask, {200, 200}, 40, 255, cv::FILLED);
  OverlayEllipse e;
  e.center_px = {450, 300};
  e.axes_px = {80, 60};
  e.label = "D0 7.00 mm";
  e.well_seen = true;
  TagDetection tag;
  tag.tag_id = 3;
  tag.corners_px.fill(Eigen::Vector2d::Zero());
  tag.T_camera_tag.translation() = Eigen::Vector3d(0.0, -0.05, 0.4);
  const cv::Mat out = drawViewOverlay(grey, mask, {e}, tag, 0.04, in, {}, 320);
  ASSERT_EQ(out.cols, 320);
  ASSERT_EQ(out.rows, 240);
  // Contour (cyan) on the disc's rim at half scale: (100, 100) radius 20, not at its centre.
  cv::Mat cyan;
  cv::inRange(out, cv::Scalar(200, 200, 0), cv::Scalar(255, 255, 60), cyan);
  EXPECT_GT(cv::countNonZero(cyan(cv::Rect(75, 75, 50, 50))), 60);
  EXPECT_EQ(cyan.at<uchar>(100, 100), 0);
  // The well-seen ellipse (green) around (225, 150) at half scale.
  cv::Mat green;
  cv::inRange(out, cv::Scalar(30, 190, 30), cv::Scalar(90, 250, 90), green);
  EXPECT_GT(cv::countNonZero(green(cv::Rect(195, 125, 60, 50))), 60);
  EXPECT_EQ(cv::countNonZero(green(cv::Rect(0, 0, 150, 240))), 0);
  // Tag axes: red (x) to the right of the tag's centre, which projects to (160, 82) at half
  // scale; with no tag, no red.
  EXPECT_GT(countColour(out(cv::Rect(160, 70, 40, 25)), cv::Scalar(0, 0, 255)), 5);
  const cv::Mat no_tag = drawViewOverlay(grey, mask, {e}, std::nullopt, 0.04, in, {}, 320);
  EXPECT_EQ(countColour(no_tag, cv::Scalar(0, 0, 255)), 0);
  // A crop of the ellipse's quarter, drawn 320 px wide (scale 2): the ellipse around (450, 300)
  // lands at ((450 - 400) * 2, (300 - 240) * 2) = (100, 120).
  const cv::Mat crop =
      drawViewOverlay(grey, mask, {e}, std::nullopt, 0.04, in, cv::Rect(400, 240, 160, 120), 320);
  ASSERT_EQ(crop.size(), cv::Size(320, 240));
  cv::Mat crop_green;
  cv::inRange(crop, cv::Scalar(30, 190, 30), cv::Scalar(90, 250, 90), crop_green);
  EXPECT_GT(cv::countNonZero(crop_green(cv::Rect(10, 50, 40, 140))), 40);  // left rim at x = 20
  EXPECT_EQ(crop_green.at<uchar>(120, 100), 0);                            // not its centre
}

TEST(ViewOverlay, TheRegionCropFramesTheRegionsProjection) {
  const StereoIntrinsics in = test::smallIntrinsics(640, 480, 600.0);
  // A 5 cm region 0.5 m ahead: 60 px radius, 75 px with the margin, around the centre pixel.
  const cv::Rect crop = regionCrop({0.0, 0.0, 0.5}, 0.05, Eigen::Isometry3d::Identity(), in);
  EXPECT_NEAR(crop.x, 319.5 - 75, 1.0);
  EXPECT_NEAR(crop.width, 150, 1.0);
  // Behind the camera: the whole image.
  EXPECT_EQ(regionCrop({0.0, 0.0, -0.5}, 0.05, Eigen::Isometry3d::Identity(), in),
            cv::Rect(0, 0, 640, 480));
}

TEST(ViewOverlay, EllipsesOfASizingArePickedByViewAndLabelled) {
  const auto image = [](int view, double size_mm, bool well_seen) {
    return nlohmann::json{
        {"view", view},
        {"size_ours_mm", size_mm},
        {"well_seen", well_seen},
        {"ellipse", {{"center_px", {10.0, 20.0}}, {"axes_px", {8.0, 6.0}}, {"angle_deg", 30.0}}}};
  };
  const nlohmann::json sizing = {
      {"sized_fruitlets",
       {{{"per_image", {image(0, 7.0, true), image(2, 7.1, false)}}},
        {{"per_image", {image(2, 6.5, true)}}}}},
      {"unsupported_detections", {{{"per_image", {image(2, 9.0, false)}}}}}};
  const auto in_two = overlayEllipses(sizing, 2, std::nullopt);
  ASSERT_EQ(in_two.size(), 3u);
  EXPECT_EQ(in_two[0].label, "D0 7.10 mm");
  EXPECT_FALSE(in_two[0].well_seen);
  EXPECT_EQ(in_two[1].label, "D1 6.50 mm");
  EXPECT_EQ(in_two[2].label, "X0 9.00 mm");
  EXPECT_FALSE(in_two[2].kept);
  EXPECT_DOUBLE_EQ(in_two[2].angle_deg, 30.0);
  EXPECT_EQ(overlayEllipses(sizing, 0, 1).front().label, "C1.D0 7.00 mm");
  EXPECT_TRUE(overlayEllipses(sizing, 1, std::nullopt).empty());
}

}  // namespace
}  // namespace fvp::host::report
