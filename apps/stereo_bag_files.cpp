#include "stereo_bag_files.h"

#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "fvp/host/perception/capture.h"
#include "fvp/host/session/capture_sizing.h"
#ifdef FVP_HAVE_ROS
#include "fvp/ros/stereo_bag.h"
#endif

namespace fvp::apps {

#ifdef FVP_HAVE_ROS

namespace {

/// The file that marks a captures directory as written by fvp size --bag.
constexpr const char* kBagCapturesMarker = ".fvp-bag-captures";

ros::StereoBagTopics topicsUnder(const std::string& ns, const std::string& world_frame) {
  ros::StereoBagTopics topics;
  topics.left_image = ns + "/left/image_rect_color";
  topics.right_image = ns + "/right/image_rect_color";
  topics.left_info = ns + "/left/camera_info";
  topics.right_info = ns + "/right/camera_info";
  topics.fruitlet_mask = ns + "/left/fruitlet_mask";
  topics.disparity = ns + "/disparity";
  topics.world_frame = world_frame;
  return topics;
}

}  // namespace

bool builtWithRos() {
  return true;
}

void writeCaptureSetAsBag(const std::filesystem::path& captures_dir,
                          const std::filesystem::path& bag) {
  std::vector<host::Capture> captures;
  for (const auto& dir : host::listCaptures(captures_dir))
    captures.push_back(host::readCapture(dir));
  const std::filesystem::path tmp = bag.string() + ".tmp";
  ros::writeStereoBag(tmp, captures, topicsUnder("/stereo", "world"));
  std::filesystem::rename(tmp, bag);  // a bag is there whole or not at all
}

std::size_t extractBagCaptures(const std::filesystem::path& bag, const std::string& stereo_ns,
                               const std::string& world_frame,
                               const std::filesystem::path& out_dir) {
  if (!std::filesystem::is_regular_file(bag))
    throw std::runtime_error("--bag '" + bag.string() + "': expected a ROS bag file");
  // Only a directory an earlier --bag run wrote (its marker says so) is replaced: a user's own
  // folder of that name is never deleted.
  const std::filesystem::path marker = out_dir / kBagCapturesMarker;
  if (std::filesystem::exists(out_dir) && !std::filesystem::is_empty(out_dir) &&
      !std::filesystem::exists(marker))
    throw std::runtime_error("--out: '" + out_dir.string() +
                             "' exists and fvp size --bag did not write it: move it, or choose "
                             "another --out");
  std::filesystem::remove_all(out_dir);
  std::filesystem::create_directories(out_dir);
  std::ofstream(marker) << "captures read from " << bag.string() << " by fvp size --bag\n";
  std::size_t index = 0;
  const ros::StereoBagStats stats =
      ros::readStereoBag(bag, topicsUnder(stereo_ns, world_frame), [&](host::Capture&& capture) {
        char name[24];
        std::snprintf(name, sizeof(name), "%03zu", index++);
        host::writeCapture(out_dir / name, capture);
      });
  std::cout << bag.string() << ": " << stats.pairs << " stereo pairs (" << stats.with_mask
            << " with a fruitlet mask, " << stats.with_disparity << " with a disparity) -> "
            << out_dir.string() << "; skipped: " << stats.unpaired_images << " unpaired images, "
            << stats.without_pose << " pairs without a pose in '" << world_frame << "', "
            << stats.without_info << " pairs before the camera infos\n";
  if (stats.pairs == 0)
    throw std::runtime_error("--bag '" + bag.string() + "': no stereo pair with a pose in '" +
                             world_frame + "' under " + stereo_ns);
  return stats.pairs;
}

#else

namespace {
[[noreturn]] void noRos() {
  throw std::runtime_error(
      "--bag: this fvp was built without the ROS layer (FVP_WITH_ROS; scripts/install-deps "
      "installs Debian's ROS packages)");
}
}  // namespace

bool builtWithRos() {
  return false;
}
void writeCaptureSetAsBag(const std::filesystem::path&, const std::filesystem::path&) {
  noRos();
}
std::size_t extractBagCaptures(const std::filesystem::path&, const std::string&, const std::string&,
                               const std::filesystem::path&) {
  noRos();
}

#endif

}  // namespace fvp::apps
