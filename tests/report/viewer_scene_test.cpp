// The viewer's scene: base64 against RFC 4648's vectors, the fine voxels decoded back equal
// the map's (two maps merged), and detections, ground truth and their links from a sizing.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <set>

#include "fvp/accel/backend.h"
#include "fvp/host/map/grid_map_engine.h"
#include "fvp/host/report/viewer_page.h"
#include "fvp/host/report/viewer_scene.h"
#include "synthetic_scan.h"

namespace fvp::host::report {
namespace {

std::vector<unsigned char> decodeBase64(const std::string& text) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> out;
  std::uint32_t word = 0;
  int bits = 0;
  for (const char c : text) {
    if (c == '=') break;
    word = (word << 6) | static_cast<std::uint32_t>(alphabet.find(c));
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((word >> bits) & 0xFFu));
    }
  }
  return out;
}

TEST(Base64, MatchesTheRfcVectors) {
  const std::pair<const char*, const char*> vectors[] = {{"", ""},
                                                         {"f", "Zg=="},
                                                         {"fo", "Zm8="},
                                                         {"foo", "Zm9v"},
                                                         {"foob", "Zm9vYg=="},
                                                         {"fooba", "Zm9vYmE="},
                                                         {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, encoded] : vectors)
    EXPECT_EQ(base64(plain, std::strlen(plain)), encoded) << plain;
}

map::MapConfig boxConfig() {
  map::MapConfig config;
  config.observation_min_m = {-0.6, -0.6, -0.2};
  config.observation_max_m = {0.6, 0.6, 0.6};
  return config;
}

TEST(ViewerScene, FineVoxelsOfTwoMapsDecodeToExactlyTheMapsOccupiedVoxels) {
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  const ClusterRegion first(Eigen::Vector3d(-0.15, 0.01, 0.31), 0.05),
      second(Eigen::Vector3d(0.17, -0.02, 0.29), 0.05);
  std::set<std::array<std::int64_t, 4>> expected;  // lattice index + roi
  ViewerScene scene("t", "s");
  for (const auto& [region, seed] : {std::pair{first, 3}, std::pair{second, 4}}) {
    map::GridMapEngine map(boxConfig(), region, *cpu);
    auto world = map::testing::makeWorld(seed, region.center_m());
    world.back_plane_offset_m = 0.03;  // inside the fine map's cube: voxels outside the ROI
    map.integrate(map::testing::renderScan(world,
                                           region.center_m() + Eigen::Vector3d(0, -0.3, 0.05), 240,
                                           180, 0.8, seed)
                      .clouds());
    const map::GridGeometry& g = map.gridGeometry(map::MapLevel::kFine);
    std::size_t roi = 0;
    for (const auto& i : map.occupiedVoxels(map::MapLevel::kFine)) {
      const bool in_roi = map.fineState(g.voxelCenter_m(i)).roi;
      roi += in_roi;
      expected.insert({g.first_voxel[0] + i[0], g.first_voxel[1] + i[1], g.first_voxel[2] + i[2],
                       in_roi ? 1 : 0});
    }
    ASSERT_GT(roi, 100u);
    ASSERT_LT(roi, map.occupiedVoxels(map::MapLevel::kFine).size());  // leaves too
    scene.addFineVoxels(map);
  }
  const nlohmann::json j = scene.toJson();
  const auto& v = j.at("fine_voxels");
  ASSERT_EQ(v.at("count").get<std::size_t>(), expected.size());
  const auto ijk_bytes = decodeBase64(v.at("ijk_u16_b64"));
  const auto roi_bytes = decodeBase64(v.at("roi_u8_b64"));
  ASSERT_EQ(ijk_bytes.size(), 6 * expected.size());
  ASSERT_EQ(roi_bytes.size(), expected.size());
  const double size = v.at("voxel_size_m");
  std::set<std::array<std::int64_t, 4>> decoded;
  for (std::size_t n = 0; n < expected.size(); ++n) {
    std::array<std::int64_t, 4> key{};
    for (int a = 0; a < 3; ++a) {
      const int value = ijk_bytes[6 * n + 2 * a] | (ijk_bytes[6 * n + 2 * a + 1] << 8);
      key[a] = std::llround(v.at("origin_m")[a].get<double>() / size) + value;
    }
    key[3] = roi_bytes[n];
    decoded.insert(key);
  }
  EXPECT_EQ(decoded, expected);
}

