#include "trial_report.h"

#include <cmath>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>
#include <stdexcept>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/cluster_region.h"
#include "fvp/host/core/gnuplot.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/report/viewer_scene.h"
#include "number_text.h"

namespace fvp::trials {
// The simulator's world by its short name.
using namespace fvp::robot::sim;
namespace {

// Report pictures of the views: small enough that a report of 60 views stays light.
constexpr int kReportImageWidthPx = 360;

}  // namespace

std::string encodeViewImage(int index, const host::StereoFrame& frame) {
  if (frame.left_bgr.empty()) return {};
  cv::Mat small;
  const double scale = double(kReportImageWidthPx) / frame.left_bgr.cols;
  cv::resize(frame.left_bgr, small, cv::Size(), scale, scale, cv::INTER_AREA);
  std::vector<unsigned char> png;
  if (!cv::imencode(".png", small, png))
    throw std::runtime_error("view image " + std::to_string(index) + ": PNG encoding failed");
  return std::string(reinterpret_cast<const char*>(png.data()), png.size());
}

namespace {

/// j[key], or null when j is not an object or lacks it (a result of an older build).
const nlohmann::json& field(const nlohmann::json& j, const char* key) {
  static const nlohmann::json null;
  if (!j.is_object()) return null;
  const auto it = j.find(key);
  return it == j.end() ? null : *it;
}

/// A view's picture in the report: views/NNN.png.
std::string viewImageFile(int view) {
  return host::numberedFileName("views", view, "png");
}

/// A JSON 3-vector as Eigen (zero when it is not one).
Eigen::Vector3d vec3Of(const nlohmann::json& v) {
  if (!v.is_array() || v.size() != 3) return Eigen::Vector3d::Zero();
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

/// Each view's viewing direction (the camera's z axis in the world) from result["view_log"],
/// by its index over the run; results of older builds have none.
std::map<int, Eigen::Vector3d> viewingDirections(const nlohmann::json& result) {
  std::map<int, Eigen::Vector3d> out;
  if (!result.contains("view_log")) return out;
  for (const auto& v : result["view_log"])
    if (v.contains("index") && v.contains("viewing_direction") &&
        v["viewing_direction"].is_array() && v["viewing_direction"].size() == 3)
      out[v["index"].get<int>()] = vec3Of(v["viewing_direction"]);
  return out;
}

/// The fruitlets scored with our estimator (result["fruitlets"] unless the trial scored with
/// the paper's, which puts ours in "fruitlets_ours_sizing").
const nlohmann::json& ourFruitlets(const nlohmann::json& result) {
  static const nlohmann::json none = nlohmann::json::array();
  if (result.value("sizing_estimator", "ours") != "ours" &&
      result.contains("fruitlets_ours_sizing"))
    return result["fruitlets_ours_sizing"];
  return result.contains("fruitlets") ? result["fruitlets"] : none;
}

// Camera-path figure: the arrow of a viewing direction, in metres as the axes.
constexpr double kDirectionArrowM = 0.03;

}  // namespace

std::string cameraPathScript(const std::vector<Eigen::Vector3d>& fruitlets,
                             const std::vector<Eigen::Vector3d>& path, const nlohmann::json& result,
                             const std::vector<PathRegion>& regions,
                             const std::string& region_title) {
  const std::map<int, Eigen::Vector3d> directions = viewingDirections(result);
  const int last = static_cast<int>(path.size()) - 1;
  std::ostringstream s;
  s << "set terminal pngcairo size 1500,660 font 'DejaVu Sans,11'\nset encoding utf8\n"
    << "set multiplot layout 1,2 title "
    << host::gnuplotQuoted("Camera path: " + std::to_string(path.size()) +
                           " views coloured by capture order" +
                           (directions.empty() ? "" : ", arrows: viewing directions (3 cm)"))
    << "\n"
    << "set size ratio -1\nset grid\nset key outside bottom center horizontal\n"
    << "set style textbox opaque noborder margins 1,1\n"
    // Room inside the axes for the labels of views at the edge.
    << "set offsets graph 0.12, graph 0.12, graph 0.12, graph 0.12\n"
    // Viridis, stopped short of its pale yellow end (the last views stay visible).
    << "set palette defined (0 '#440154', 1 '#3b528b', 2 '#21918c', 3 '#5ec962', "
       "4 '#b5c91a')\n"
    << "set cbrange [0:" << std::max(last, 1) << "]\nset cblabel 'view (capture order)'\n";
  const char* axis[] = {"x (m)", "y (m)", "z (m)"};
  bool first_panel = true;
  for (const auto& [a, b, title] :
       {std::tuple{0, 1, "top view"}, std::tuple{0, 2, "side view (from the start view)"}}) {
    s << "$path << EOD\n";
    for (std::size_t i = 0; i < path.size(); ++i)
      s << path[i][a] << " " << path[i][b] << " " << i << "\n";
    s << "EOD\n$dirs << EOD\n";
    for (const auto& [view, d] : directions)
      if (view >= 0 && view <= last)
        s << path[view][a] << " " << path[view][b] << " " << kDirectionArrowM * d[a] << " "
          << kDirectionArrowM * d[b] << " " << view << "\n";
    s << "EOD\n$fruit << EOD\n";
    for (const auto& f : fruitlets) s << f[a] << " " << f[b] << "\n";
    s << "EOD\n$region << EOD\n";
    for (const auto& r : regions)
      s << r.center_m[a] << " " << r.center_m[b] << " " << r.radius_m << "\n";
    s << "EOD\n";
    s << "set title " << host::gnuplotQuoted(title) << "\nset xlabel "
      << host::gnuplotQuoted(axis[a]) << "\nset ylabel " << host::gnuplotQuoted(axis[b])
      << "\nunset label\n"
      << (first_panel ? "unset colorbox\n" : "set colorbox\n");
    // The start's and the last view's labels point away from the cluster (off the fruitlets
    // and the region), on an opaque box; two views close together get opposite sides.
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const auto& f : fruitlets.empty() ? path : fruitlets)
      centre += Eigen::Vector2d(f[a], f[b]);
    centre /= std::max<std::size_t>(1, fruitlets.empty() ? path.size() : fruitlets.size());
    const auto label = [&](int tag, const std::string& text, int view, double flip) {
      const Eigen::Vector2d p(path[view][a], path[view][b]);
      const double dx = (p - centre).x() >= 0 ? 1.0 : -1.0;
      const double dy = flip * ((p - centre).y() >= 0 ? 1.0 : -1.0);
      s << "set label " << tag << " " << host::gnuplotQuoted(text) << " at " << p.x() << ","
        << p.y() << " offset char " << 2.0 * dx << "," << 1.4 * dy << (dx > 0 ? " left" : " right")
        << " front boxed font ',9'\n";
    };
    if (last >= 0) label(1, "start (view 0)", 0, 1.0);
    if (last > 0) {
      const bool near = (path[last] - path[0]).norm() < 0.05;
      label(2, "last (view " + std::to_string(last) + ")", last, near ? -1.0 : 1.0);
    }
    std::vector<std::string> clauses;
    if (!regions.empty())
      clauses.push_back(
          "$region using 1:2:3 with circles lc rgb '#2ca02c' dt 2 lw 1.5 "
          "fs empty title " +
          host::gnuplotQuoted(region_title));
    clauses.push_back("$path using 1:2 with lines lc rgb '#b0b0b0' lw 1 title 'path'");
    if (!directions.empty())
      clauses.push_back(
          "$dirs using 1:2:3:4:5 with vectors head filled size screen 0.007,25 "
          "lw 1.5 lc palette notitle");
    clauses.push_back(
        "$path using 1:2:3 with points pt 7 ps 1.1 lc palette title 'camera (colour: order)'");
    if (last >= 0)
      clauses.push_back(
          "$path every ::0::0 using 1:2 with points pt 4 ps 2.6 lw 2 "
          "lc rgb 'black' title 'start view'");
    if (last > 0)
      clauses.push_back("$path every ::" + std::to_string(last) + "::" + std::to_string(last) +
                        " using 1:2 with points pt 8 ps 2.6 lw 2 lc rgb 'black' "
                        "title 'last view'");
    if (!fruitlets.empty())
      clauses.push_back(
          "$fruit using 1:2 with points pt 7 ps 0.7 lc rgb '#d62728' "
          "title 'fruitlets (truth)'");
    s << "plot ";
    for (std::size_t i = 0; i < clauses.size(); ++i) s << (i ? ", " : "") << clauses[i];
    s << "\n";
    first_panel = false;
  }
  s << "unset multiplot\n";
  return s.str();
}

bool plotSizeScatter(const nlohmann::json& result, const std::filesystem::path& png) {
  // Matched fruitlets by cluster (-1: a one-cluster trial): true and estimated mm.
  std::map<int, std::vector<std::pair<double, double>>> by_cluster;
  double lo = 1e9, hi = -1e9, abs_error = 0.0;
  std::size_t n = 0;
  for (const auto& f : ourFruitlets(result)) {
    if (!f.value("matched", false) || !f["est_size_mm"].is_number()) continue;
    const double t = f["gt_size_mm"].get<double>(), e = f["est_size_mm"].get<double>();
    by_cluster[f.value("cluster", -1)].push_back({t, e});
    lo = std::min({lo, t, e});
    hi = std::max({hi, t, e});
    abs_error += std::abs(e - t);
    ++n;
  }
  if (n == 0) return false;
  lo = std::floor(lo - 1.0);
  hi = std::ceil(hi + 1.0);
  std::ostringstream s;
  s << "set terminal pngcairo size 760,720 font 'DejaVu Sans,11'\nset encoding utf8\n"
    << "set title "
    << host::gnuplotQuoted("Estimated against true size (our estimator): " + std::to_string(n) +
                           " matched, MAE " + fmt(abs_error / n, 2) + " mm")
    << "\n"
    << "set xlabel 'true size (mm)'\nset ylabel 'estimated size (mm)'\nset size ratio -1\n"
    << "set grid\nset key top left\nset xrange [" << lo << ":" << hi << "]\nset yrange [" << lo
    << ":" << hi << "]\nset samples 2\n";
  for (const auto& [cluster, points] : by_cluster) {
    s << "$c" << (cluster + 1) << " << EOD\n";
    for (const auto& [t, e] : points) s << t << " " << e << "\n";
    s << "EOD\n";
  }
  s << "plot '+' using 1:($1-0.5):($1+0.5) with filledcurves lc rgb '#2ca02c' "
       "fs transparent solid 0.18 noborder title '± 0.5 mm', "
       "x with lines lc rgb '#555555' dt 2 title 'y = x'";
  int colour = 0;
  for (const auto& [cluster, points] : by_cluster)
    s << ", $c" << (cluster + 1) << " using 1:2 with points pt 7 ps 1.3 lc " << ++colour
      << " title "
      << host::gnuplotQuoted(cluster < 0 ? "fruitlet" : "cluster " + std::to_string(cluster));
  s << "\n";
  host::plotWithGnuplot(s.str(), png, "size figure");
  return true;
}

std::map<std::string, double> simulatedSecondsByStage(const nlohmann::json& clock) {
  std::map<std::string, double> charged;
  for (const auto& it : field(clock, "iterations"))
    for (const auto& [key, value] : it.items())
      if (value.is_number() && key != "total_s" && key.ends_with("_s") && !key.ends_with("_wall_s"))
        charged[key] += value.get<double>();
  return charged;
}

ReportFigures writeResultMapAndPath(
    nlohmann::json& result, const World& world, const host::map::MapEngine* map,
    const std::vector<Eigen::Vector3d>& camera_path, const std::vector<PathRegion>& regions,
    const std::string& region_title, const std::filesystem::path& out_dir,
    const std::function<void(const std::string&)>& warn, const ExtraWriter& extra) {
  std::filesystem::create_directories(out_dir);
  const auto write_result = [&] {
    host::writeFileAtomically(out_dir / "result.json", "trial result", result.dump(2) + "\n");
  };
  write_result();
  if (map) extra("coarse.bt", [&] { map->exportCoarse(out_dir / "coarse.bt"); });
  ReportFigures drawn;
  // One warning a cause: a missing gnuplot loses both figures, and says so once.
  std::vector<std::pair<std::string, std::string>> failed;  // warning text, cause
  const auto not_drawn = [&](const std::string& file, const std::string& what,
                             const std::exception& e) {
    std::string cause = e.what();
    if (cause.rfind(what + ": ", 0) == 0) cause.erase(0, what.size() + 2);
    for (auto& [text, earlier] : failed)
      if (earlier == cause) {
        text += "; " + file + " not drawn either, for the same reason";
        return;
      }
    failed.emplace_back(file + " not drawn: " + e.what(), cause);
  };
  if (!camera_path.empty()) {
    try {
      std::vector<Eigen::Vector3d> fruitlets;
      for (const auto& f : world.fruitlets()) fruitlets.push_back(f.center_m);
      host::plotWithGnuplot(cameraPathScript(fruitlets, camera_path, result, regions, region_title),
                            out_dir / "path.png", "camera path figure");
      drawn.path = true;
    } catch (const std::exception& e) {
      not_drawn("path.png", "camera path figure", e);
    }
  }
  try {
    drawn.sizes = plotSizeScatter(result, out_dir / "sizes.png");
  } catch (const std::exception& e) {
    not_drawn("sizes.png", "size figure", e);
  }
  for (const auto& [text, cause] : failed) {
    result["warnings"].push_back(text);
    if (warn) warn(text);
  }
  if (!failed.empty()) write_result();
  return drawn;
}

namespace {

/// "(x, y, z)" of a JSON 3-vector in metres, to the millimetre.
std::string pointText(const nlohmann::json& v) {
  if (!v.is_array() || v.size() != 3) return "-";
  return "(" + fmt(v[0], 3) + ", " + fmt(v[1], 3) + ", " + fmt(v[2], 3) + ")";
}

/// The top table: the simulated run's figures only (wall time has its own section).
void appendSimulatedSummary(std::ostringstream& md, const nlohmann::json& result,
                            const std::string& third_header, const std::string& third_value) {
  const nlohmann::json& m = field(result, "metrics");
  md << "| views | simulated time | " << third_header
     << " | detections | match % | MAE (mm) | MAPE (%) | precision % |\n"
        "|---|---|---|---|---|---|---|---|\n"
     << "| " << field(result, "views").dump() << " | " << fmtOrDash(field(result, "sim_time_s"), 1)
     << " s | " << third_value << " | " << result.value("detections", 0) << " | "
     << fmtOrDash(field(m, "match_percent"), 1) << " | " << fmtOrDash(field(m, "mae_mm"), 2)
     << " | " << fmtOrDash(field(m, "mape_percent"), 1) << " | "
     << fmtOrDash(field(m, "precision_percent"), 1) << " |\n";
}

/// The simulated seconds the clock charged, by stage over the loop's iterations (the
/// iterations also record wall times that the clock does not charge: those are left to
/// the wall-time section).
void appendSimulatedBudget(std::ostringstream& md, const nlohmann::json& result) {
  std::map<std::string, double> charged = simulatedSecondsByStage(field(result, "clock"));
  double total = 0.0;
  for (const auto& it : field(field(result, "clock"), "iterations"))
    if (const auto t = it.find("total_s"); t != it.end() && t->is_number())
      total += t->get<double>();
  md << "\n## Where the simulated budget went\n\nSimulated seconds charged by the clock (`"
     << (field(result, "clock").is_object() ? result["clock"].value("mode", "?") : "?")
     << "` mode), summed over the loop's iterations.\n\n| stage | simulated s |\n|---|---|\n";
  // The loop's order first, any other stage after it.
  const std::vector<std::string> order = {
      "capture_s",    "perception_s",      "mapping_s", "tsdf_s",  "planning_s",
      "goal_check_s", "motion_planning_s", "motion_s",  "sizing_s"};
  const auto row = [&](const std::string& key, double s) {
    md << "| " << key.substr(0, key.size() - (key.size() > 2 && key.ends_with("_s") ? 2 : 0))
       << " | " << fmt(s, 2) << " |\n";
  };
  for (const std::string& key : order)
    if (charged.contains(key)) row(key, charged[key]);
  for (const auto& [key, s] : charged)
    if (std::find(order.begin(), order.end(), key) == order.end()) row(key, s);
  md << "| **total of the iterations** | **" << fmt(total, 2) << "** |\n";
  const double sim = result.value("sim_time_s", total);
  if (std::abs(sim - total) >= 0.005)
    md << "| outside the iterations (e.g. moves between clusters) | " << fmt(sim - total, 2)
       << " |\n| **simulated time** | **" << fmt(sim, 2) << "** |\n";
}

/// Where the wall time went: the total first, then the parts (wall seconds of this
/// machine, which the simulated clock does not count).
void appendWallTime(std::ostringstream& md, const nlohmann::json& result) {
  md << "\n## Where the wall time went\n\nWall-clock seconds on this machine. The simulated "
        "clock never charges rendering (a fixed capture charge stands in for a camera), and "
        "charges the compute stages, perception included, their measured time only in `wall` "
        "clock mode.\n\n| part | wall s |\n|---|---|\n"
     << "| **total wall time** | **" << fmtOrDash(field(result, "wall_time_s"), 2) << "** |\n";
  for (const auto& [part, s] : field(result, "wall_breakdown_s").items())
    md << "| " << part << " | " << fmtOrDash(s, 2) << " |\n";
  double sgbm = 0.0;
  for (const auto& it : field(field(result, "clock"), "iterations"))
    if (it.contains("sgbm_wall_s") && it["sgbm_wall_s"].is_number())
      sgbm += it["sgbm_wall_s"].get<double>();
  if (sgbm > 0.0) md << "| stereo matching, within perception | " << fmt(sgbm, 2) << " |\n";
}

/// The size and centre a detection was scored with (the trial's estimator's).
std::pair<double, nlohmann::json> scoredSizeAndCentre(const nlohmann::json& d,
                                                      const std::string& estimator) {
  const bool paper = estimator == "paper";
  const char* size_key = paper ? "size_paper_mm" : "size_ours_mm";
  const char* centre_key = paper ? "centroid_m" : "center_m";
  const double size = d.contains(size_key) && d[size_key].is_number() ? d[size_key].get<double>()
                                                                      : d.value("size_mm", 0.0);
  return {size, d.contains(centre_key) ? d[centre_key] : d.value("center_m", nlohmann::json())};
}

/// "nearest F2 at 14.3 mm" against the scope's ground truth ("" without one); cluster names
/// a tree's cluster ("nearest C3.F2 ...").
std::string nearestFruitletText(const nlohmann::json& centre, const nlohmann::json& fruitlets,
                                std::optional<int> cluster) {
  if (!centre.is_array() || centre.size() != 3) return "";
  const Eigen::Vector3d c = vec3Of(centre);
  int best = -1;
  double best_mm = 0.0;
  for (std::size_t j = 0; j < fruitlets.size(); ++j) {
    if (!fruitlets[j].contains("gt_center_m")) continue;
    const double mm = 1000.0 * (vec3Of(fruitlets[j]["gt_center_m"]) - c).norm();
    if (best < 0 || mm < best_mm) best = static_cast<int>(j), best_mm = mm;
  }
  if (best < 0) return "";
  return "nearest " + host::report::fruitletLabel(static_cast<std::size_t>(best), cluster) +
         " at " + fmt(best_mm, 1) + " mm";
}

/// Where a detection's size came from (docs/sizing.md).
std::string sizeSourceText(const nlohmann::json& d) {
  const nlohmann::json& s = d.contains("support") ? d["support"] : nlohmann::json::object();
  const std::string source = d.value("size_source", "");
  if (source == "well_seen_images") {
    const int n = s.value("well_seen_images", 0);
    return n == 1 ? "size: its one well-seen image"
                  : "size: median of its " + std::to_string(n) + " well-seen images";
  }
  if (source == "all_images")
    return "size: median of all " + std::to_string(s.value("sized_images", 0)) +
           " images (none well seen)";
  if (source == "sphere_fit") return "size: sphere fit (no well-seen image)";
  return source.empty() ? "" : "size: " + source;
}

/// One table of a scope's detections (a trial's or a cluster's): the kept ones (D0.., the
/// order of sized_fruitlets) with the ground-truth fruitlet (F0.., the order of fruitlets)
/// each matched or "spurious", and the ones the support rule dropped (X0..), each with the
/// rule's numbers and why. cluster names a tree's cluster in the ids (C3.D0).
void appendDetectionTable(std::ostringstream& md, const nlohmann::json& scope,
                          const std::string& estimator, std::optional<int> cluster) {
  static const nlohmann::json none = nlohmann::json::array();
  const nlohmann::json& kept = scope.contains("sized_fruitlets") ? scope["sized_fruitlets"] : none;
  const nlohmann::json& dropped =
      scope.contains("unsupported_detections") ? scope["unsupported_detections"] : none;
  const nlohmann::json& truth = scope.contains("fruitlets") ? scope["fruitlets"] : none;
  std::map<int, int> fruitlet_of;  // detection -> ground-truth fruitlet
  for (std::size_t j = 0; j < truth.size(); ++j)
    if (truth[j].value("matched", false) && truth[j].contains("detection"))
      fruitlet_of[truth[j]["detection"].get<int>()] = static_cast<int>(j);
  const std::size_t spurious = kept.size() - std::min(kept.size(), fruitlet_of.size());
  md << kept.size() << " kept (" << fruitlet_of.size() << " matched, " << spurious << " spurious), "
     << dropped.size() << " dropped by the support rule.\n\n";
  if (kept.empty() && dropped.empty()) return;
  md << "| id | centre (m) | size (mm) | fruitlet | points / required | sized images "
        "(well seen) | sphere RMS (mm) | ± stderr (mm) | why |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  const auto row = [&](const std::string& id, const nlohmann::json& d, bool is_kept, int fruitlet) {
    const auto [size, centre] = scoredSizeAndCentre(d, estimator);
    const nlohmann::json& s = d.contains("support") ? d["support"] : nlohmann::json::object();
    const double points = d.value("points", 0.0);
    const double required = s.value("required_points", 0.0);
    const double stderr_mm = s.value("size_stderr_mm", -1.0);
    const std::string ratio = required > 0.0 ? " (" + fmt(points / required, 2) + "x)" : "";
    std::string match;
    if (!is_kept)
      match = "dropped";
    else if (fruitlet >= 0)
      match = host::report::fruitletLabel(static_cast<std::size_t>(fruitlet), cluster) + " (true " +
              fmtOrDash(field(truth[fruitlet], "gt_size_mm"), 2) + " mm)";
    else
      match = "**spurious**";
    const std::string nearest = fruitlet < 0 ? nearestFruitletText(centre, truth, cluster) : "";
    if (!nearest.empty()) match += " (" + nearest + ")";
    std::string why;
    if (is_kept) {
      why = required > 0.0
                ? "kept: " + fmt(points, 0) + " points >= " + fmt(required, 0) + " required" + ratio
                : "kept: support rule off";
      const std::string source = sizeSourceText(d);
      if (!source.empty()) why += "; " + source;
      if (fruitlet < 0) why += "; matched no fruitlet";
    } else {
      why = required > 0.0 && points < required
                ? "dropped: " + fmt(points, 0) + " points < " + fmt(required, 0) + " required" +
                      ratio + ", too little of its sphere seen"
                : "dropped by the support rule";
    }
    md << "| " << id << " | " << pointText(centre) << " | " << fmt(size, 2) << " | " << match
       << " | " << fmt(points, 0) << " / " << (required > 0.0 ? fmt(required, 0) : "-") << " | "
       << s.value("sized_images", 0) << " (" << s.value("well_seen_images", 0) << ") | "
       << (s.value("sphere_rms_mm", -1.0) >= 0.0 ? fmt(s["sphere_rms_mm"], 2) : "-") << " | "
       << (stderr_mm >= 0.0 ? "±" + fmt(stderr_mm, 2) : "- (< 2 well seen)") << " | " << why
       << " |\n";
  };
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const auto it = fruitlet_of.find(static_cast<int>(i));
    row(host::report::detectionLabel(true, i, cluster), kept[i], true,
        it == fruitlet_of.end() ? -1 : it->second);
  }
  for (std::size_t i = 0; i < dropped.size(); ++i)
    row(host::report::detectionLabel(false, i, cluster), dropped[i], false, -1);
}

