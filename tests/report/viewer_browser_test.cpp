// A real trial's viewer.html opened by headless Chromium (Debian's chromium-headless-shell,
// WebGL on SwiftShader) from a file URL: the page loads with no error and no blocked
// request, the objects it drew equal those of the trial's files, and each layer alone puts
// pixels on the screen. The trial's overlays are checked against result.json.
#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "fvp/host/core/subprocess.h"
#include "fvp/trials/trial.h"

namespace fvp::trials {
namespace {

namespace fs = std::filesystem;

// Chromium is given this long; a page that has not loaded by then is a failure, not a hang.
constexpr int kBrowserTimeoutS = 120;

class ViewerInBrowser : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("fvp_viewer_browser_test_" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    TrialOptions o;
    o.seed = 7;
    o.backend = accel::BackendChoice::kCpu;
    o.clock = robot::sim::SimClock::Mode::kFixed;
    o.max_views = 4;
    o.out_dir = *dir_ / "trial";
    result_ = new nlohmann::json(runTrial(o));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete result_;
  }

  /// Chromium on the trial's page with the query; dump: the DOM (else a screenshot to png).
  static host::SubprocessResult browse(const std::string& query, const fs::path& png = {}) {
    const std::string url = "file://" + (*dir_ / "trial" / "viewer.html").string() + query;
    std::vector<std::string> argv = {"timeout",
                                     std::to_string(kBrowserTimeoutS),
                                     "chromium-headless-shell",
                                     "--no-sandbox",
                                     "--use-angle=swiftshader",
                                     "--enable-unsafe-swiftshader",
                                     "--window-size=1000,700",
                                     "--virtual-time-budget=15000",
                                     "--user-data-dir=" + (*dir_ / "profile").string()};
    argv.push_back(png.empty() ? "--dump-dom" : "--screenshot=" + png.string());
    argv.push_back(url);
    return host::runProgram(argv, "");
  }

  /// The page's test hook (docs/viewer.md) from a DOM dump.
  static nlohmann::json hook(const std::string& dom) {
    const std::smatch m = [&] {
      std::smatch found;
      std::regex_search(dom, found, std::regex("<pre id=\"fvp-test-hook\"[^>]*>([^<]*)</pre>"));
      return found;
    }();
    if (m.empty()) return nullptr;
    std::string text = m[1].str();
    for (const auto& [entity, c] : {std::pair{"&quot;", "\""}, std::pair{"&lt;", "<"},
                                    std::pair{"&gt;", ">"}, std::pair{"&amp;", "&"}})
      for (std::size_t at; (at = text.find(entity)) != std::string::npos;)
        text.replace(at, std::strlen(entity), c);
    return nlohmann::json::parse(text);
  }

  void checkPage();
  void checkLayers();
  void checkOverlays();

  static inline fs::path* dir_ = nullptr;
  static inline nlohmann::json* result_ = nullptr;
};

template <typename Tree>
std::size_t countOccupied(const Tree& tree) {
  std::size_t count = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it)
    if (tree.isNodeOccupied(*it)) count += std::size_t{1} << (3 * (16 - it.getDepth()));
  return count;
}

/// Occupied voxels of an OctoMap file at its finest resolution (a pruned leaf at depth d
/// stands for 8^(16 - d) of them). The fine map is written as a ColorOcTree (docs/maps.md).
std::size_t occupiedVoxels(const fs::path& ot) {
  std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(ot.string()));
  if (const auto* color = dynamic_cast<const octomap::ColorOcTree*>(tree.get()))
    return countOccupied(*color);
  if (const auto* plain = dynamic_cast<const octomap::OcTree*>(tree.get()))
    return countOccupied(*plain);
  return 0;
}

/// Faces of a PLY mesh, from its header.
std::size_t plyFaces(const fs::path& ply) {
  std::ifstream in(ply, std::ios::binary);
  for (std::string line; std::getline(in, line) && line != "end_header";)
    if (line.rfind("element face ", 0) == 0) return std::stoul(line.substr(13));
  return 0;
}

// One test: CTest runs each case in a process of its own, and each would run the trial.
TEST_F(ViewerInBrowser, ShowsTheTrialAndItsOverlays) {
  ASSERT_EQ(host::runProgram({"sh", "-c", "command -v chromium-headless-shell"}, "").exit_code, 0)
      << "chromium-headless-shell is not installed: scripts/install-deps --tests installs it";
  {
    SCOPED_TRACE("the page loads and draws what the trial holds");
    checkPage();
  }
  {
    SCOPED_TRACE("each layer alone puts its pixels on the screen");
    checkLayers();
  }
  {
    SCOPED_TRACE("overlays: the start view and the views that sized a fruitlet");
    checkOverlays();
  }
}

