// Each config's key table both reads its YAML file and writes its JSON (result.json's
// config): what a config writes, read back as its file, is the same config.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "fvp/host/map/map_config.h"
#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/planner/planner_config.h"
#include "fvp/host/planner/rvp_config.h"
#include "fvp/robot/arm_config.h"
#include "fvp/robot/sim/world_config.h"

namespace fvp {
namespace {

namespace fs = std::filesystem;

/// The JSON written as a config file (JSON is YAML's flow style).
fs::path asConfigFile(const std::string& json, const std::string& name) {
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(json);
  const fs::path path = fs::temp_directory_path() / ("fvp_config_json_" + name + ".yaml");
  std::ofstream(path) << j.dump(2);
  return path;
}

template <typename Config, typename Change>
void expectRoundTrip(const std::string& name, Change change) {
  Config config;
  change(config);
  const std::string json = config.toJson();
  const Config read = Config::fromYamlFile(asConfigFile(json, name));
  EXPECT_EQ(read.toJson(), json) << name;
  EXPECT_NE(Config{}.toJson(), json) << name << ": the change must show in the JSON";
}

TEST(ConfigJson, EachConfigReadsBackWhatItWrites) {
  expectRoundTrip<host::planner::PlannerConfig>(
      "planner", [](auto& c) { c.roi_samples = 123, c.gain_mode = "single_ray"; });
  expectRoundTrip<host::planner::RvpConfig>("rvp", [](auto& c) { c.alpha_per_m = 0.25; });
  expectRoundTrip<host::map::MapConfig>("map", [](auto& c) {
    c.fine_voxel_size_m = 0.002;
    c.fine_map_extent = host::map::FineMapExtent::kObservationBox;
    c.model.prob_hit = 0.8;
  });
  expectRoundTrip<host::PerceptionConfig>("perception", [](auto& c) {
    c.tag.tag_id = 7;
    c.region.center_m = Eigen::Vector3d(0.1, 1.5, -0.25);
    c.segmentation.fruitlet_hues = {{10, 40}, {170, 5}};
  });
  expectRoundTrip<robot::ArmConfig>("arm", [](auto& c) { c.slider_travel_m = 2.5; });
  expectRoundTrip<robot::sim::WorldConfig>("world", [](auto& c) { c.cluster_count = 3; });
}

TEST(ConfigJson, AnUnsetOptionalIsLeftOutAsAFileLeavesItOut) {
  const auto j = nlohmann::json::parse(host::PerceptionConfig{}.toJson());
  EXPECT_FALSE(j.contains("region_center_m"));
  EXPECT_TRUE(j.contains("region_offset_tag_m"));
  expectRoundTrip<host::PerceptionConfig>("perception_tag", [](auto& c) { c.tag.tag_id = 3; });
}

TEST(ConfigJson, KeysAreTheFilesKeysInTheirOrder) {
  // result.json's config.planner is the planner config file's keys, first to last.
  const auto j = nlohmann::ordered_json::parse(host::planner::PlannerConfig{}.toJson());
  ASSERT_FALSE(j.empty());
  EXPECT_EQ(j.begin().key(), "roi_samples");
  EXPECT_EQ(j.size(), 16u);
}

}  // namespace
}  // namespace fvp