/// The support rule in a sentence, with the trial's fraction.
void appendSupportRule(std::ostringstream& md, const nlohmann::json& result) {
  double fraction = 0.25, sphere_fit_fraction = 0.0;
  if (result.contains("config") && result["config"].contains("trial") &&
      result["config"]["trial"].contains("sizing")) {
    const nlohmann::json& sizing = result["config"]["trial"]["sizing"];
    fraction = sizing.value("min_support_area_fraction", fraction);
    sphere_fit_fraction = sizing.value("sphere_fit_support_area_fraction", sphere_fit_fraction);
  }
  md << "A detection of size 2r is kept only if its surface shows at least " << fmt(fraction, 2)
     << " of its sphere's area: `points` >= `required_points` (docs/sizing.md, \"Which "
        "detections are fruitlets\")";
  if (sphere_fit_fraction > fraction)
    md << ", and at least " << fmt(sphere_fit_fraction, 2)
       << " when its size comes from its sphere fit alone (\"Sized by its 3-D surface alone\")";
  md << "; two whose spheres overlap by more than half the smaller "
        "radius are one fruitlet seen twice and are merged (\"One fruitlet seen twice\"). A "
        "kept detection no fruitlet matched is **spurious**. "
        "± stderr is the standard error of its well-seen sizes' median; sphere RMS the "
        "distance of its points to its fitted sphere.\n\n";
}

