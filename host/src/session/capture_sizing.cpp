#include "fvp/host/session/capture_sizing.h"

#include <algorithm>
#include <map>
#include <optional>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/interrupt.h"
#include "fvp/host/core/memory_budget.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/eval/sizing_score.h"
#include "fvp/host/perception/capture.h"
#include "fvp/host/perception/ply_io.h"
#include "fvp/host/report/viewer_page.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/host/session/session_report.h"

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

/// The views a set's sizing keeps in memory (its mask, disparity and images, ~11 MB a view
/// of 1440 x 1080) must fit in the memory there is: refused before the first view is read,
/// where 1 000 views once failed after 285 s with nothing saved.
void checkSetFitsInMemory(const std::vector<std::filesystem::path>& dirs) {
  std::uint64_t bytes = 0;
  for (const auto& dir : dirs) {
    const StereoIntrinsics K = readCaptureIntrinsics(dir);
    bytes += kSizingBytesPerPixel * std::uint64_t(K.width_px) * std::uint64_t(K.height_px);
  }
  checkMemoryFor(bytes, std::to_string(dirs.size()) + " captures (--captures, " +
                            std::to_string(kSizingBytesPerPixel) +
                            " bytes a pixel of each view are kept for sizing)");
}

/// The overlays of the views that sized fruitlets (their left.png read again) and
/// viewer.html: the set's maps, mesh and detections, and a camera per capture.
void writeSetViewer(const MappingSession& session, nlohmann::json& out,
                    const std::filesystem::path& captures_dir,
                    const std::vector<std::filesystem::path>& dirs,
                    const std::filesystem::path& out_dir) {
  const auto left_image = [&](int view) {
    return cv::imread((dirs.at(static_cast<std::size_t>(view)) / "left.png").string(),
                      cv::IMREAD_COLOR);
  };
  out["overlays"] = writeSessionOverlays(session, out, 0, std::nullopt, left_image, out_dir);
  writeFileAtomically(out_dir / "fruitlets.json", "fruitlets", out.dump(2) + "\n");
  const std::map<int, std::string> overlay_of = overlayFileOfView(out["overlays"]);
  report::ViewerScene scene("Capture set: " + captures_dir.lexically_normal().string(),
                            std::to_string(dirs.size()) + " captures, " +
                                std::to_string(out["sized_fruitlets"].size()) + " fruitlets sized");
  addSessionToScene(scene, session, out, 0, std::nullopt);
  const auto& views = session.sizingViews();
  for (std::size_t v = 0; v < views.size(); ++v) {
    nlohmann::json extra = {{"capture", dirs[v].filename().string()},
                            {"tag_detected", session.views()[v].tag_detected},
                            {"roi_points", session.views()[v].roi_points},
                            {"other_points", session.views()[v].other_points}};
    if (const auto it = overlay_of.find(int(v)); it != overlay_of.end())
      extra["image"] = it->second;
    scene.addCamera(int(v), views[v].T_world_camera, std::move(extra));
  }
  if (!views.empty()) scene.setIntrinsics(views.front().intrinsics);
  report::writeViewerPage(scene.toJson(), out_dir / "viewer.html");
}

}  // namespace

nlohmann::json sizeCaptureSet(const std::filesystem::path& captures_dir,
                              const CaptureSizingOptions& options, accel::Backend* backend) {
  std::vector<std::string> warnings;
  const auto warn = [&](const std::string& text) {
    warnings.push_back(text);
    if (options.on_warning) options.on_warning(text);
  };
  std::vector<std::string> skipped;
  const std::vector<std::filesystem::path> dirs = listCaptures(captures_dir, &skipped);
  for (const std::string& s : skipped) warn(s);
  static const std::vector<std::string> kOutputs = {"fruitlets.json", "surface.ply", "mesh.ply",
                                                    "clusters.ply", "viewer.html"};
  checkSetFitsInMemory(dirs);
  std::optional<OutputDirectoryLock> lock;  // one writer, for the whole command
  if (!options.out_dir.empty()) {
    prepareOutputDirectory(options.out_dir, "sizing output directory");
    lock.emplace(options.out_dir, "sizing output directory");
    checkOutputPaths(options.out_dir, "sizing output directory", kOutputs, {"overlays"});
    removeStaleOutputs(options.out_dir, kOutputs, {"overlays"});
  }
  MappingSession session(options.perception, options.engine, map::MapConfig{}, backend);
  session.enableTsdf();
  std::string ground_truth, ground_truth_source;
  nlohmann::json views = nlohmann::json::array();
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
    if (ground_truth.empty() && !capture.ground_truth_json.empty()) {
      ground_truth = capture.ground_truth_json;
      ground_truth_source = (dir / "ground_truth.json").string();
    }
    views.push_back({{"capture", dir.filename().string()},
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
  const sizing::SizingResult sized = session.sizeFruitlets(config);
  std::vector<eval::GroundTruthFruitlet> truth;
  if (!ground_truth.empty()) truth = eval::groundTruthFromJson(ground_truth, ground_truth_source);

  nlohmann::json out = eval::scoreBothEstimators(sized, truth, options.estimator);
  if (truth.empty()) {
    // No ground truth: no match, only what was found.
    out.erase("fruitlets");
    out.erase("metrics");
    for (auto it = out.begin(); it != out.end();)
      it = it.key().rfind("fruitlets_", 0) == 0 || it.key().rfind("metrics_", 0) == 0
               ? out.erase(it)
               : std::next(it);
  }
  // The details object must outlive the loop (items() of a temporary would dangle).
  const nlohmann::json details = eval::sizingDetails(sized);
  for (const auto& [key, value] : details.items()) out[key] = value;
  out["captures"] = views;
  out["cluster_region_found"] = session.region().has_value();
  if (session.region() && out["sized_fruitlets"].empty())
    warn("no fruitlet was sized (no surface cluster passed the sizing chain)");
  out["warnings"] = warnings;
  if (!options.out_dir.empty()) {
    // The result first: a failure writing the clouds cannot lose it.
    writeFileAtomically(options.out_dir / "fruitlets.json", "fruitlets", out.dump(2) + "\n");
    writePlyPoints(options.out_dir / "surface.ply", session.surfacePoints());
    const tsdf::TriangleMesh mesh = session.surfaceMesh();
    writePlyMesh(options.out_dir / "mesh.ply", mesh.vertices_m, mesh.triangles,
                 "fvp TSDF mesh (marching cubes), world frame, metres");
    writePlyColoredPoints(options.out_dir / "clusters.ply", sized.points,
                          sizing::clusterColours(sized.labels),
                          "fvp clusters, world frame, metres; grey = noise");
    writeSetViewer(session, out, captures_dir, dirs, options.out_dir);
  }
  return out;
}

}  // namespace fvp::host
