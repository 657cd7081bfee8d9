#include "trial_parts.h"

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "fvp/accel/backend.h"
#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/gnuplot.h"
#include "fvp/host/eval/fruitlet_matching.h"
#include "fvp/host/map/map_config.h"
#include "fvp/host/perception/ply_io.h"
#include "fvp/host/planner/fvp_planner.h"
#include "fvp/host/planner/rvp_planner.h"
#include "fvp/host/sizing/fruitlet_sizer.h"
#include "fvp/host/tsdf/tsdf_volume.h"

namespace fvp::robot::sim {
namespace {

// Report pictures of the views: small enough that a report of 60 views stays light.
constexpr int kReportImageWidthPx = 360;

}  // namespace

std::string defaultEngine(const std::string& planner) {
  return planner == "rvp" ? "octomap" : "grid";
}

std::string defaultCacheDir() {
  if (const char* dir = std::getenv("FVP_CACHE_DIR"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return (std::filesystem::path(xdg) / "fvp").string();
  if (const char* home = std::getenv("HOME"); home && *home)
    return (std::filesystem::path(home) / ".cache" / "fvp").string();
  return (std::filesystem::temp_directory_path() / "fvp-cache").string();
}

struct TrialParts::Impl {
  Impl(const TrialOptions& options, const std::string& engine, accel::Backend* backend)
      : options(options),
        engine(engine),
        backend(backend),
        session(host::PerceptionConfig{}, engine, host::map::MapConfig{}, backend) {
    if (options.planner == "fvp") {
      const host::planner::PlannerConfig config =
          options.planner_config.empty()
              ? host::planner::PlannerConfig{}
              : host::planner::PlannerConfig::fromYamlFile(options.planner_config);
      planner = std::make_unique<host::planner::FvpPlanner>(config, options.seed);
    } else {
      const host::planner::RvpConfig config =
          options.planner_config.empty()
              ? host::planner::RvpConfig{}
              : host::planner::RvpConfig::fromYamlFile(options.planner_config);
      planner = std::make_unique<host::planner::RvpPlanner>(config, options.seed);
    }
  }

  TrialOptions options;
  std::string engine;
  accel::Backend* backend;
  host::MappingSession session;
  std::unique_ptr<host::planner::ViewPlanner> planner;
  host::tsdf::TsdfVolume tsdf;
  std::vector<host::sizing::SizingView> sizing_views;
  host::sizing::SizingConfig sizing_config;
  host::sizing::SizingResult sizing;  ///< of the last sizeAndScore
};

TrialParts::TrialParts(const TrialOptions& options, const std::string& engine,
                       accel::Backend* backend)
    : impl_(std::make_unique<Impl>(options, engine, backend)) {}

TrialParts::~TrialParts() = default;

ViewOutcome TrialParts::addView(const host::StereoFrame& frame) {
  ViewOutcome outcome;
  host::PerceptionResult perceived;
  outcome.result = impl_->session.addView(frame, &perceived);
  outcome.mapping_s = outcome.result.scan.seconds;
  // The fruitlets' TSDF from this view's ROI depth, and what sizing needs of the view.
  const cv::Mat depth =
      host::tsdf::depthFromDisparity(perceived.disparity.disparity_px, frame.intrinsics);
  outcome.tsdf_s =
      impl_->tsdf.integrate(depth, perceived.fruitlet_mask, frame.intrinsics, frame.T_world_camera)
          .seconds;
  impl_->sizing_views.push_back({perceived.fruitlet_mask, perceived.disparity.disparity_px,
                                 frame.intrinsics, frame.T_world_camera});
  return outcome;
}

host::map::MapEngine* TrialParts::map() {
  return impl_->session.map();
}

host::planner::ViewPlanner& TrialParts::planner() {
  return *impl_->planner;
}

nlohmann::json TrialParts::configJson() const {
  return {{"engine", impl_->engine}, {"clock", impl_->options.clock}};
}

void TrialParts::keepViewImage(int index, const host::StereoFrame& frame) const {
  if (frame.left_bgr.empty()) return;
  const std::filesystem::path dir = impl_->options.out_dir / "views";
  std::filesystem::create_directories(dir);
  cv::Mat small;
  const double scale = double(kReportImageWidthPx) / frame.left_bgr.cols;
  cv::resize(frame.left_bgr, small, cv::Size(), scale, scale, cv::INTER_AREA);
  std::vector<unsigned char> png;
  if (!cv::imencode(".png", small, png))
    throw std::runtime_error("view image " + std::to_string(index) + ": PNG encoding failed");
  std::ostringstream name;
  name << std::setw(3) << std::setfill('0') << index << ".png";
  host::writeFileAtomically(
      dir / name.str(), "view image",
      std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

}  // namespace fvp::robot::sim

namespace fvp::robot::sim {
namespace {

std::string fmt(double v, int precision) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(precision) << v;
  return s.str();
}

std::string fmtOrDash(const nlohmann::json& v, int precision) {
  return v.is_number() ? fmt(v.get<double>(), precision) : "-";
}

/// Top and side views of the camera path around the cluster, with the fruitlets.
void plotCameraPath(const World& world, const std::vector<Eigen::Vector3d>& path,
                    const std::filesystem::path& png) {
  std::ostringstream s;
  s << "set terminal pngcairo size 1200,560 font 'DejaVu Sans,11'\nset output '{png}'\n"
    << "set multiplot layout 1,2 title 'Camera positions (numbered in capture order) and "
       "fruitlets'\nset size ratio -1\nset grid\nset key bottom right\n";
  const auto block = [&](int a, int b) {
    std::ostringstream d;
    d << "$path << EOD\n";
    for (std::size_t i = 0; i < path.size(); ++i)
      d << path[i][a] << " " << path[i][b] << " " << i << "\n";
    d << "EOD\n$fruit << EOD\n";
    for (const auto& f : world.fruitlets()) d << f.center_m[a] << " " << f.center_m[b] << "\n";
    d << "EOD\n";
    return d.str();
  };
  const char* axis[] = {"x (m)", "y (m)", "z (m)"};
  for (const auto& [a, b, title] :
       {std::tuple{0, 1, "top view"}, std::tuple{0, 2, "side view (from the start view)"}}) {
    s << block(a, b) << "set title '" << title << "'\nset xlabel '" << axis[a] << "'\nset ylabel '"
      << axis[b] << "'\n"
      << "plot $path using 1:2 with linespoints lc rgb '#1f77b4' pt 7 ps 0.8 title 'camera', "
         "$path using 1:2:3 with labels offset 0.7,0.7 font ',8' notitle, "
         "$fruit using 1:2 with points lc rgb '#d62728' pt 7 ps 1.2 title 'fruitlets'\n";
  }
  s << "unset multiplot\n";
  host::plotWithGnuplot(s.str(), png, "camera path figure");
}

}  // namespace

void TrialParts::writeOutputs(const nlohmann::json& result, const World& world,
                              const std::vector<Eigen::Vector3d>& camera_path,
                              const std::filesystem::path& out_dir) const {
  std::filesystem::create_directories(out_dir);
  if (const host::map::MapEngine* map = impl_->session.map()) {
    map->exportCoarse(out_dir / "coarse.bt");
    map->exportFine(out_dir / "fine.ot");
  }
  if (!camera_path.empty()) plotCameraPath(world, camera_path, out_dir / "path.png");
  const auto& sz = impl_->sizing;
  host::writePlyPoints(out_dir / "surface.ply", impl_->tsdf.extractSurfacePoints());
  {
    // Clusters in distinct colours, noise grey.
    static constexpr std::array<std::array<std::uint8_t, 3>, 8> kPalette{{{228, 26, 28},
                                                                          {55, 126, 184},
                                                                          {77, 175, 74},
                                                                          {152, 78, 163},
                                                                          {255, 127, 0},
                                                                          {166, 86, 40},
                                                                          {247, 129, 191},
                                                                          {255, 255, 51}}};
    std::vector<std::array<std::uint8_t, 3>> colors;
    for (int label : sz.labels)
      colors.push_back(label < 0 ? std::array<std::uint8_t, 3>{128, 128, 128}
                                 : kPalette[label % kPalette.size()]);
    host::writePlyColoredPoints(out_dir / "clusters.ply", sz.points, colors,
                                "fvp clusters, world frame, metres; grey = noise");
  }

  std::ostringstream md;
  md << "# Trial: " << result["planner"].get<std::string>() << ", world seed " << result["seed"]
     << "\n\n"
     << "Engine `" << result["engine"].get<std::string>() << "`, backend `"
     << result["backend"].get<std::string>() << "`, status `" << result["status"].get<std::string>()
     << "`.\n\n"
     << "| views | simulated time | budget | wall time | detections | match % | MAE (mm) | "
        "MAPE (%) |\n|---|---|---|---|---|---|---|---|\n"
     << "| " << result["views"] << " | " << fmt(result["sim_time_s"], 1) << " s | "
     << fmt(result["budget_s"], 0) << " s | " << fmt(result["wall_time_s"], 1) << " s | "
     << result.value("detections", 0) << " | " << fmtOrDash(result["metrics"]["match_percent"], 1)
     << " | " << fmtOrDash(result["metrics"]["mae_mm"], 2) << " | "
     << fmtOrDash(result["metrics"]["mape_percent"], 1) << " |\n\n"
     << "## Sizes against ground truth\n\n"
     << "| fruitlet | true size (mm) | estimated (mm) | error (mm) | centre error (mm) |\n"
        "|---|---|---|---|---|\n";
  int i = 0;
  for (const auto& f : result["fruitlets"]) {
    const bool matched = f.value("matched", false);
    md << "| " << i++ << " | " << fmt(f["gt_size_mm"], 2) << " | "
       << (matched ? fmt(f["est_size_mm"], 2) : "not matched") << " | "
       << (matched ? fmt(f["est_size_mm"].get<double>() - f["gt_size_mm"].get<double>(), 2) : "-")
       << " | " << (f.contains("center_error_mm") ? fmtOrDash(f["center_error_mm"], 2) : "-")
       << " |\n";
  }
  md << "\n## Where the simulated budget went\n\n| stage | simulated s |\n|---|---|\n";
  std::map<std::string, double> charged;
  for (const auto& it : result["clock"]["iterations"])
    for (const auto& [key, value] : it.items())
      if (value.is_number()) charged[key] += value.get<double>();
  for (const auto& [stage, s] : charged) md << "| " << stage << " | " << fmt(s, 2) << " |\n";
  md << "\n## Where the wall time went\n\n| part | wall s |\n|---|---|\n";
  for (const auto& [part, s] : result["wall_breakdown_s"].items())
    md << "| " << part << " | " << fmt(s, 2) << " |\n";
  md << "\n## Counted events\n\n```json\n" << result["events"].dump(2) << "\n```\n";
  if (!camera_path.empty()) md << "\n## Camera path\n\n![camera path](path.png)\n";
  md << "\n## Captured views\n\n";
  for (std::size_t v = 0; v < camera_path.size(); ++v) {
    std::ostringstream name;
    name << std::setw(3) << std::setfill('0') << v << ".png";
    md << "![view " << v << "](views/" << name.str() << ") ";
  }
  md << "\n";
  host::writeFileAtomically(out_dir / "report.md", "trial report", md.str());
  host::writeFileAtomically(out_dir / "result.json", "trial result", result.dump(2) + "\n");
}

}  // namespace fvp::robot::sim

namespace fvp::robot::sim {

namespace {

nlohmann::json vec3(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

/// The fruitlets of result.json for one estimator: every ground-truth fruitlet with its
/// match, plus detections and metrics.
nlohmann::json scoreEstimator(const World& world, const host::sizing::SizingResult& sizing,
                              host::sizing::SizingEstimator estimator) {
  std::vector<Eigen::Vector3d> detections, truth;
  std::vector<double> est_mm, gt_mm;
  for (const auto& f : sizing.fruitlets) {
    const bool paper = estimator == host::sizing::SizingEstimator::kPaper;
    detections.push_back(paper ? f.centroid_m : f.sphere_center_m);
    est_mm.push_back(paper ? f.size_paper_mm : f.size_ours_mm);
  }
  for (const auto& f : world.fruitlets()) {
    truth.push_back(f.center_m);
    gt_mm.push_back(f.gtSizeMm());
  }
  const std::vector<int> match = host::eval::matchFruitlets(detections, truth);
  const host::eval::SizeMetrics m =
      host::eval::sizeMetrics(gt_mm, est_mm, match, detections.size());
  nlohmann::json fruitlets = nlohmann::json::array();
  for (std::size_t g = 0; g < truth.size(); ++g) {
    nlohmann::json f = {
        {"gt_center_m", vec3(truth[g])}, {"gt_size_mm", gt_mm[g]}, {"matched", match[g] >= 0}};
    if (match[g] >= 0) {
      f["est_center_m"] = vec3(detections[match[g]]);
      f["est_size_mm"] = est_mm[match[g]];
      f["center_error_mm"] = 1000.0 * (detections[match[g]] - truth[g]).norm();
      f["detection"] = match[g];
    } else {
      f["est_center_m"] = nullptr;
      f["est_size_mm"] = nullptr;
    }
    fruitlets.push_back(f);
  }
  const auto opt = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json();
  };
  return {{"fruitlets", fruitlets},
          {"detections", detections.size()},
          {"metrics",
           {{"match_percent", m.match_percent},
            {"mae_mm", opt(m.mae_mm)},
            {"mape_percent", opt(m.mape_percent)},
            {"precision_percent", opt(m.precision_percent)}}}};
}

}  // namespace

nlohmann::json TrialParts::sizeAndScore(const World& world, const std::filesystem::path&) {
  const host::map::MapEngine* map = impl_->session.map();
  const auto in_roi_voxel = [map](const Eigen::Vector3f& p) {
    if (!map) return false;
    const host::map::VoxelState s = map->fineState(p.cast<double>());
    return s.roi && s.occupancy == host::map::VoxelClass::kOccupied;
  };
  impl_->sizing = host::sizing::sizeFruitlets(
      impl_->sizing_views, impl_->tsdf.extractSurfacePoints(), in_roi_voxel, impl_->sizing_config);
  const auto& sz = impl_->sizing;
  nlohmann::json out = scoreEstimator(world, sz, impl_->sizing_config.estimator);
  const auto other = impl_->sizing_config.estimator == host::sizing::SizingEstimator::kOurs
                         ? host::sizing::SizingEstimator::kPaper
                         : host::sizing::SizingEstimator::kOurs;
  const nlohmann::json alternative = scoreEstimator(world, sz, other);
  out["sizing_estimator"] = host::sizing::toString(impl_->sizing_config.estimator);
  out[std::string("fruitlets_") + host::sizing::toString(other) + "_sizing"] =
      alternative["fruitlets"];
  out[std::string("metrics_") + host::sizing::toString(other) + "_sizing"] = alternative["metrics"];
  nlohmann::json detections = nlohmann::json::array();
  for (const auto& f : sz.fruitlets) {
    nlohmann::json per_image = nlohmann::json::array();
    for (const auto& s : f.per_image)
      per_image.push_back({{"view", s.view},
                           {"size_paper_mm", s.size_paper_mm},
                           {"size_ours_mm", s.size_ours_mm},
                           {"minor_axis_px", s.minor_axis_px},
                           {"max_disparity_px", s.max_disparity_px},
                           {"visible_fraction", s.visible_fraction},
                           {"touches_border", s.touches_border},
                           {"shared_segment", s.shared_segment},
                           {"axis_ratio", s.axis_ratio}});
    detections.push_back({{"center_m", vec3(f.center_m)},
                          {"size_mm", f.size_mm},
                          {"centroid_m", vec3(f.centroid_m)},
                          {"sphere_center_m", vec3(f.sphere_center_m)},
                          {"size_paper_mm", f.size_paper_mm},
                          {"size_ours_mm", f.size_ours_mm},
                          {"points", f.points},
                          {"per_image", per_image}});
  }
  out["sized_fruitlets"] = detections;
  out["sizing_stats"] = {{"surface_points", sz.surface_points},
                         {"in_roi_points", sz.in_roi_points},
                         {"inlier_points", sz.inlier_points},
                         {"tsdf_blocks", impl_->tsdf.blockCount()},
                         {"tsdf_bytes", impl_->tsdf.memoryBytes()},
                         {"events",
                          {{"small_clusters", sz.events.small_clusters},
                           {"invalid_disparity_windows", sz.events.invalid_disparity_windows},
                           {"saturated_windows", sz.events.saturated_windows},
                           {"not_visible", sz.events.not_visible},
                           {"single_image_fruitlets", sz.events.single_image_fruitlets},
                           {"unsized_clusters", sz.events.unsized_clusters},
                           {"failed_sphere_fits", sz.events.failed_sphere_fits}}}};
  return out;
}

}  // namespace fvp::robot::sim
