#include "fvp/host/session/capture_sizing.h"

#include <algorithm>
#include <stdexcept>

#include <opencv2/core.hpp>

#include "fvp/host/core/interrupt.h"
#include "fvp/host/core/memory_budget.h"
#include "fvp/host/perception/capture.h"

namespace fvp::host {

namespace {

/// Files of the capture format (docs/capture-format.md) besides camera.yaml.
bool holdsCaptureFiles(const std::filesystem::path& dir) {
  for (const char* name : {"left.png", "right.png", "disparity.png", "mask.png", "roi.ply",
                           "other.ply", "ground_truth.json"})
    if (std::filesystem::exists(dir / name)) return true;
  return false;
}

}  // namespace

std::vector<std::filesystem::path> listCaptures(const std::filesystem::path& dir,
                                                std::vector<std::string>* skipped) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(dir))
    throw std::runtime_error(dir.string() + ": not a directory of captures");
  std::vector<fs::path> captures, subdirs;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_directory()) subdirs.push_back(entry.path());
  std::sort(subdirs.begin(), subdirs.end());
  for (const fs::path& sub : subdirs) {
    if (fs::exists(sub / "camera.yaml"))
      captures.push_back(sub);
    else if (holdsCaptureFiles(sub))
      throw std::runtime_error(sub.string() +
                               ": holds capture files but no camera.yaml (an incomplete "
                               "capture); complete it or move it out of the set");
    else if (skipped)
      skipped->push_back(sub.string() + ": not a capture (no camera.yaml), skipped");
  }
  if (fs::exists(dir / "camera.yaml")) {
    if (!captures.empty())
      throw std::runtime_error(dir.string() +
                               ": holds camera.yaml and capture subdirectories too (" +
                               captures.front().filename().string() +
                               ", ...): point --captures at one capture or at the set, and "
                               "remove the stray camera.yaml");
    if (skipped) skipped->clear();  // one capture: its subdirectories are none of ours
    return {dir};
  }
  if (captures.empty())
    throw std::runtime_error(dir.string() +
                             ": no capture (a directory with camera.yaml) in it; see "
                             "docs/capture-format.md");
  return captures;
}

namespace {

/// What sizing keeps of a view, bytes a pixel: its disparity (float), mask and the working
/// copies beside them (measured: ~11 MB a 1440 x 1080 view).
constexpr std::uint64_t kSizingBytesPerPixel = 8;

}  // namespace

/// The views a set's sizing keeps in memory (its mask, disparity and images, ~11 MB a view
/// of 1440 x 1080) must fit in the memory there is: refused before the first view is read,
/// where 1 000 views once failed after 285 s with nothing saved.
void checkCaptureSetFitsInMemory(const std::vector<std::filesystem::path>& dirs) {
  std::uint64_t bytes = 0;
  for (const auto& dir : dirs) {
    const StereoIntrinsics K = readCaptureIntrinsics(dir);
    bytes += kSizingBytesPerPixel * std::uint64_t(K.width_px) * std::uint64_t(K.height_px);
  }
  checkMemoryFor(bytes, std::to_string(dirs.size()) + " captures (--captures, " +
                            std::to_string(kSizingBytesPerPixel) +
                            " bytes a pixel of each view are kept for sizing)");
}

SizedCaptureSet sizeCaptures(const std::vector<std::filesystem::path>& dirs,
                             const CaptureSizingOptions& options, accel::Backend* backend,
                             const std::function<void(const std::string&)>& warn) {
  SizedCaptureSet set;
  set.session = std::make_unique<MappingSession>(options.perception, options.engine,
                                                 map::MapConfig{}, backend);
  MappingSession& session = *set.session;
  session.enableTsdf();
  for (const auto& dir : dirs) {
    throwIfInterrupted();
    const Capture capture = readCapture(dir);
    const StereoFrame frame = toStereoFrame(capture);  // its own mask and disparity as given
    PerceptionResult perceived;
    const ViewResult v = session.addView(frame, &perceived);
    const int fruitlet_px =
        perceived.fruitlet_mask.empty() ? 0 : cv::countNonZero(perceived.fruitlet_mask);
    if (fruitlet_px == 0)
      warn(dir.string() + (capture.fruitlet_mask.empty()
                               ? ": no fruitlet pixels segmented (HSV thresholds for the "
                                 "simulator's fruitlet colours; a grey or real image needs its "
                                 "own mask.png)"
                               : ": its mask.png marks no fruitlet pixel"));
    if (set.ground_truth_json.empty() && !capture.ground_truth_json.empty()) {
      set.ground_truth_json = capture.ground_truth_json;
      set.ground_truth_source = (dir / "ground_truth.json").string();
    }
    set.captures.push_back({{"capture", dir.filename().string()},
                            {"tag_detected", v.tag_detected},
                            {"fruitlet_pixels", fruitlet_px},
                            {"roi_points", v.roi_points},
                            {"dropped_disparities", v.perception.droppedDisparities()}});
  }
  const sizing::SizingConfig config = [&] {
    sizing::SizingConfig c;
    c.estimator = options.estimator;
    return c;
  }();
  if (!session.region())
    warn("no capture showed the AprilTag (" + options.perception.tag.family + " id " +
         std::to_string(options.perception.tag.tag_id) +
         ") and no region_center_m is configured: no Cluster Region, nothing mapped or sized");
  set.sized = session.sizeFruitlets(config);
  return set;
}

}  // namespace fvp::host