/// The views: overlays of the views that count at full width (result["overlays"], with
/// why each counts), then the other views as thumbnails; without overlays every view's
/// thumbnail.
void appendViews(std::ostringstream& md, const nlohmann::json& result) {
  std::size_t views = 0;
  if (result.contains("camera_path_m") && result["camera_path_m"].is_array())
    views = result["camera_path_m"].size();
  else if (result.contains("views") && result["views"].is_number_integer())
    views = result["views"].get<std::size_t>();
  std::set<int> shown;
  const bool overlays =
      result.contains("overlays") && result["overlays"].is_array() && !result["overlays"].empty();
  if (overlays) {
    md << "\n## Views that count\n\nThe start view and each view whose segments sized a "
          "fruitlet, cropped to the Cluster Region, with the segments drawn over the image "
          "(docs/viewer.md, \"The evidence report\").\n";
    for (const auto& o : result["overlays"]) {
      const int view = o.value("view", -1);
      const std::string why = o.value("why", "");
      shown.insert(view);
      md << "\n![view " << view << (why.empty() ? "" : ": " + why) << "](" << o.value("file", "")
         << ")\n\n*View " << view << (why.empty() ? "" : ": " + why) << ".*\n";
    }
  }
  if (views == 0 || shown.size() >= views) return;
  md << "\n## " << (overlays ? "Other captured views" : "Captured views") << "\n\n";
  for (std::size_t v = 0; v < views; ++v)
    if (!shown.contains(static_cast<int>(v)))
      md << "![view " << v << "](" << viewImageFile(static_cast<int>(v)) << ") ";
  md << "\n";
}

