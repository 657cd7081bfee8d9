// A session's overlays and scene when nothing was found (no tag: no region, map or mesh) and
// when a view sized a fruitlet: which views get an overlay and why, and a scene that holds
// only what exists.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "fvp/host/report/session_report.h"
#include "fvp/host/report/view_overlay.h"
#include "small_intrinsics.h"

namespace fvp::host {
namespace {

namespace fs = std::filesystem;

StereoFrame darkFrame() {
  StereoFrame frame;
  frame.intrinsics = test::smallIntrinsics(320, 240, 300.0);
  frame.left_bgr = cv::Mat(240, 320, CV_8UC3, cv::Scalar(20, 20, 20));
  frame.right_bgr = frame.left_bgr.clone();
  return frame;
}

class SessionReport : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() / ("fvp_session_report_test_" + std::to_string(::getpid()));
    fs::remove_all(out_);
    session_.enableTsdf();
    for (int v = 0; v < 3; ++v) session_.addView(darkFrame());
  }
  void TearDown() override { fs::remove_all(out_); }

  fs::path out_;
  MappingSession session_{PerceptionConfig{}, "octomap", map::MapConfig{}, nullptr};
};

TEST_F(SessionReport, WithoutATagOnlyTheStartViewIsShownAndTheSceneIsEmpty) {
  ASSERT_FALSE(session_.region().has_value());
  const nlohmann::json sizing = {{"sized_fruitlets", nlohmann::json::array()},
                                 {"unsupported_detections", nlohmann::json::array()}};
  const auto image_of = [](int) { return darkFrame().left_bgr; };
  const nlohmann::json overlays =
      writeSessionOverlays(session_, sizing, 5, std::nullopt, image_of, out_, "start view");
  ASSERT_EQ(overlays.size(), 1u);
  EXPECT_EQ(overlays[0]["view"], 5);  // numbered over the run: the session's first view is 5
  EXPECT_EQ(overlays[0]["why"], "start view");
  EXPECT_FALSE(overlays[0]["tag_detected"].get<bool>());
  const cv::Mat written = cv::imread((out_ / overlays[0]["file"].get<std::string>()).string());
  EXPECT_EQ(written.cols, report::kOverlayWidthPx);  // the whole image: no region to crop to
  // Without a reason for the first view (fvp size: no start view), nothing.
  EXPECT_TRUE(writeSessionOverlays(session_, sizing, 0, std::nullopt, image_of, out_).empty());

  report::ViewerScene scene("t", "s");
  addSessionToScene(scene, session_, sizing, 0, std::nullopt);
  const nlohmann::json j = scene.toJson();
  EXPECT_FALSE(j.contains("fine_voxels"));
  EXPECT_FALSE(j.contains("mesh"));
  EXPECT_TRUE(j.at("cluster_regions").empty());
  EXPECT_TRUE(j.at("tags").empty());
  EXPECT_TRUE(j.at("detections").empty());
}

TEST_F(SessionReport, AViewThatSizedAFruitletGetsAnOverlaySayingWhich) {
  const auto image = [](int view) {
    return nlohmann::json{
        {"view", view},
        {"size_ours_mm", 7.0},
        {"size_paper_mm", 6.8},
        {"well_seen", true},
        {"ellipse",
         {{"center_px", {160.0, 120.0}}, {"axes_px", {30.0, 28.0}}, {"angle_deg", 0.0}}}};
  };
  const nlohmann::json sizing = {
      {"sized_fruitlets", {{{"per_image", {image(2)}}}, {{"per_image", {image(2)}}}}},
      {"unsupported_detections", {{{"per_image", {image(1)}}}}}};
  const nlohmann::json overlays = writeSessionOverlays(
      session_, sizing, 0, 3, [](int) { return darkFrame().left_bgr; }, out_);
  // View 1 only sized a dropped detection: not a view that counts.
  ASSERT_EQ(overlays.size(), 1u);
  EXPECT_EQ(overlays[0]["view"], 2);
  EXPECT_EQ(overlays[0]["why"], "sized C3.D0, C3.D1");
  EXPECT_TRUE(fs::exists(out_ / "overlays" / "002.jpg"));
}

}  // namespace
}  // namespace fvp::host
