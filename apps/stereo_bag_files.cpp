#include "stereo_bag_files.h"

#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "fvp/host/perception/capture.h"
#include "fvp/host/perception/stereo_frame.h"
#include "fvp/host/session/capture_sizing.h"
#ifdef FVP_HAVE_ROS
#include "fvp/ros/stereo_bag.h"
#endif

namespace fvp::apps {

#ifdef FVP_HAVE_ROS

namespace {

/// The file that marks a captures directory as written by fvp size --bag.
constexpr const char* kBagCapturesMarker = ".fvp-bag-captures";

}  // namespace

bool builtWithRos() {
  return true;
}

struct TrialBagRecorder::Writer {
  std::filesystem::path bag, tmp;
  ros::StereoBagWriter writer;
  Writer(const std::filesystem::path& bag_path, const std::filesystem::path& tmp_path)
      : bag(bag_path), tmp(tmp_path), writer(tmp_path, ros::StereoBagTopics{}) {}
};

TrialBagRecorder::TrialBagRecorder(const std::filesystem::path& bag)
    : writer_(std::make_unique<Writer>(bag, bag.string() + ".tmp")) {}

TrialBagRecorder::~TrialBagRecorder() {
  if (!writer_) return;
  writer_->writer.close();
  std::error_code ignored;  // an unfinished recording (the trial failed) is not kept
  std::filesystem::remove(writer_->tmp, ignored);
}

void TrialBagRecorder::add(const host::StereoFrame& frame, double sim_time_s) {
  writer_->writer.add(host::captureOfFrame(frame), 1.0 + sim_time_s);
}

namespace {

/// A trial's detections (result.json's sized_fruitlets and unsupported_detections, each cluster's
/// in a tour) as the bag's markers draw them.
std::vector<ros::BagDetection> detectionsOf(const nlohmann::json& result) {
  std::vector<ros::BagDetection> out;
  const auto add = [&out](const nlohmann::json& part) {
    for (const auto& [key, kept] :
         {std::pair{"sized_fruitlets", true}, {"unsupported_detections", false}})
      for (const auto& f : part.value(key, nlohmann::json::array())) {
        const auto& c = f.at("center_m");
        out.push_back(
            {Eigen::Vector3d(c.at(0).get<double>(), c.at(1).get<double>(), c.at(2).get<double>()),
             f.at("size_mm").get<double>(), kept});
      }
  };
  add(result);
  for (const auto& cluster : result.value("clusters", nlohmann::json::array())) add(cluster);
  return out;
}

}  // namespace

std::size_t TrialBagRecorder::finish(const nlohmann::json& result) {
  writer_->writer.addMarkers(detectionsOf(result), 1.0 + result.value("sim_time_s", 0.0));
  writer_->writer.close();
  const std::size_t pairs = writer_->writer.pairs();
  std::filesystem::rename(writer_->tmp, writer_->bag);
  writer_.reset();
  return pairs;
}

void writeCaptureSetAsBag(const std::filesystem::path& captures_dir,
                          const std::filesystem::path& bag) {
  std::vector<host::Capture> captures;
  for (const auto& dir : host::listCaptures(captures_dir))
    captures.push_back(host::readCapture(dir));
  const std::filesystem::path tmp = bag.string() + ".tmp";
  ros::writeStereoBag(tmp, captures, ros::StereoBagTopics{});
  std::filesystem::rename(tmp, bag);  // a bag is there whole or not at all
}

std::size_t extractBagCaptures(const std::filesystem::path& bag, const std::string& stereo_ns,
                               const std::string& world_frame,
                               const std::filesystem::path& out_dir) {
  if (!std::filesystem::is_regular_file(bag))
    throw std::runtime_error("--bag '" + bag.string() + "': expected a ROS bag file");
  // Only a directory an earlier --bag run wrote (its marker says so) is replaced: a user's own
  // folder of that name is never deleted.
  if (std::filesystem::exists(out_dir) && !std::filesystem::is_empty(out_dir) &&
      !std::filesystem::exists(out_dir / kBagCapturesMarker))
    throw std::runtime_error("--out: '" + out_dir.string() +
                             "' exists and fvp size --bag did not write it: move it, or choose "
                             "another --out");
  // Read into a temporary directory, swapped in whole: a bad bag leaves earlier captures be.
  const std::filesystem::path tmp = out_dir.string() + ".tmp";
  std::filesystem::remove_all(tmp);
  std::filesystem::create_directories(tmp);
  std::size_t index = 0;
  const ros::StereoBagStats stats = ros::readStereoBag(
      bag, ros::StereoBagTopics::under(stereo_ns, world_frame), [&](host::Capture&& capture) {
        char name[24];  // six digits: name order is capture order up to a million pairs
        std::snprintf(name, sizeof(name), "%06zu", index++);
        host::writeCapture(tmp / name, capture);
      });
  std::cout << bag.string() << ": " << stats.pairs << " stereo pairs (" << stats.with_mask
            << " with a fruitlet mask, " << stats.with_disparity << " with a disparity) -> "
            << out_dir.string() << "; skipped: " << stats.unpaired_images << " unpaired images, "
            << stats.without_pose << " pairs without a pose in '" << world_frame << "', "
            << stats.without_info << " pairs before the camera infos\n";
  if (stats.pairs == 0) {
    std::filesystem::remove_all(tmp);
    throw std::runtime_error("--bag '" + bag.string() + "': no stereo pair with a pose in '" +
                             world_frame + "' under " + stereo_ns);
  }
  const std::size_t skipped = stats.unpaired_images + stats.without_pose + stats.without_info;
  if (skipped > 0)
    std::cerr << "fvp: warning: " << bag.string() << ": " << skipped
              << " images or pairs skipped (counted above)\n";
  if (!(std::ofstream(tmp / kBagCapturesMarker)
        << "captures read from " << bag.string() << " by fvp size --bag\n"))
    throw std::runtime_error("--out: cannot write in '" + tmp.string() + "'");
  std::filesystem::remove_all(out_dir);
  std::filesystem::rename(tmp, out_dir);
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
struct TrialBagRecorder::Writer {};
TrialBagRecorder::TrialBagRecorder(const std::filesystem::path&) {
  noRos();
}
TrialBagRecorder::~TrialBagRecorder() = default;
void TrialBagRecorder::add(const host::StereoFrame&, double) {
  noRos();
}
std::size_t TrialBagRecorder::finish(const nlohmann::json&) {
  noRos();
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
