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
#include "fvp/host/eval/sizing_score.h"
#include "fvp/host/map/map_config.h"
#include "fvp/host/perception/ply_io.h"
#include "fvp/host/planner/planner_registry.h"
#include "fvp/host/sizing/fruitlet_sizer.h"
#include "fvp/host/tsdf/tsdf_volume.h"

namespace fvp::trials {
// The simulator's parts and the arm, by their short names.
using namespace fvp::robot;
using namespace fvp::robot::sim;
namespace {

// Report pictures of the views: small enough that a report of 60 views stays light.
constexpr int kReportImageWidthPx = 360;

}  // namespace

std::string defaultEngine(const std::string& planner) {
  return host::planner::PlannerRegistry::instance().at(planner).default_engine;
}

std::string defaultCacheDir() {
  if (const char* dir = std::getenv("FVP_CACHE_DIR"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return (std::filesystem::path(xdg) / "fvp").string();
  if (const char* home = std::getenv("HOME"); home && *home)
    return (std::filesystem::path(home) / ".cache" / "fvp").string();
  return (std::filesystem::temp_directory_path() / "fvp-cache").string();
}

WorkspaceTree loadWorkspaceTree(const ArmModel& arm,
                                const std::function<void(const std::string&)>& warn) {
  std::ostringstream log;
  WorkspaceTree tree = WorkspaceTree::loadOrBuild(arm, log);
  std::istringstream lines(log.str());
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("warning: ", 0) == 0) warn(line.substr(9));
  return tree;
}

struct TrialParts::Impl {
  Impl(const TrialOptions& options, const std::string& engine, accel::Backend* backend,
       const host::PerceptionConfig& perception, std::uint64_t planner_seed)
      : options(options),
        engine(engine),
        backend(backend),
        map_config(host::planner::plannerMapConfig(options.planner, engine)),
        session(perception, engine, map_config, backend) {
    session.enableTsdf();
    planner = host::planner::createPlanner(options.planner, options.planner_config, planner_seed,
                                           backend);
  }

  TrialOptions options;
  std::string engine;
  accel::Backend* backend;
  host::map::MapConfig map_config;  ///< the maps' config, as the session got it
  host::MappingSession session;
  std::unique_ptr<host::planner::ViewPlanner> planner;
  host::sizing::SizingConfig sizing_config;
  host::sizing::SizingResult sizing;  ///< of the last sizeAndScore
};

TrialParts::TrialParts(const TrialOptions& options, const std::string& engine,
                       accel::Backend* backend, const host::PerceptionConfig& perception,
                       std::uint64_t planner_seed)
    : impl_(std::make_unique<Impl>(options, engine, backend, perception, planner_seed)) {}

TrialParts::~TrialParts() = default;

ViewOutcome TrialParts::addView(const host::StereoFrame& frame) {
  ViewOutcome outcome;
  outcome.result = impl_->session.addView(frame);
  outcome.mapping_s = outcome.result.scan.seconds;
  outcome.tsdf_s = outcome.result.tsdf_s;
  return outcome;
}

host::map::MapEngine* TrialParts::map() {
  return impl_->session.map();
}

host::MappingSession& TrialParts::session() {
  return impl_->session;
}

const host::sizing::SizingConfig& TrialParts::sizingConfig() const {
  return impl_->sizing_config;
}

host::planner::ViewPlanner& TrialParts::planner() {
  return *impl_->planner;
}

nlohmann::json TrialParts::configJson() const {
  return {{"engine", impl_->engine},
          {"clock", impl_->options.clock},
          {"fine_map_extent", host::map::toString(impl_->map_config.fine_map_extent)},
          {"stop", impl_->options.stop},
          {"sizing",
           {{"estimator", host::sizing::toString(impl_->sizing_config.estimator)},
            {"min_support_area_fraction", impl_->sizing_config.min_support_area_fraction}}}};
}

std::vector<host::eval::GroundTruthFruitlet> groundTruthOf(const World& world,
                                                           const std::vector<int>& indices) {
  std::vector<host::eval::GroundTruthFruitlet> truth;
  for (const int i : indices) {
    const Fruitlet& f = world.fruitlets().at(static_cast<std::size_t>(i));
    truth.push_back({f.center_m, f.gtSizeMm()});
  }
  return truth;
}

void keepViewImage(const std::filesystem::path& out_dir, int index,
                   const host::StereoFrame& frame) {
  if (frame.left_bgr.empty()) return;
  const std::filesystem::path dir = out_dir / "views";
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

}  // namespace fvp::trials

namespace fvp::trials {
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
  s << "set terminal pngcairo size 1200,560 font 'DejaVu Sans,11'\n"
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

/// result.json first (nothing after it, a full disk or a missing gnuplot, can lose it), then
/// the coarse map and the camera-path figure; a figure that cannot be drawn becomes a
/// warning in result (written again). Returns whether path.png was drawn.
bool writeResultMapAndPath(nlohmann::json& result, const World& world,
                           const host::map::MapEngine* map,
                           const std::vector<Eigen::Vector3d>& camera_path,
                           const std::filesystem::path& out_dir,
                           const std::function<void(const std::string&)>& warn) {
  std::filesystem::create_directories(out_dir);
  const auto write_result = [&] {
    host::writeFileAtomically(out_dir / "result.json", "trial result", result.dump(2) + "\n");
  };
  write_result();
  if (map) map->exportCoarse(out_dir / "coarse.bt");
  if (camera_path.empty()) return false;
  try {
    plotCameraPath(world, camera_path, out_dir / "path.png");
    return true;
  } catch (const std::exception& e) {
    const std::string text = std::string("path.png not drawn: ") + e.what();
    result["warnings"].push_back(text);
    if (warn) warn(text);
    write_result();
    return false;
  }
}

/// The report's wall times, counted events, camera path and warnings.
void appendReportTail(std::ostringstream& md, const nlohmann::json& result, bool path_drawn) {
  md << "\n## Where the wall time went\n\n| part | wall s |\n|---|---|\n";
  for (const auto& [part, s] : result["wall_breakdown_s"].items())
    md << "| " << part << " | " << fmt(s, 2) << " |\n";
  md << "\n## Counted events\n\n```json\n" << result["events"].dump(2) << "\n```\n";
  if (path_drawn) md << "\n## Camera path\n\n![camera path](path.png)\n";
  if (!result["warnings"].empty()) {
    md << "\n## Warnings\n\n";
    for (const auto& w : result["warnings"]) md << "- " << w.get<std::string>() << "\n";
  }
}

}  // namespace

const std::vector<std::string>& TrialParts::clusterFiles() {
  static const std::vector<std::string> files = {"fine.ot", "surface.ply", "mesh.ply",
                                                 "clusters.ply"};
  return files;
}

void TrialParts::writeClusterFiles(const std::filesystem::path& dir) const {
  std::filesystem::create_directories(dir);
  if (const host::map::MapEngine* map = impl_->session.map()) map->exportFine(dir / "fine.ot");
  const auto& sz = impl_->sizing;
  host::writePlyPoints(dir / "surface.ply", impl_->session.surfacePoints());
  const host::tsdf::TriangleMesh mesh = impl_->session.surfaceMesh();
  host::writePlyMesh(dir / "mesh.ply", mesh.vertices_m, mesh.triangles,
                     "fvp TSDF mesh (marching cubes), world frame, metres");
  host::writePlyColoredPoints(dir / "clusters.ply", sz.points,
                              host::sizing::clusterColours(sz.labels),
                              "fvp clusters, world frame, metres; grey = noise");
}

const std::vector<std::string>& TrialParts::outputFiles() {
  static const std::vector<std::string> files = {"result.json",  "report.md",   "coarse.bt",
                                                 "fine.ot",      "surface.ply", "mesh.ply",
                                                 "clusters.ply", "path.png"};
  return files;
}

void TrialParts::writeOutputs(nlohmann::json& result, const World& world,
                              const std::vector<Eigen::Vector3d>& camera_path,
                              const std::filesystem::path& out_dir,
                              const std::function<void(const std::string&)>& warn) const {
  const bool path_drawn =
      writeResultMapAndPath(result, world, impl_->session.map(), camera_path, out_dir, warn);
  writeClusterFiles(out_dir);
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
  appendReportTail(md, result, path_drawn);
  md << "\n## Captured views\n\n";
  for (std::size_t v = 0; v < camera_path.size(); ++v) {
    std::ostringstream name;
    name << std::setw(3) << std::setfill('0') << v << ".png";
    md << "![view " << v << "](views/" << name.str() << ") ";
  }
  md << "\n";
  host::writeFileAtomically(out_dir / "report.md", "trial report", md.str());
}

void writeTreeOutputs(nlohmann::json& result, const World& world, const host::map::MapEngine* map,
                      const std::vector<Eigen::Vector3d>& camera_path,
                      const std::filesystem::path& out_dir,
                      const std::function<void(const std::string&)>& warn) {
  const bool path_drawn = writeResultMapAndPath(result, world, map, camera_path, out_dir, warn);
  const nlohmann::json& m = result["metrics"];
  const double minutes = result.value("sim_time_s", 0.0) / 60.0;
  std::size_t matched = 0;
  for (const auto& f : result["fruitlets"]) matched += f.value("matched", false);
  std::ostringstream md;
  md << "# Tree trial: " << result["planner"].get<std::string>() << ", world seed "
     << result["seed"] << "\n\n"
     << "Engine `" << result["engine"].get<std::string>() << "`, backend `"
     << result["backend"].get<std::string>() << "`, " << result["clusters"].size()
     << " clusters, stop rule `" << result["stop"].value("rule", "?") << "` (cap "
     << fmt(result["budget_s"], 0) << " s a cluster).\n\n"
     << "| views | simulated time | fruitlets sized / min | detections | match % | MAE (mm) | "
        "MAPE (%) | precision % |\n|---|---|---|---|---|---|---|---|\n"
     << "| " << result["views"] << " | " << fmt(result["sim_time_s"], 1) << " s | "
     << (minutes > 0 ? fmt(matched / minutes, 2) : "-") << " | " << result.value("detections", 0)
     << " | " << fmtOrDash(m["match_percent"], 1) << " | " << fmtOrDash(m["mae_mm"], 2) << " | "
     << fmtOrDash(m["mape_percent"], 1) << " | " << fmtOrDash(m["precision_percent"], 1)
     << " |\n\n## Clusters, in the order visited\n\n"
     << "| cluster | tag | status | views | simulated s | stop | fruitlets | matched | "
        "detections | MAE (mm) |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : result["clusters"]) {
    std::size_t c_matched = 0;
    if (c.contains("fruitlets"))
      for (const auto& f : c["fruitlets"]) c_matched += f.value("matched", false);
    const bool ran = c.contains("views");
    md << "| " << c["index"] << " | " << c["tag_id"] << " | " << c.value("status", "?") << " | "
       << (ran ? std::to_string(c["views"].get<int>()) : "-") << " | "
       << (ran ? fmt(c["sim_time_s"], 1) : "-") << " | " << c.value("stop_reason", "-") << " | "
       << c["gt_fruitlets"] << " | " << c_matched << " | " << c.value("detections", 0) << " | "
       << (c.contains("metrics") ? fmtOrDash(c["metrics"]["mae_mm"], 2) : "-") << " |\n";
  }
  md << "\nBetween clusters the arm spent " << fmt(result["tour"]["transit_sim_s"], 1)
     << " simulated s moving. Each cluster's fine map, TSDF surface and clusters are in "
        "`cluster_K/`.\n\n## Sizes against ground truth\n\n"
     << "| cluster | true size (mm) | estimated (mm) | error (mm) |\n|---|---|---|---|\n";
  for (const auto& f : result["fruitlets"]) {
    const bool hit = f.value("matched", false);
    md << "| " << f["cluster"] << " | " << fmt(f["gt_size_mm"], 2) << " | "
       << (hit ? fmt(f["est_size_mm"], 2) : "not matched") << " | "
       << (hit ? fmt(f["est_size_mm"].get<double>() - f["gt_size_mm"].get<double>(), 2) : "-")
       << " |\n";
  }
  appendReportTail(md, result, path_drawn);
  host::writeFileAtomically(out_dir / "report.md", "trial report", md.str());
}

}  // namespace fvp::trials

