#include "fvp/host/session/capture_sizing.h"

#include <algorithm>
#include <stdexcept>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/eval/sizing_score.h"
#include "fvp/host/perception/capture.h"
#include "fvp/host/perception/ply_io.h"
#include "fvp/host/session/mapping_session.h"

namespace fvp::host {

std::vector<std::filesystem::path> listCaptures(const std::filesystem::path& dir) {
  if (!std::filesystem::is_directory(dir))
    throw std::runtime_error(dir.string() + ": not a directory of captures");
  if (std::filesystem::exists(dir / "camera.yaml")) return {dir};
  std::vector<std::filesystem::path> out;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.is_directory() && std::filesystem::exists(entry.path() / "camera.yaml"))
      out.push_back(entry.path());
  std::sort(out.begin(), out.end());
  if (out.empty())
    throw std::runtime_error(dir.string() +
                             ": no capture (a directory with camera.yaml) in it; see "
                             "docs/capture-format.md");
  return out;
}

nlohmann::json sizeCaptureSet(const std::filesystem::path& captures_dir,
                              const CaptureSizingOptions& options, accel::Backend* backend) {
  const std::vector<std::filesystem::path> dirs = listCaptures(captures_dir);
  MappingSession session(PerceptionConfig{}, options.engine, map::MapConfig{}, backend);
  session.enableTsdf();
  std::string ground_truth, ground_truth_source;
  nlohmann::json views = nlohmann::json::array();
  for (const auto& dir : dirs) {
    const Capture capture = readCapture(dir);
    StereoFrame frame;
    frame.left_bgr = capture.left_bgr;
    frame.right_bgr = capture.right_bgr;
    frame.intrinsics = capture.intrinsics;
    frame.T_world_camera = capture.T_world_camera;
    const ViewResult v = session.addView(frame);
    if (ground_truth.empty() && !capture.ground_truth_json.empty()) {
      ground_truth = capture.ground_truth_json;
      ground_truth_source = (dir / "ground_truth.json").string();
    }
    views.push_back({{"capture", dir.filename().string()},
                     {"tag_detected", v.tag_detected},
                     {"roi_points", v.roi_points},
                     {"dropped_disparities", v.perception.droppedDisparities()}});
  }
  const sizing::SizingConfig config = [&] {
    sizing::SizingConfig c;
    c.estimator = options.estimator;
    return c;
  }();
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
  if (!options.out_dir.empty()) {
    std::filesystem::create_directories(options.out_dir);
    writePlyPoints(options.out_dir / "surface.ply", session.surfacePoints());
    const tsdf::TriangleMesh mesh = session.surfaceMesh();
    writePlyMesh(options.out_dir / "mesh.ply", mesh.vertices_m, mesh.triangles,
                 "fvp TSDF mesh (marching cubes), world frame, metres");
    writePlyColoredPoints(options.out_dir / "clusters.ply", sized.points,
                          sizing::clusterColours(sized.labels),
                          "fvp clusters, world frame, metres; grey = noise");
    writeFileAtomically(options.out_dir / "fruitlets.json", "fruitlets", out.dump(2) + "\n");
  }
  return out;
}

}  // namespace fvp::host
