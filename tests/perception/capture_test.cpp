#include "fvp/host/perception/capture.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <regex>

#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/perception/ply_io.h"
#include "synthetic_scenes.h"

namespace fvp::host {
namespace {
namespace fs = std::filesystem;

fs::path freshDir(const std::string& name) {
  const fs::path dir = fs::path(FVP_BINARY_DIR) / "tests" / "perception" / "tmp" / name;
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  return dir;
}

Capture makeCapture() {
  Capture c;
  c.intrinsics.width_px = 64;
  c.intrinsics.height_px = 48;
  c.intrinsics.fx_px = 1100.25;
  c.intrinsics.fy_px = 1099.75;
  c.intrinsics.cx_px = 31.5;
  c.intrinsics.cy_px = 23.25;
  c.intrinsics.baseline_m = 0.0501;
  c.T_world_camera.linear() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  c.T_world_camera.translation() = Eigen::Vector3d(0.1, -0.35, 1.2);
  const cv::Mat tex = test::randomTexture({64, 48}, 1);
  tex.convertTo(c.left_bgr, CV_8UC3);
  test::randomTexture({64, 48}, 2).convertTo(c.right_bgr, CV_8UC3);
  c.disparity_px = cv::Mat(48, 64, CV_32F, cv::Scalar(0.0f));
  for (int v = 10; v < 40; ++v)
    for (int u = 5; u < 60; ++u) c.disparity_px.at<float>(v, u) = 150.0f + 0.0625f * (u + v);
  c.disparity_px.at<float>(12, 12) = std::numeric_limits<float>::quiet_NaN();
  c.fruitlet_mask = cv::Mat::zeros(48, 64, CV_8U);
  c.fruitlet_mask(cv::Rect(20, 20, 10, 8)).setTo(255);
  c.roi_points_m = {{0.1f, 0.2f, 0.3f}, {-1.5f, 2.25f, 1e-3f}};
  for (int i = 0; i < 1000; ++i) c.other_points_m.emplace_back(i * 0.001f, -i * 0.5f, 3.0f);
  c.has_clouds = true;
  c.ground_truth_json = R"({"seed": 7, "fruitlets": []})";
  return c;
}

TEST(Capture, WriteReadRoundTrip) {
  const fs::path dir = freshDir("round_trip");
  const Capture c = makeCapture();
  writeCapture(dir, c);
  for (const char* f : {"left.png", "right.png", "disparity.png", "mask.png", "camera.yaml",
                        "roi.ply", "other.ply", "ground_truth.json"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  for (const auto& e : fs::directory_iterator(dir))  // no temporaries left behind
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();

  const Capture r = readCapture(dir);
  EXPECT_EQ(r.intrinsics.width_px, 64);
  EXPECT_EQ(r.intrinsics.height_px, 48);
  EXPECT_DOUBLE_EQ(r.intrinsics.fx_px, c.intrinsics.fx_px);
  EXPECT_DOUBLE_EQ(r.intrinsics.fy_px, c.intrinsics.fy_px);
  EXPECT_DOUBLE_EQ(r.intrinsics.cx_px, c.intrinsics.cx_px);
  EXPECT_DOUBLE_EQ(r.intrinsics.cy_px, c.intrinsics.cy_px);
  EXPECT_DOUBLE_EQ(r.intrinsics.baseline_m, c.intrinsics.baseline_m);
  EXPECT_TRUE(r.T_world_camera.matrix().isApprox(c.T_world_camera.matrix(), 1e-12));
  EXPECT_EQ(cv::norm(r.left_bgr, c.left_bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(r.right_bgr, c.right_bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(r.fruitlet_mask, c.fruitlet_mask, cv::NORM_INF), 0.0);
  // Disparities are exact at 1/16 px; NaN became 0 (invalid).
  EXPECT_EQ(r.disparity_px.at<float>(12, 12), 0.0f);
  cv::Mat expected = c.disparity_px.clone();
  expected.at<float>(12, 12) = 0.0f;
  EXPECT_EQ(cv::norm(r.disparity_px, expected, cv::NORM_INF), 0.0);
  ASSERT_TRUE(r.has_clouds);
  EXPECT_EQ(r.roi_points_m, c.roi_points_m);
  EXPECT_EQ(r.other_points_m, c.other_points_m);
  EXPECT_EQ(r.ground_truth_json, c.ground_truth_json);
  EXPECT_DOUBLE_EQ(r.disparity_scale, 16.0);

  // Rewriting without the optional parts removes them (no stale files).
  Capture minimal = c;
  minimal.disparity_px.release();
  minimal.fruitlet_mask.release();
  minimal.has_clouds = false;
  minimal.ground_truth_json.clear();
  writeCapture(dir, minimal);
  const Capture m = readCapture(dir);
  EXPECT_TRUE(m.disparity_px.empty());
  EXPECT_TRUE(m.fruitlet_mask.empty());
  EXPECT_FALSE(m.has_clouds);
  EXPECT_TRUE(m.ground_truth_json.empty());
}

TEST(Capture, InstanceMaskRoundTripsAsItsIds) {
  const fs::path dir = freshDir("instances");
  Capture c = makeCapture();
  c.fruitlet_mask = cv::Mat::zeros(48, 64, CV_16U);
  c.fruitlet_mask(cv::Rect(20, 20, 10, 8)).setTo(3);
  c.fruitlet_mask(cv::Rect(30, 20, 10, 8)).setTo(60000);  // touching the first
  writeCapture(dir, c);
  const Capture r = readCapture(dir);
  ASSERT_EQ(r.fruitlet_mask.type(), CV_16U);
  EXPECT_EQ(cv::norm(r.fruitlet_mask, c.fruitlet_mask, cv::NORM_INF), 0.0);
  // The frame keeps the ids; the pipeline's mask is their union, its instances the ids.
  const StereoFrame frame = toStereoFrame(r);
  EXPECT_NO_THROW(checkStereoFrame(frame, "capture"));
  // And back: the frame as a capture holds the same parts.
  const Capture again = captureOfFrame(frame);
  EXPECT_EQ(cv::norm(again.fruitlet_mask, c.fruitlet_mask, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(again.left_bgr, r.left_bgr, cv::NORM_INF), 0.0);
  EXPECT_TRUE(again.T_world_camera.isApprox(r.T_world_camera, 0.0));
  EXPECT_EQ(again.intrinsics.fx_px, r.intrinsics.fx_px);
  const PerceptionResult perceived = PerceptionPipeline().process(frame);
  EXPECT_EQ(cv::countNonZero(perceived.fruitlet_mask), 2 * 80);
  EXPECT_EQ(cv::norm(perceived.fruitlet_instances, c.fruitlet_mask, cv::NORM_INF), 0.0);
  // Other types are named in the error.
  StereoFrame bad = frame;
  bad.fruitlet_mask = cv::Mat::zeros(48, 64, CV_32S);
  EXPECT_THROW(
      {
        try {
          checkStereoFrame(bad, "capture");
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(std::string(e.what()).find("fruitlet_mask"), std::string::npos) << e.what();
          throw;
        }
      },
      std::invalid_argument);
}

std::string readAll(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void expectReadError(const fs::path& dir, const std::string& file, const std::string& field) {
  try {
    readCapture(dir);
    FAIL() << "no exception for " << file << " / " << field;
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file), std::string::npos) << msg;
    EXPECT_NE(msg.find(field), std::string::npos) << msg;
    EXPECT_NE(msg.find("expected"), std::string::npos) << msg;
  }
}

TEST(Capture, CorruptCameraYamlNamesFileAndField) {
  const fs::path dir = freshDir("corrupt");
  writeCapture(dir, makeCapture());
  const std::string yaml = readAll(dir / "camera.yaml");
  auto rewrite = [&](const std::string& from_regex, const std::string& to) {
    std::ofstream(dir / "camera.yaml") << std::regex_replace(yaml, std::regex(from_regex), to);
  };
  rewrite("fx: [^\\n]*", "fx: -3");
  expectReadError(dir, "camera.yaml", "'fx'");
  rewrite("baseline_m: [^\\n]*", "baseline_m: five centimetres");
  expectReadError(dir, "camera.yaml", "'baseline_m'");
  rewrite("height: [^\\n]*\\n", "");
  expectReadError(dir, "camera.yaml", "'height'");
  rewrite("- \\[0, 0, 0, 1\\]", "- [0, 0, 1]");
  expectReadError(dir, "camera.yaml", "'T_world_camera'");
  rewrite("width: 64", "width: 65");
  expectReadError(dir, "left.png", "image size");
  std::ofstream(dir / "camera.yaml") << yaml;
  EXPECT_NO_THROW(readCapture(dir));
  fs::remove(dir / "camera.yaml");
  expectReadError(dir, "camera.yaml", "");
}

TEST(Capture, CorruptPlyAndDisparityNameTheFile) {
  const fs::path dir = freshDir("corrupt_ply");
  writeCapture(dir, makeCapture());
  {
    const std::string ply = readAll(dir / "roi.ply");
    std::ofstream(dir / "roi.ply", std::ios::binary) << ply.substr(0, ply.size() - 5);
  }
  expectReadError(dir, "roi.ply", "vertex data");
  std::ofstream(dir / "roi.ply") << "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n";
  expectReadError(dir, "roi.ply", "format");
  writeCapture(dir, makeCapture());
  cv::imwrite((dir / "disparity.png").string(), cv::Mat(48, 64, CV_8U, cv::Scalar(3)));
  expectReadError(dir, "disparity.png", "pixel format");
}

TEST(PlyIo, ReadsExtraPropertiesAndEmptyClouds) {
  const fs::path dir = freshDir("ply");
  fs::create_directories(dir);
  writePlyPoints(dir / "empty.ply", {});
  EXPECT_TRUE(readPlyPoints(dir / "empty.ply").empty());
  // x y z with an extra uchar property in between, as other tools write.
  std::ofstream out(dir / "extra.ply", std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
         "property uchar red\nproperty float y\nproperty float z\nend_header\n";
  const float x = 1.5f, y = -2.0f, z = 0.25f;
  const unsigned char red = 200;
  out.write(reinterpret_cast<const char*>(&x), 4);
  out.write(reinterpret_cast<const char*>(&red), 1);
  out.write(reinterpret_cast<const char*>(&y), 4);
  out.write(reinterpret_cast<const char*>(&z), 4);
  out.close();
  const auto pts = readPlyPoints(dir / "extra.ply");
  ASSERT_EQ(pts.size(), 1u);
  EXPECT_EQ(pts[0], Eigen::Vector3f(x, y, z));
}

// Headers that lie about their data are errors naming the file, before any allocation.
TEST(PlyIo, HeadersThatDoNotFitTheDataAreErrorsNamingTheFile) {
  const fs::path dir = freshDir("ply_bad");
  fs::create_directories(dir);
  auto expectError = [&](const std::string& name, const std::string& header,
                         const std::string& needle) {
    std::ofstream(dir / name, std::ios::binary) << header << std::string(12, '\0');
    try {
      readPlyPoints(dir / name);
      FAIL() << name << " was accepted";
    } catch (const std::exception& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(name), std::string::npos) << what;
      EXPECT_NE(what.find(needle), std::string::npos) << what;
    }
  };
  const std::string xyz = "property float x\nproperty float y\nproperty float z\nend_header\n";
  expectError("huge.ply",
              "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n" + xyz,
              "truncated");
  expectError("word.ply", "ply\nformat binary_little_endian 1.0\nelement vertex abc\n" + xyz,
              "element vertex");
  expectError(
      "face.ply",
      "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty float a\nelement vertex 1\n" +
          xyz,
      "element face");
}

}  // namespace
}  // namespace fvp::host
