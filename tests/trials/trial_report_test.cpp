// A trial's report.md and figures from a constructed result.json (no trial is run): every
// detection, kept or dropped, is listed with why; spurious ones are marked; wall time and
// simulated time stay in separate tables; the overlays of the views that count are shown at
// full size and their views are not repeated as thumbnails; the figures are PNGs.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fvp/host/core/gnuplot.h"
#include "trial_report.h"

namespace fvp::trials {
namespace {

namespace fs = std::filesystem;

nlohmann::json detection(double x, double size_mm, double points, double required,
                         const std::string& source, int sized, int well_seen, double stderr_mm) {
  return {{"center_m", {x, 0.03, 1.0}},
          {"centroid_m", {x, 0.03, 1.0}},
          {"size_mm", size_mm},
          {"size_ours_mm", size_mm},
          {"size_paper_mm", size_mm + 1.0},
          {"size_source", source},
          {"points", points},
          {"support",
           {{"sized_images", sized},
            {"own_segment_images", well_seen},
            {"well_seen_images", well_seen},
            {"sphere_rms_mm", 0.41},
            {"required_points", required},
            {"size_stderr_mm", stderr_mm}}},
          {"per_image", nlohmann::json::array()}};
}

nlohmann::json matchedFruitlet(double x, double true_mm, double est_mm, int detection) {
  return {{"gt_center_m", {x, 0.03, 1.0}},  {"gt_size_mm", true_mm}, {"matched", true},
          {"est_center_m", {x, 0.03, 1.0}}, {"est_size_mm", est_mm}, {"center_error_mm", 0.3},
          {"detection", detection}};
}

nlohmann::json missedFruitlet(double x, double true_mm) {
  return {{"gt_center_m", {x, 0.03, 1.0}},
          {"gt_size_mm", true_mm},
          {"matched", false},
          {"est_center_m", nullptr},
          {"est_size_mm", nullptr}};
}

// The sizing of one cluster: D0 matches F1, D1 matches F0, D2 is spurious (30 mm from every
// fruitlet), F2 is missed; X0 and X1 were dropped by the support rule.
nlohmann::json clusterSizing() {
  nlohmann::json s;
  s["sized_fruitlets"] = {detection(0.20, 9.87, 4089, 1115, "well_seen_images", 10, 9, 0.061),
                          detection(0.23, 8.13, 2000, 900, "sphere_fit", 4, 0, -1.0),
                          detection(0.29, 6.54, 700, 500, "all_images", 3, 0, -1.0)};
  s["unsupported_detections"] = {detection(0.215, 5.79, 34, 158, "sphere_fit", 4, 0, -1.0),
                                 detection(0.245, 7.11, 61, 240, "all_images", 2, 0, -1.0)};
  s["fruitlets"] = {matchedFruitlet(0.23, 8.19, 8.13, 1), matchedFruitlet(0.20, 10.01, 9.87, 0),
                    missedFruitlet(0.26, 9.36)};
  s["detections"] = 3;
  s["metrics"] = {{"match_percent", 66.7},
                  {"mae_mm", 0.10},
                  {"mape_percent", 1.2},
                  {"precision_percent", 66.7}};
  s["sizing_estimator"] = "ours";
  return s;
}

nlohmann::json viewLog(int views) {
  nlohmann::json log = nlohmann::json::array();
  for (int i = 0; i < views; ++i)
    log.push_back({{"index", i},
                   {"position_m", {0.1 * i, -0.3, 1.0}},
                   {"quaternion_wxyz", {1.0, 0.0, 0.0, 0.0}},
                   {"viewing_direction", {0.0, 1.0, 0.0}},
                   {"tag_detected", true},
                   {"sim_time_s", 2.0 * i}});
  return log;
}

nlohmann::json clockIterations(int views) {
  nlohmann::json it = nlohmann::json::array();
  for (int i = 0; i < views; ++i)
    it.push_back({{"capture_s", 0.2},
                  {"perception_s", 0.4},
                  {"mapping_s", 0.1},
                  {"tsdf_s", 0.1},
                  {"planning_s", 0.1},
                  {"motion_planning_s", 0.1},
                  {"motion_s", 1.4},
                  {"sizing_s", 0.1},
                  {"measured_wall", {{"mapping_s", 0.3}}},
                  {"rendering_wall_s", 1.6},
                  {"sgbm_wall_s", 1.1},
                  {"total_s", 2.5}});
  return {{"mode", "fixed"}, {"iterations", it}};
}

constexpr int kViews = 5;

nlohmann::json trialResult() {
  nlohmann::json r = clusterSizing();
  r["planner"] = "fvp";
  r["seed"] = 7;
  r["engine"] = "grid";
  r["backend"] = "cpu";
  r["status"] = "ok";
  r["stop_reason"] = "budget";
  r["views"] = kViews;
  r["sim_time_s"] = 2.5 * kViews;
  r["budget_s"] = 180.0;
  r["wall_time_s"] = 82.4;
  r["wall_breakdown_s"] = {{"rendering", 25.3}, {"perception", 20.2}, {"planning", 12.9}};
  r["clock"] = clockIterations(kViews);
  r["view_log"] = viewLog(kViews);
  r["camera_path_m"] = nlohmann::json::array();
  for (const auto& v : r["view_log"]) r["camera_path_m"].push_back(v["position_m"]);
  r["events"] = {{"move_attempts", 6}};
  r["warnings"] = nlohmann::json::array();
  r["config"] = {{"trial", {{"sizing", {{"min_support_area_fraction", 0.25}}}}}};
  return r;
}

/// The markdown from its heading "## title" to the next "## " heading.
std::string section(const std::string& md, const std::string& title) {
  const std::size_t start = md.find("\n## " + title + "\n");
  if (start == std::string::npos) return "";
  const std::size_t end = md.find("\n## ", start + 1);
  return md.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

/// The table row whose first cell is `id` ("" when none).
std::string row(const std::string& text, const std::string& id) {
  const std::size_t start = text.find("\n| " + id + " |");
  if (start == std::string::npos) return "";
  return text.substr(start + 1, text.find('\n', start + 1) - start - 1);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

bool isPng(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string head(8, '\0');
  in.read(head.data(), 8);
  return in && head == std::string("\x89PNG\r\n\x1a\n", 8);
}

bool haveGnuplot() {
  return std::system("gnuplot --version > /dev/null 2>&1") == 0;
}

fs::path freshDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(TrialReport, ListsEveryKeptAndDroppedDetectionWithWhy) {
  nlohmann::json result = trialResult();
  result["unsupported_detections"][1]["support"]["sphere_rms_mm"] = -1.0;  // no sphere fit
  const std::string md = trialReportMarkdown(result, {});
  const std::string detections = section(md, "Detections");
  ASSERT_FALSE(detections.empty()) << md;
  EXPECT_TRUE(contains(detections, "3 kept (2 matched, 1 spurious), 2 dropped")) << detections;
  // Kept, in sized_fruitlets' order, each with the fruitlet it matched.
  const std::string d0 = row(detections, "D0"), d1 = row(detections, "D1");
  const std::string d2 = row(detections, "D2");
  EXPECT_TRUE(contains(d0, "| 9.87 |") && contains(d0, "F1 (true 10.01 mm)")) << d0;
  EXPECT_TRUE(contains(d0, "4089 / 1115") && contains(d0, "| 10 (9) |")) << d0;
  EXPECT_TRUE(contains(d0, "±0.06") && contains(d0, "| 0.41 |")) << d0;
  EXPECT_TRUE(contains(d0, "kept: 4089 points >= 1115 required")) << d0;
  EXPECT_TRUE(contains(d0, "median of its 9 well-seen images")) << d0;
  EXPECT_TRUE(contains(d1, "F0 (true 8.19 mm)") && contains(d1, "sphere fit")) << d1;
  EXPECT_TRUE(contains(d1, "- (< 2 well seen)")) << d1;
  EXPECT_FALSE(contains(d0 + d1, "spurious"));
  EXPECT_TRUE(contains(d2, "**spurious**") && contains(d2, "nearest F2 at 30.0 mm")) << d2;
  // Dropped, with the rule's numbers.
  const std::string x0 = row(detections, "X0"), x1 = row(detections, "X1");
  EXPECT_TRUE(contains(x0, "| 5.79 |") && contains(x0, "dropped: 34 points < 158 required")) << x0;
  EXPECT_TRUE(contains(x1, "| 7.11 |") && contains(x1, "dropped: 61 points < 240 required")) << x1;
  EXPECT_TRUE(contains(x1, "| 2 (0) | - |")) << x1;
  EXPECT_TRUE(row(detections, "D3").empty() && row(detections, "X2").empty());
  // The ground-truth table points at the detections.
  const std::string sizes = section(md, "Sizes against ground truth");
  EXPECT_TRUE(contains(row(sizes, "F0"), "| D1 |")) << sizes;
  EXPECT_TRUE(contains(row(sizes, "F2"), "not matched")) << sizes;
}

TEST(TrialReport, SizesWithThePaperEstimatorShowItsSizes) {
  nlohmann::json result = trialResult();
  result["sizing_estimator"] = "paper";
  const std::string detections = section(trialReportMarkdown(result, {}), "Detections");
  EXPECT_TRUE(contains(row(detections, "D0"), "| 10.87 |")) << detections;
  EXPECT_TRUE(contains(row(detections, "X0"), "| 6.79 |")) << detections;
}

TEST(TrialReport, KeepsWallAndSimulatedTimeInSeparateTables) {
  const std::string md = trialReportMarkdown(trialResult(), {});
  // The top table, before the first section: simulated figures only.
  const std::string top = md.substr(0, md.find("\n## "));
  EXPECT_TRUE(contains(top, "| views | simulated time | budget | detections |")) << top;
  EXPECT_TRUE(contains(top, "precision %")) << top;
  EXPECT_FALSE(contains(top, "82.4")) << top;
  EXPECT_FALSE(contains(top, "wall time |")) << top;
  // The simulated budget: charged stages, no wall seconds.
  const std::string sim = section(md, "Where the simulated budget went");
  ASSERT_FALSE(sim.empty()) << md;
  EXPECT_TRUE(contains(row(sim, "motion"), "| 7.00 |")) << sim;
  EXPECT_TRUE(contains(sim, "| **total of the iterations** | **12.50** |")) << sim;
  // Perception is charged, in the loop's order: right after the capture.
  EXPECT_TRUE(contains(sim, "| capture | 1.00 |\n| perception | 2.00 |\n| mapping |")) << sim;
  EXPECT_FALSE(contains(sim, "wall")) << sim;
  EXPECT_FALSE(contains(sim, "sgbm")) << sim;
  // The wall time: the total first, then the parts and stereo matching's share of perception.
  const std::string wall = section(md, "Where the wall time went");
  ASSERT_FALSE(wall.empty()) << md;
  const std::size_t table = wall.find("|---|---|\n");
  ASSERT_NE(table, std::string::npos) << wall;
  const std::string first_row = "| **total wall time** | **82.40** |\n";
  EXPECT_EQ(wall.substr(table + 10, first_row.size()), first_row) << wall;
  EXPECT_TRUE(contains(row(wall, "rendering"), "25.30")) << wall;
  EXPECT_TRUE(contains(wall, "| stereo matching, within perception | 5.50 |")) << wall;
}

TEST(TrialReport, ShowsOverlaysOfTheViewsThatCountAndThumbnailsOfTheOthers) {
  nlohmann::json result = trialResult();
  result["overlays"] = {{{"view", 0}, {"file", "overlays/000.jpg"}, {"why", "start view"}},
                        {{"view", 3}, {"file", "overlays/003.jpg"}, {"why", "sized D0, D2"}}};
  const std::string md = trialReportMarkdown(result, {});
  const std::string overlays = section(md, "Views that count");
  ASSERT_FALSE(overlays.empty()) << md;
  EXPECT_TRUE(contains(overlays, "\n![view 0: start view](overlays/000.jpg)\n")) << overlays;
  EXPECT_TRUE(contains(overlays, "*View 3: sized D0, D2.*")) << overlays;
  EXPECT_TRUE(contains(overlays, "\n![view 3: sized D0, D2](overlays/003.jpg)\n")) << overlays;
  const std::string others = section(md, "Other captured views");
  ASSERT_FALSE(others.empty()) << md;
  for (const char* shown : {"views/001.png", "views/002.png", "views/004.png"})
    EXPECT_TRUE(contains(others, shown)) << shown;
  EXPECT_FALSE(contains(md, "views/000.png"));
  EXPECT_FALSE(contains(md, "views/003.png"));
  EXPECT_TRUE(section(md, "Captured views").empty());
}

TEST(TrialReport, WithoutOverlaysShowsEveryViewAsAThumbnail) {
  const std::string md = trialReportMarkdown(trialResult(), {});
  EXPECT_TRUE(section(md, "Views that count").empty());
  const std::string views = section(md, "Captured views");
  for (int v = 0; v < kViews; ++v)
    EXPECT_TRUE(contains(views, "](views/00" + std::to_string(v) + ".png)")) << views;
}

TEST(TrialReport, ShowsTheFiguresDrawn) {
  const std::string without = trialReportMarkdown(trialResult(), {});
  EXPECT_FALSE(contains(without, "path.png"));
  EXPECT_FALSE(contains(without, "sizes.png"));
  const std::string with = trialReportMarkdown(trialResult(), {.path = true, .sizes = true});
  EXPECT_TRUE(contains(section(with, "Camera path"), "](path.png)"));
  EXPECT_TRUE(contains(section(with, "Sizes against ground truth"), "](sizes.png)"));
}

TEST(TreeReport, ListsEachClustersDetectionsAndOverlays) {
  nlohmann::json result = trialResult();
  for (const char* key : {"sized_fruitlets", "unsupported_detections"}) result.erase(key);
  result["stop"] = {{"rule", "auto"}};
  result["tour"] = {{"transit_sim_s", 3.5}};
  nlohmann::json a = clusterSizing(), b = clusterSizing();
  a.update({{"index", 0},
            {"tag_id", 0},
            {"status", "sized"},
            {"views", 3},
            {"sim_time_s", 6.3},
            {"gt_fruitlets", 3}});
  b.update({{"index", 1},
            {"tag_id", 1},
            {"status", "sized"},
            {"views", 2},
            {"sim_time_s", 4.2},
            {"gt_fruitlets", 3}});
  b["sized_fruitlets"].erase(2);  // no spurious detection here
  b["unsupported_detections"].erase(1);
  b["detections"] = 2;
  const nlohmann::json skipped = {
      {"index", 2}, {"tag_id", 2}, {"status", "unreachable"}, {"gt_fruitlets", 4}};
  result["clusters"] = {a, b, skipped};
  result["fruitlets"] = nlohmann::json::array();
  for (const auto& c : {a, b})
    for (nlohmann::json f : c["fruitlets"]) {
      f["cluster"] = c["index"];
      result["fruitlets"].push_back(f);
    }
  result["overlays"] = {{{"view", 0}, {"file", "overlays/000.jpg"}, {"why", "start view"}},
                        {{"view", 4}, {"file", "overlays/004.jpg"}, {"why", "sized C1.D1"}}};
  const std::string md = treeReportMarkdown(result, {});
  const std::string detections = section(md, "Detections");
  ASSERT_FALSE(detections.empty()) << md;
  const std::size_t c0 = detections.find("### Cluster 0 (tag 0)");
  const std::size_t c1 = detections.find("### Cluster 1 (tag 1)");
  const std::size_t c2 = detections.find("### Cluster 2 (tag 2)");
  ASSERT_TRUE(c0 != std::string::npos && c1 != std::string::npos && c2 != std::string::npos)
      << detections;
  const std::string first = detections.substr(c0, c1 - c0);
  const std::string second = detections.substr(c1, c2 - c1);
  // Ids name the cluster, as the overlays' captions do.
  for (const char* id : {"C0.D0", "C0.D1", "C0.D2", "C0.X0", "C0.X1"})
    EXPECT_FALSE(row(first, id).empty()) << id << "\n" << first;
  EXPECT_TRUE(contains(row(first, "C0.D0"), "| C0.F1 (true 10.01 mm) |")) << first;
  EXPECT_TRUE(contains(row(first, "C0.D2"), "**spurious** (nearest C0.F2 at 30.0 mm)")) << first;
  for (const char* id : {"C1.D0", "C1.D1", "C1.X0"}) EXPECT_FALSE(row(second, id).empty()) << id;
  EXPECT_TRUE(row(second, "C1.D2").empty() && row(second, "C1.X1").empty()) << second;
  EXPECT_FALSE(contains(second, "spurious**")) << second;
  EXPECT_TRUE(contains(detections.substr(c2), "Not sized (unreachable)")) << detections;
  const std::string sizes = section(md, "Sizes against ground truth");
  EXPECT_TRUE(contains(row(sizes, "1"), "| C1.F0 | 8.19 | 8.13 | -0.06 | C1.D1 |")) << sizes;
  // The wall time is below, not in the top table.
  EXPECT_FALSE(contains(md.substr(0, md.find("\n## ")), "82.4"));
  EXPECT_TRUE(contains(section(md, "Where the wall time went"), "**82.40**"));
  EXPECT_TRUE(contains(section(md, "Views that count"), "](overlays/004.jpg)"));
  const std::string others = section(md, "Other captured views");
  EXPECT_TRUE(contains(others, "views/001.png")) << others;
  EXPECT_FALSE(contains(md, "views/004.png"));
}

TEST(TrialFigures, CameraPathDrawsViewingDirectionsAndNoLabelPerView) {
  const nlohmann::json result = trialResult();
  std::vector<Eigen::Vector3d> path;
  for (const auto& p : result["camera_path_m"]) path.emplace_back(p[0], p[1], p[2]);
  const std::vector<Eigen::Vector3d> fruitlets = {{0.2, 0.03, 1.0}, {0.23, 0.03, 1.0}};
  const std::string script = cameraPathScript(fruitlets, path, result,
                                              {{Eigen::Vector3d(0.2, 0.0, 1.0), 0.065}}, "region");
  EXPECT_NE(script.find("with vectors"), std::string::npos);
  EXPECT_NE(script.find("view (capture order)"), std::string::npos);
  EXPECT_NE(script.find("with circles"), std::string::npos);
  EXPECT_NE(script.find("'start (view 0)'"), std::string::npos);
  EXPECT_NE(script.find("'last (view 4)'"), std::string::npos);
  EXPECT_EQ(script.find("with labels"), std::string::npos);
  // One 3 cm arrow a view, in each of the two panels (top view: along +y).
  std::size_t arrows = 0;
  for (std::size_t at = script.find("$dirs << EOD\n"); at != std::string::npos;
       at = script.find("$dirs << EOD\n", at + 1)) {
    std::istringstream block(script.substr(at + 13, script.find("EOD\n", at + 13) - at - 13));
    for (std::string line; std::getline(block, line);) ++arrows;
  }
  EXPECT_EQ(arrows, 2u * kViews);
  EXPECT_NE(script.find("0 -0.3 0 0.03 0\n"), std::string::npos) << script;
  // Without viewing directions (a result of an older build): no arrows.
  nlohmann::json old = result;
  old.erase("view_log");
  EXPECT_EQ(cameraPathScript(fruitlets, path, old, {}, "region").find("with vectors"),
            std::string::npos);
  if (!haveGnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path dir = freshDir("fvp_trial_report_path");
  host::plotWithGnuplot(script, dir / "path.png", "camera path figure");
  EXPECT_TRUE(isPng(dir / "path.png"));
}

TEST(TrialFigures, SizeScatterIsAPngOnlyWhenAFruitletMatched) {
  if (!haveGnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path dir = freshDir("fvp_trial_report_sizes");
  nlohmann::json result = trialResult();
  EXPECT_TRUE(plotSizeScatter(result, dir / "sizes.png"));
  EXPECT_TRUE(isPng(dir / "sizes.png"));
  // A tree's fruitlets, one colour a cluster.
  for (auto& f : result["fruitlets"]) f["cluster"] = 1;
  result["fruitlets"][0]["cluster"] = 0;
  EXPECT_TRUE(plotSizeScatter(result, dir / "tree.png"));
  EXPECT_TRUE(isPng(dir / "tree.png"));
  // Nothing matched: no figure, no error.
  for (auto& f : result["fruitlets"]) f = missedFruitlet(0.2, 9.0);
  EXPECT_FALSE(plotSizeScatter(result, dir / "none.png"));
  EXPECT_FALSE(fs::exists(dir / "none.png"));
}

}  // namespace
}  // namespace fvp::trials
