#include "fvp/host/report/session_report.h"

#include <iomanip>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/report/view_overlay.h"

namespace fvp::host {
nlohmann::json writeSessionOverlays(const MappingSession& session, const nlohmann::json& sizing,
                                    int first_view, std::optional<int> cluster,
                                    const std::function<cv::Mat(int view)>& image_of,
                                    const std::filesystem::path& out_dir,
                                    const std::optional<std::string>& first_view_reason) {
  // Session view -> the labels of the kept detections it sized.
  std::map<int, std::vector<std::string>> sized_in;
  if (sizing.contains("sized_fruitlets")) {
    std::size_t k = 0;
    for (const auto& d : sizing["sized_fruitlets"]) {
      for (const auto& s : d.at("per_image"))
        sized_in[s.at("view").get<int>()].push_back(report::detectionLabel(true, k, cluster));
      ++k;
    }
  }
  const auto& views = session.sizingViews();
  nlohmann::json out = nlohmann::json::array();
  for (int v = 0; v < static_cast<int>(views.size()); ++v) {
    const bool first_counts = v == 0 && first_view_reason.has_value();
    if (!first_counts && !sized_in.count(v)) continue;
    const cv::Mat image = image_of(first_view + v);
    if (image.empty()) continue;
    std::string why = first_counts ? *first_view_reason : "";
    if (sized_in.count(v)) {
      why += (why.empty() ? "sized " : "; sized ");
      for (std::size_t i = 0; i < sized_in[v].size(); ++i) why += (i ? ", " : "") + sized_in[v][i];
    }
    const ViewResult& result = session.views().at(static_cast<std::size_t>(v));
    const cv::Rect crop =
        session.region()
            ? report::regionCrop(session.region()->center_m(), session.region()->radius_m(),
                                 views[v].T_world_camera, views[v].intrinsics)
            : cv::Rect();
    const cv::Mat overlay = report::drawViewOverlay(
        image, views[v].fruitlet_mask, report::overlayEllipses(sizing, v, cluster), result.tag,
        session.perception().config().tag.tag_size_m, views[v].intrinsics, crop);
    // JPEG: a trial's thirty overlays take 3 MB, not 15 as PNG.
    std::vector<unsigned char> jpeg;
    if (!cv::imencode(".jpg", overlay, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90}))
      throw std::runtime_error("overlay of view " + std::to_string(first_view + v) +
                               ": JPEG encoding failed");
    const std::string file = numberedFileName("overlays", first_view + v, "jpg");
    std::filesystem::create_directories(out_dir / "overlays");
    writeFileAtomically(out_dir / file, "view overlay",
                        std::string_view(reinterpret_cast<const char*>(jpeg.data()), jpeg.size()));
    out.push_back({{"view", first_view + v},
                   {"file", file},
                   {"why", why},
                   {"tag_detected", result.tag.has_value()}});
  }
  return out;
}

std::map<int, std::string> overlayFileOfView(const nlohmann::json& overlays) {
  std::map<int, std::string> file_of;
  for (const auto& o : overlays) file_of[o.at("view").get<int>()] = o.at("file");
  return file_of;
}

void addSessionToScene(report::ViewerScene& scene, const MappingSession& session,
                       const nlohmann::json& sizing, int first_view, std::optional<int> cluster) {
  if (const map::MapEngine* map = session.map()) scene.addFineVoxels(*map);
  scene.addMesh(session.surfaceMesh());
  if (session.region()) scene.addClusterRegion(*session.region(), cluster);
  if (session.T_world_tag())
    scene.addTag(*session.T_world_tag(), session.perception().config().tag.tag_size_m,
                 session.perception().config().tag.tag_id, cluster);
  scene.addSizing(sizing, first_view, cluster);
}

}  // namespace fvp::host
