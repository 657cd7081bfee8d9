#include "trial_viewer.h"

#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>

#include "fvp/host/core/output_directory.h"
#include "fvp/host/report/session_report.h"
#include "fvp/host/report/view_overlay.h"
#include "fvp/host/report/viewer_page.h"

namespace fvp::trials {

void ViewImages::add(int view, const cv::Mat& left_bgr) {
  if (left_bgr.empty()) return;
  // JPEG at 95: a view's 4.7 MB of pixels in about 0.3 MB; the overlay, encoded once more,
  // loses nothing visible at its scale.
  std::vector<unsigned char> jpeg;
  if (!cv::imencode(".jpg", left_bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95}))
    throw std::runtime_error("view image " + std::to_string(view) + ": JPEG encoding failed");
  jpeg_[view] = std::move(jpeg);
}

cv::Mat ViewImages::image(int view) const {
  const auto it = jpeg_.find(view);
  return it == jpeg_.end() ? cv::Mat() : cv::imdecode(it->second, cv::IMREAD_COLOR);
}

namespace {

Eigen::Isometry3d poseOf(const nlohmann::json& position, const nlohmann::json& wxyz) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(position[0].get<double>(), position[1].get<double>(),
                                    position[2].get<double>());
  T.linear() = Eigen::Quaterniond(wxyz[0].get<double>(), wxyz[1].get<double>(),
                                  wxyz[2].get<double>(), wxyz[3].get<double>())
                   .normalized()
                   .toRotationMatrix();
  return T;
}

std::optional<int> clusterOf(const nlohmann::json& entry) {
  return entry.contains("cluster") ? std::optional<int>(entry["cluster"].get<int>()) : std::nullopt;
}

}  // namespace

void writeTrialViewer(host::report::ViewerScene& scene, const nlohmann::json& result,
                      const std::optional<host::StereoIntrinsics>& intrinsics,
                      const std::filesystem::path& out_dir) {
  if (intrinsics) scene.setIntrinsics(*intrinsics);
  const std::map<int, std::string> overlay_of =
      host::overlayFileOfView(result.value("overlays", nlohmann::json::array()));
  for (const auto& v : result.at("view_log")) {
    const int view = v.at("index").get<int>();
    nlohmann::json extra = {
        {"sim_time_s", v.at("sim_time_s")},
        {"tag_detected", v.at("tag_detected")},
        {"roi_points", v.at("roi_points")},
        {"other_points", v.at("other_points")},
        {"image", overlay_of.count(view) ? overlay_of.at(view)
                                         : host::numberedFileName("views", view, "png")}};
    if (v.contains("cluster")) extra["cluster"] = v["cluster"];
    scene.addCamera(view, poseOf(v.at("position_m"), v.at("quaternion_wxyz")), std::move(extra));
  }
  int iteration = 0;
  for (const auto& p : result.at("plan_log")) {
    if (p.contains("chosen_position_m") && !p["chosen_position_m"].is_null())
      scene.addChosenCandidate(
          iteration, poseOf(p["chosen_position_m"], p["chosen_quaternion_wxyz"]),
          p.value("chosen_utility", 0.0), p.value("moved", false), clusterOf(p));
    ++iteration;
  }
  std::ostringstream subtitle;
  subtitle << std::fixed << std::setprecision(1) << "engine " << result.value("engine", "?") << ", "
           << result.value("views", 0) << " views, " << result.value("sim_time_s", 0.0)
           << " simulated s";
  if (result.contains("metrics") && result["metrics"].is_object()) {
    const nlohmann::json& m = result["metrics"];
    if (m.contains("match_percent") && m["match_percent"].is_number())
      subtitle << ", match " << m["match_percent"].get<double>() << " %";
    if (m.contains("mae_mm") && m["mae_mm"].is_number())
      subtitle << std::setprecision(2) << ", MAE " << m["mae_mm"].get<double>() << " mm";
  }
  scene.setSubtitle(subtitle.str());
  host::report::writeViewerPage(scene.toJson(), out_dir / "viewer.html");
}

}  // namespace fvp::trials