namespace fvp::trials {

nlohmann::json TrialParts::sizeAndScore(const World& world,
                                        const std::vector<int>& fruitlet_indices) {
  impl_->sizing = impl_->session.sizeFruitlets(impl_->sizing_config);
  const std::vector<host::eval::GroundTruthFruitlet> truth = groundTruthOf(world, fruitlet_indices);
  nlohmann::json out =
      host::eval::scoreBothEstimators(impl_->sizing, truth, impl_->sizing_config.estimator);
  // The details object must outlive the loop (items() of a temporary would dangle).
  const nlohmann::json details = host::eval::sizingDetails(impl_->sizing);
  for (const auto& [key, value] : details.items()) out[key] = value;
  // No TSDF when no view ever saw the tag (nothing was sized then).
  const host::tsdf::TsdfVolume* tsdf = impl_->session.tsdf();
  out["sizing_stats"]["tsdf_blocks"] = tsdf ? tsdf->blockCount() : 0;
  out["sizing_stats"]["tsdf_bytes"] = tsdf ? tsdf->memoryBytes() : 0;
  out["sizing_stats"]["tsdf_bytes_per_block"] =
      tsdf && tsdf->blockCount() ? double(tsdf->memoryBytes()) / tsdf->blockCount() : 0.0;
  return out;
}

}  // namespace fvp::trials