void ViewerInBrowser::checkPage() {
  const host::SubprocessResult run = browse("");
  ASSERT_EQ(run.exit_code, 0) << run.stderr_text;
  const nlohmann::json h = hook(run.stdout_text);
  ASSERT_FALSE(h.is_null()) << "no test hook in the page:\n" << run.stdout_text.substr(0, 2000);
  ASSERT_TRUE(h.at("loaded").get<bool>()) << h.dump(2);
  EXPECT_TRUE(h.at("errors").empty()) << h.dump(2);
  EXPECT_TRUE(h.at("blocked").empty())
      << "the page asked for something outside itself: " << h.dump(2);
  // The browser's own console: no JavaScript error (Chromium logs them as CONSOLE lines).
  EXPECT_EQ(run.stderr_text.find("Uncaught"), std::string::npos) << run.stderr_text;

  const nlohmann::json& r = *result_;
  const nlohmann::json& c = h.at("counts");
  const fs::path trial = *dir_ / "trial";
  EXPECT_EQ(c.at("cameras").get<std::size_t>(), r.at("view_log").size());
  std::size_t chosen = 0;
  for (const auto& p : r.at("plan_log")) chosen += !p.at("chosen_position_m").is_null();
  ASSERT_GT(chosen, 0u);
  EXPECT_EQ(c.at("chosen_candidates").get<std::size_t>(), chosen);
  EXPECT_EQ(c.at("kept_detections").get<std::size_t>(), r.at("sized_fruitlets").size());
  EXPECT_EQ(c.at("detections").get<std::size_t>(),
            r.at("sized_fruitlets").size() + r.at("unsupported_detections").size());
  EXPECT_EQ(c.at("ground_truth").get<std::size_t>(), r.at("fruitlets").size());
  EXPECT_EQ(c.at("tags").get<int>(), 1);
  EXPECT_EQ(c.at("cluster_regions").get<int>(), 1);
  const std::size_t fine = occupiedVoxels(trial / "fine.ot");
  ASSERT_GT(fine, 1000u);
  EXPECT_EQ(c.at("fine_voxels").get<std::size_t>(), fine);
  EXPECT_GT(c.at("roi_voxels").get<std::size_t>(), 0u);
  const std::size_t faces = plyFaces(trial / "mesh.ply");
  ASSERT_GT(faces, 1000u);
  EXPECT_EQ(c.at("mesh_triangles").get<std::size_t>(), faces);
}

void ViewerInBrowser::checkLayers() {
  const fs::path empty_png = *dir_ / "empty.png";
  ASSERT_EQ(browse("?layers=", empty_png).exit_code, 0);
  const cv::Mat empty = cv::imread(empty_png.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(empty.empty());
  for (const char* layer : {"mesh", "cameras", "voxels", "detections"}) {
    const fs::path png = *dir_ / (std::string(layer) + ".png");
    const host::SubprocessResult run = browse(std::string("?layers=") + layer, png);
    ASSERT_EQ(run.exit_code, 0) << run.stderr_text;
    const cv::Mat shot = cv::imread(png.string(), cv::IMREAD_COLOR);
    ASSERT_EQ(shot.size(), empty.size()) << layer;
    cv::Mat diff, changed;
    cv::absdiff(shot, empty, diff);
    cv::inRange(diff, cv::Scalar(0, 0, 0), cv::Scalar(24, 24, 24), changed);
    const int drawn = static_cast<int>(changed.total()) - cv::countNonZero(changed);
    // At least 0.2 % of the window (1400 px): a frustum's lines alone are thousands.
    EXPECT_GT(drawn, static_cast<int>(changed.total() / 500)) << layer;
  }
}

void ViewerInBrowser::checkOverlays() {
  const nlohmann::json& r = *result_;
  std::set<int> expected = {0};
  for (const auto& d : r.at("sized_fruitlets"))
    for (const auto& s : d.at("per_image")) expected.insert(s.at("view").get<int>());
  std::set<int> listed;
  for (const auto& o : r.at("overlays")) {
    listed.insert(o.at("view").get<int>());
    const cv::Mat image = cv::imread((*dir_ / "trial" / o.at("file").get<std::string>()).string());
    ASSERT_FALSE(image.empty()) << o.dump();
    EXPECT_EQ(image.cols, 960) << o.dump();
  }
  EXPECT_EQ(listed, expected);
  // view_log says what each view contributed: the detections it sized are its overlay's.
  for (const auto& v : r.at("view_log")) {
    EXPECT_TRUE(v.contains("fine_voxels_updated")) << v.dump();
    if (!v.contains("sized")) continue;
    const int view = v.at("index").get<int>();
    EXPECT_TRUE(listed.count(view)) << view;
    for (const auto& o : r.at("overlays")) {
      if (o.at("view") != view) continue;
      for (const auto& label : v.at("sized")) {
        EXPECT_NE(o.at("why").get<std::string>().find(label.get<std::string>()), std::string::npos)
            << o.dump();
      }
    }
  }
}

}  // namespace
}  // namespace fvp::trials