/// The report's wall times, counted events, camera path, warnings and views.
void appendReportTail(std::ostringstream& md, const nlohmann::json& result,
                      const ReportFigures& figures) {
  appendWallTime(md, result);
  md << "\n## Counted events\n\n```json\n" << field(result, "events").dump(2) << "\n```\n";
  if (figures.path)
    md << "\n## Camera path\n\nPositions in capture order (colour), each view's viewing "
          "direction as an arrow, the start and last views marked.\n\n"
          "![camera path](path.png)\n";
  if (result.contains("warnings") && !result["warnings"].empty()) {
    md << "\n## Warnings\n\n";
    for (const auto& w : result["warnings"]) md << "- " << w.get<std::string>() << "\n";
  }
  appendViews(md, result);
}

}  // namespace

std::string trialReportMarkdown(const nlohmann::json& result, const ReportFigures& figures) {
  const std::string estimator = result.value("sizing_estimator", "ours");
  std::ostringstream md;
  md << "# Trial: " << result.value("planner", "?") << ", world seed "
     << field(result, "seed").dump() << "\n\n"
     << "Engine `" << result.value("engine", "?") << "`, backend `" << result.value("backend", "?")
     << "`, status `" << result.value("status", "?") << "`, stopped by `"
     << result.value("stop_reason", "?") << "`; sizes by the `" << estimator
     << "` estimator. Simulated figures (wall time: below).\n\n";
  appendSimulatedSummary(md, result, "budget", fmtOrDash(field(result, "budget_s"), 0) + " s");
  md << "\n## Sizes against ground truth\n\n"
     << "| fruitlet | true size (mm) | estimated (mm) | error (mm) | centre error (mm) | "
        "detection |\n|---|---|---|---|---|---|\n";
  std::size_t i = 0;
  for (const auto& f : field(result, "fruitlets")) {
    const bool matched = f.value("matched", false) && field(f, "est_size_mm").is_number();
    md << "| " << host::report::fruitletLabel(i++, std::nullopt) << " | "
       << fmtOrDash(field(f, "gt_size_mm"), 2) << " | "
       << (matched ? fmt(f["est_size_mm"], 2) : "not matched") << " | "
       << (matched ? fmt(f["est_size_mm"].get<double>() - f["gt_size_mm"].get<double>(), 2) : "-")
       << " | " << fmtOrDash(field(f, "center_error_mm"), 2) << " | "
       << (matched && f.contains("detection")
               ? host::report::detectionLabel(true, f["detection"].get<std::size_t>(), std::nullopt)
               : "-")
       << " |\n";
  }
  if (figures.sizes) md << "\n![estimated against true size](sizes.png)\n";
  md << "\n## Detections\n\n";
  appendSupportRule(md, result);
  appendDetectionTable(md, result, estimator, std::nullopt);
  appendSimulatedBudget(md, result);
  appendReportTail(md, result, figures);
  return md.str();
}

