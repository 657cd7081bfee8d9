#include "fvp/host/report/capture_set_report.h"

#include <map>
#include <optional>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/eval/sizing_score.h"
#include "fvp/host/perception/ply_io.h"
#include "fvp/host/report/session_report.h"
#include "fvp/host/report/viewer_page.h"

namespace fvp::host {

namespace {

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
  checkCaptureSetFitsInMemory(dirs);
  std::optional<OutputDirectoryLock> lock;  // one writer, for the whole command
  if (!options.out_dir.empty()) {
    prepareOutputDirectory(options.out_dir, "sizing output directory");
    lock.emplace(options.out_dir, "sizing output directory");
    checkOutputPaths(options.out_dir, "sizing output directory", kOutputs, {"overlays"});
    removeStaleOutputs(options.out_dir, kOutputs, {"overlays"});
  }
  const SizedCaptureSet set = sizeCaptures(dirs, options, backend, warn);
  const MappingSession& session = *set.session;
  const sizing::SizingResult& sized = set.sized;
  std::vector<eval::GroundTruthFruitlet> truth;
  if (!set.ground_truth_json.empty())
    truth = eval::groundTruthFromJson(set.ground_truth_json, set.ground_truth_source);

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
  nlohmann::json details = eval::sizingDetails(sized);
  eval::addTagFrame(details, session.T_world_tag(), session.appliedAnchorShift_m());
  for (const auto& [key, value] : details.items()) out[key] = value;
  out["captures"] = set.captures;
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
