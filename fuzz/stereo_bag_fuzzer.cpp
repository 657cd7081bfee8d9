// readStereoBag (ros/src/stereo_bag.cpp) on the input as a ROS bag: rosbag's reader underneath,
// then the pairing, camera infos, tf and image checks. What it gives must be a usable capture:
// positive focal lengths and baseline, images of the camera info's size, a rigid finite pose,
// a mask and disparity of the left image's size. C++17, as ROS 1's headers are.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "fuzz_support.h"
#include "fvp/ros/stereo_bag.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = fvp::fuzz::scratchDir() / "input.bag";
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  try {
    fvp::ros::readStereoBag(path, fvp::ros::StereoBagTopics{}, [](fvp::host::Capture&& c) {
      const auto& K = c.intrinsics;
      const cv::Size image(K.width_px, K.height_px);
      const bool ok =
          K.fx_px > 0.0 && K.fy_px > 0.0 && K.baseline_m > 0.0 && c.left_bgr.size() == image &&
          c.right_bgr.size() == image && c.left_bgr.type() == CV_8UC3 &&
          c.T_world_camera.matrix().allFinite() &&
          (c.T_world_camera.linear().transpose() * c.T_world_camera.linear()).isIdentity(1e-6) &&
          (c.fruitlet_mask.empty() || c.fruitlet_mask.size() == image) &&
          (c.disparity_px.empty() || c.disparity_px.size() == image);
      if (!ok) {
        std::fprintf(stderr, "fvp fuzz: gave a capture that is not usable (%d x %d)\n", K.width_px,
                     K.height_px);
        std::abort();
      }
    });
  } catch (const std::exception&) {
    // Rejected (rosbag's and tf2's exceptions are std::runtime_errors named by the reader).
  }
  return 0;
}