std::string treeReportMarkdown(const nlohmann::json& result, const ReportFigures& figures) {
  const std::string estimator = result.value("sizing_estimator", "ours");
  const nlohmann::json& clusters = field(result, "clusters");
  const double minutes = result.value("sim_time_s", 0.0) / 60.0;
  std::size_t matched = 0;
  for (const auto& f : field(result, "fruitlets")) matched += f.value("matched", false);
  std::ostringstream md;
  md << "# Tree trial: " << result.value("planner", "?") << ", world seed "
     << field(result, "seed").dump() << "\n\n"
     << "Engine `" << result.value("engine", "?") << "`, backend `" << result.value("backend", "?")
     << "`, " << clusters.size() << " clusters, stop rule `"
     << field(result, "stop").value("rule", "?") << "` (cap "
     << fmtOrDash(field(result, "budget_s"), 0) << " s a cluster); sizes by the `" << estimator
     << "` estimator. Simulated figures (wall time: below).\n\n";
  appendSimulatedSummary(md, result, "fruitlets sized / min",
                         minutes > 0 ? fmt(matched / minutes, 2) : "-");
  md << "\n## Clusters, in the order visited\n\n"
     << "| cluster | tag | status | views | simulated s | stop | fruitlets | matched | "
        "detections | MAE (mm) |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : clusters) {
    std::size_t c_matched = 0;
    for (const auto& f : field(c, "fruitlets")) c_matched += f.value("matched", false);
    const bool ran = c.contains("views");
    md << "| " << field(c, "index").dump() << " | " << field(c, "tag_id").dump() << " | "
       << c.value("status", "?") << " | " << (ran ? field(c, "views").dump() : "-") << " | "
       << (ran ? fmtOrDash(field(c, "sim_time_s"), 1) : "-") << " | " << c.value("stop_reason", "-")
       << " | " << field(c, "gt_fruitlets").dump() << " | " << c_matched << " | "
       << c.value("detections", 0) << " | " << fmtOrDash(field(field(c, "metrics"), "mae_mm"), 2)
       << " |\n";
  }
  md << "\nBetween clusters the arm spent "
     << fmtOrDash(field(field(result, "tour"), "transit_sim_s"), 1)
     << " simulated s moving. Each cluster's fine map, TSDF surface and clusters are in "
        "`cluster_K/`.\n\n## Sizes against ground truth\n\n"
     << "| cluster | fruitlet | true size (mm) | estimated (mm) | error (mm) | detection |\n"
        "|---|---|---|---|---|---|\n";
  std::map<int, std::size_t> next_in_cluster;  // fruitlets are numbered C<k>.F0.. in each cluster
  for (const auto& f : field(result, "fruitlets")) {
    const int cluster = f.value("cluster", -1);
    const bool hit = f.value("matched", false) && field(f, "est_size_mm").is_number();
    md << "| " << cluster << " | "
       << host::report::fruitletLabel(next_in_cluster[cluster]++, cluster) << " | "
       << fmtOrDash(field(f, "gt_size_mm"), 2) << " | "
       << (hit ? fmt(f["est_size_mm"], 2) : "not matched") << " | "
       << (hit ? fmt(f["est_size_mm"].get<double>() - f["gt_size_mm"].get<double>(), 2) : "-")
       << " | "
       << (hit && f.contains("detection")
               ? host::report::detectionLabel(true, f["detection"].get<std::size_t>(), cluster)
               : "-")
       << " |\n";
  }
  if (figures.sizes) md << "\n![estimated against true size](sizes.png)\n";
  md << "\n## Detections\n\nBy cluster: C3.D0 is cluster 3's first detection, C3.F0 its "
        "first fruitlet.\n\n";
  appendSupportRule(md, result);
  bool first = true;
  for (const auto& c : clusters) {
    md << (first ? "" : "\n") << "### Cluster " << field(c, "index").dump() << " (tag "
       << field(c, "tag_id").dump() << ")\n\n";
    first = false;
    if (c.contains("sized_fruitlets") || c.contains("unsupported_detections"))
      appendDetectionTable(md, c, estimator, c.value("index", -1));
    else
      md << "Not sized (" << c.value("status", "?") << ").\n";
  }
  appendSimulatedBudget(md, result);
  appendReportTail(md, result, figures);
  return md.str();
}

void writeTreeOutputs(nlohmann::json& result, const World& world, const host::map::MapEngine* map,
                      const std::vector<Eigen::Vector3d>& camera_path,
                      const std::filesystem::path& out_dir,
                      const std::function<void(const std::string&)>& warn,
                      const ExtraWriter& extra) {
  // Each sized cluster's region where its tag is (the regions its session placed were
  // handed on with the map).
  std::vector<PathRegion> regions;
  for (const auto& c : result["clusters"]) {
    const std::size_t k = c.value("index", world.clusters().size());
    if (c.value("status", "") != "sized" || k >= world.clusters().size()) continue;
    const host::ClusterRegion region =
        host::ClusterRegion::fromTag(world.clusters()[k].tag.T_world_tag);
    regions.push_back({region.center_m(), region.radius_m()});
  }
  const ReportFigures figures =
      writeResultMapAndPath(result, world, map, camera_path, regions,
                            "Cluster Regions (at the tags)", out_dir, warn, extra);
  extra("report.md", [&] {
    host::writeFileAtomically(out_dir / "report.md", "trial report",
                              treeReportMarkdown(result, figures));
  });
}
}  // namespace fvp::trials
