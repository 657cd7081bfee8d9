// The stereo_bag harness's seeds (run by hand, outputs committed; docs/fuzzing.md): small bags
// written by writeStereoBag. Usage: fvp_fuzz_make_bag_seeds DIR. C++17, as ROS 1's headers are.
#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <vector>

#include "fvp/ros/stereo_bag.h"

namespace {

fvp::host::Capture tiny(int i, bool extras) {
  fvp::host::Capture c;
  c.intrinsics.width_px = 8;
  c.intrinsics.height_px = 4;
  c.intrinsics.fx_px = c.intrinsics.fy_px = 10.0;
  c.intrinsics.cx_px = 3.5;
  c.intrinsics.cy_px = 1.5;
  c.intrinsics.baseline_m = 0.06;
  c.left_bgr = cv::Mat(4, 8, CV_8UC3, cv::Scalar(10 * i, 20, 30));
  c.right_bgr = cv::Mat(4, 8, CV_8UC3, cv::Scalar(30, 20 * i, 10));
  if (extras) {
    c.fruitlet_mask = cv::Mat(4, 8, CV_8U, cv::Scalar(255));
    c.disparity_px = cv::Mat(4, 8, CV_32F, cv::Scalar(1.5));
  }
  c.T_world_camera = Eigen::Translation3d(0.1 * i, 0.0, 1.0) *
                     Eigen::AngleAxisd(0.5 * i, Eigen::Vector3d::UnitY());
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  fvp::ros::writeStereoBag(dir / "two_pairs.bag", {tiny(0, false), tiny(1, false)},
                           fvp::ros::StereoBagTopics{});
  fvp::ros::writeStereoBag(dir / "pair_with_mask_and_disparity.bag", {tiny(2, true)},
                           fvp::ros::StereoBagTopics{});
  return 0;
}