nlohmann::json detection(double x, double size_mm, std::vector<int> views) {
  nlohmann::json per_image = nlohmann::json::array();
  for (int v : views)
    per_image.push_back(
        {{"view", v}, {"size_ours_mm", size_mm}, {"size_paper_mm", size_mm}, {"well_seen", true}});
  return {{"center_m", {x, 0.0, 1.0}},
          {"size_mm", size_mm},
          {"points", 400},
          {"support",
           {{"sized_images", views.size()},
            {"well_seen_images", views.size()},
            {"sphere_rms_mm", 0.1},
            {"required_points", 200.0},
            {"size_stderr_mm", 0.05}}},
          {"per_image", per_image}};
}

TEST(ViewerScene, DetectionsKeepTheirMatchAndViewsAcrossClusters) {
  ViewerScene scene("t", "s");
  // Cluster 0: two kept detections, the second spurious; one dropped; two fruitlets, one
  // missed. Its views count from 0; cluster 1's from 5.
  const nlohmann::json cluster0 = {
      {"sized_fruitlets", {detection(0.00, 7.0, {0, 2}), detection(0.02, 6.0, {1})}},
      {"unsupported_detections", {detection(0.04, 9.0, {3})}},
      {"fruitlets",
       {{{"gt_center_m", {0.0, 0.0, 1.0}},
         {"gt_size_mm", 7.2},
         {"matched", true},
         {"detection", 0}},
        {{"gt_center_m", {0.1, 0.0, 1.0}}, {"gt_size_mm", 8.0}, {"matched", false}}}}};
  const nlohmann::json cluster1 = {{"sized_fruitlets", {detection(0.5, 8.0, {0, 1})}},
                                   {"unsupported_detections", nlohmann::json::array()},
                                   {"fruitlets",
                                    {{{"gt_center_m", {0.5, 0.0, 1.0}},
                                      {"gt_size_mm", 8.1},
                                      {"matched", true},
                                      {"detection", 0}}}}};
  scene.addSizing(cluster0, 0, 0);
  scene.addSizing(cluster1, 5, 1);
  const nlohmann::json j = scene.toJson();
  const auto& d = j.at("detections");
  ASSERT_EQ(d.size(), 4u);
  EXPECT_EQ(d[0]["label"], "C0.D0");
  EXPECT_TRUE(d[0]["matched"].get<bool>());
  EXPECT_EQ(d[0]["ground_truth"], 0);
  EXPECT_NEAR(d[0]["error_mm"].get<double>(), -0.2, 1e-12);
  EXPECT_EQ(d[1]["label"], "C0.D1");
  EXPECT_FALSE(d[1]["matched"].get<bool>());
  EXPECT_EQ(d[2]["label"], "C0.X0");
  EXPECT_FALSE(d[2]["kept"].get<bool>());
  EXPECT_EQ(d[3]["label"], "C1.D0");
  EXPECT_EQ(d[3]["ground_truth"], 2);
  EXPECT_EQ(d[3]["per_view"][1]["view"], 6);  // shifted by the cluster's first view
  const auto& truth = j.at("ground_truth");
  ASSERT_EQ(truth.size(), 3u);
  EXPECT_EQ(truth[0]["detection"], 0);
  EXPECT_TRUE(truth[1]["detection"].is_null());
  EXPECT_EQ(truth[2]["detection"], 3);
  EXPECT_EQ(truth[0]["label"], "C0.F0");
  EXPECT_EQ(truth[2]["label"], "C1.F0");  // numbered within its cluster, as the report does
}

TEST(ViewerPage, InlinesTheSceneSoThatNoTextEndsItsScript) {
  ViewerScene scene("a </script><script>alert(1)</script> <!--FVP_SCRIPTS--> title", "s");
  const std::string page = viewerPageHtml(scene.toJson());
  // The title's '<' are escaped: the only "</script" left close the page's own scripts, and
  // the placeholder in the title stays text.
  EXPECT_EQ(page.find("</script><script>alert"), std::string::npos);
  EXPECT_NE(
      page.find(
          "a \\u003c/script>\\u003cscript>alert(1)\\u003c/script> \\u003c!--FVP_SCRIPTS--> title"),
      std::string::npos);
  EXPECT_NE(page.find("id=\"fvp-scene\""), std::string::npos);
  EXPECT_NE(page.find("THREE.OrbitControls"), std::string::npos);
  for (const char* placeholder : {"/*FVP_CSS*/", "<!--FVP_SCENE-->", "<!--FVP_SCRIPTS-->"})
    EXPECT_EQ(page.find(placeholder), std::string::npos) << placeholder;
  // Nothing is fetched: no element names a remote source.
  for (const char* remote : {"src=\"http", "href=\"http", "src='http", "href='http", "url(http"})
    EXPECT_EQ(page.find(remote), std::string::npos) << remote;
}

}  // namespace
}  // namespace fvp::host::report
