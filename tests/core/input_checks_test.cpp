#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>

#include "fvp/host/core/input_checks.h"
#include "fvp/host/core/yaml_config.h"

using namespace fvp::host;

namespace {

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(InputChecks, TheDefaultCameraPasses) {
  EXPECT_NO_THROW(checkIntrinsics(StereoIntrinsics{}, "camera"));
}

TEST(InputChecks, FocalLengthsOutsideThePlausibleFieldOfViewFail) {
  StereoIntrinsics K;
  // 170 degrees over 1440 px: f = 720 / tan(85 deg) = 62.99 px; 1 degree: 82505 px.
  K.fx_px = 63.5;
  EXPECT_NO_THROW(checkIntrinsics(K, "cam"));
  K.fx_px = 62.0;
  EXPECT_NE(errorOf([&] { checkIntrinsics(K, "cam"); }).find("cam: field 'fx': expected"),
            std::string::npos);
  K.fx_px = 0.004;  // metres, not pixels
  EXPECT_NE(errorOf([&] { checkIntrinsics(K, "cam"); }).find("got 0.004"), std::string::npos);
  K.fx_px = 82000.0;
  EXPECT_NO_THROW(checkIntrinsics(K, "cam"));
  K.fx_px = 83000.0;
  EXPECT_FALSE(errorOf([&] { checkIntrinsics(K, "cam"); }).empty());
  K.fx_px = std::nan("");
  EXPECT_FALSE(errorOf([&] { checkIntrinsics(K, "cam"); }).empty());
}

TEST(InputChecks, ImageSidesPrincipalPointAndBaselineAreBounded) {
  const auto fails = [](auto change) {
    StereoIntrinsics K;
    change(K);
    return !errorOf([&] { checkIntrinsics(K, "cam"); }).empty();
  };
  EXPECT_TRUE(fails([](StereoIntrinsics& K) { K.width_px = 2; }));
  EXPECT_TRUE(fails([](StereoIntrinsics& K) { K.height_px = kMaxImageSidePx + 1; }));
  EXPECT_TRUE(fails([](StereoIntrinsics& K) { K.cx_px = -1.0; }));
  EXPECT_TRUE(fails([](StereoIntrinsics& K) { K.cy_px = 1081.0; }));
  EXPECT_TRUE(fails([](StereoIntrinsics& K) { K.baseline_m = 0.0; }));
  EXPECT_TRUE(fails([](StereoIntrinsics& K) { K.baseline_m = INFINITY; }));
  EXPECT_FALSE(fails([](StereoIntrinsics& K) {
    K.width_px = K.height_px = kMinImageSidePx;
    K.cx_px = K.cy_px = 16.0;
    K.fx_px = K.fy_px = 30.0;
  }));
}

TEST(InputChecks, PosesMustBeFiniteRotationsNearTheOrigin) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  EXPECT_NO_THROW(checkPose(T, "pose", "T"));
  T.translation().x() = NAN;
  EXPECT_NE(errorOf([&] { checkPose(T, "pose", "T"); }).find("pose: field 'T'"), std::string::npos);
  T.translation() = Eigen::Vector3d(2000, 0, 0);
  EXPECT_FALSE(errorOf([&] { checkPose(T, "pose", "T"); }).empty());
  T.setIdentity();
  T.linear()(0, 0) = -1.0;  // a reflection
  EXPECT_FALSE(errorOf([&] { checkPose(T, "pose", "T"); }).empty());
}

TEST(YamlScalars, NonFiniteNumbersAndNonScalarsAreRefusedWithTheirText) {
  const YAML::Node doc = YAML::Load("a: .nan\nb: -.inf\nc: [1]\nd: 1.5\ne: x\n");
  EXPECT_EQ(errorOf([&] { readScalar<double>(doc["a"], "f: key 'a'", "a number"); }),
            "f: key 'a': expected a number (finite), got '.nan'");
  EXPECT_FALSE(errorOf([&] { readScalar<double>(doc["b"], "w", "a number"); }).empty());
  EXPECT_EQ(errorOf([&] { readScalar<double>(doc["c"], "w", "a number"); }),
            "w: expected a number");
  EXPECT_EQ(readScalar<double>(doc["d"], "w", "a number"), 1.5);
  EXPECT_EQ(errorOf([&] { readScalar<int>(doc["d"], "w", "an integer"); }),
            "w: expected an integer, got '1.5'");
  EXPECT_EQ(errorOf([&] { readScalar<int>(doc["e"], "w", "an integer"); }),
            "w: expected an integer, got 'x'");
}

TEST(YamlScalars, ADirectoryIsNotAConfigFile) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / "fvp_yaml_dir.yaml";
  std::filesystem::create_directories(dir);
  EXPECT_EQ(errorOf([&] { readYamlMapping(dir, "cfg"); }),
            "cfg: not a readable file (a directory)");
}

}  // namespace
