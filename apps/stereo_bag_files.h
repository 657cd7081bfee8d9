// Stereo bags in the CLI (docs/ros.md): `fvp size --bag` and `fvp capture --bag`. In a build
// without the ROS layer (FVP_WITH_ROS) each says so and fails.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

namespace fvp::host {
struct StereoFrame;
}

namespace fvp::apps {

/// Whether this fvp was built with the ROS layer.
bool builtWithRos();

/// Writes the capture set in captures_dir (listCaptures' order) as a stereo bag.
void writeCaptureSetAsBag(const std::filesystem::path& captures_dir,
                          const std::filesystem::path& bag);

/// Records a trial's frames as a stereo bag (fvp run --bag), each stamped 1 s + its simulated
/// time (tf reads a stamp of 0 as "the latest"), and at the end the trial's RViz markers (its
/// views, camera path and sized detections); written under a temporary name and renamed by
/// finish(), so a bag is there whole or not at all.
class TrialBagRecorder {
 public:
  explicit TrialBagRecorder(const std::filesystem::path& bag);
  ~TrialBagRecorder();
  /// What the trial calls with each frame (trials::TrialOptions::on_frame).
  void add(const host::StereoFrame& frame, double sim_time_s);
  /// Writes the markers of the trial's result.json object (its sized and dropped detections,
  /// per cluster in a tour) stamped at its end, closes the bag and renames it into place;
  /// returns the pairs written.
  std::size_t finish(const nlohmann::json& result);

 private:
  struct Writer;
  std::unique_ptr<Writer> writer_;
};

/// Writes the bag's stereo pairs as captures out_dir/000000, 000001, ... (read into
/// out_dir.tmp, then swapped in whole) and returns how many; what it skipped is printed, and
/// warned on stderr when it skipped anything.
std::size_t extractBagCaptures(const std::filesystem::path& bag, const std::string& stereo_ns,
                               const std::string& world_frame,
                               const std::filesystem::path& out_dir);

}  // namespace fvp::apps
