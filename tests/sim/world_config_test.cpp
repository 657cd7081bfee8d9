#include "fvp/robot/sim/world_config.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>

namespace fvp::robot::sim {
namespace {

const std::filesystem::path kDefaultConfig =
    std::filesystem::path(FVP_SOURCE_DIR) / "robot/sim/config/world_default.yaml";

std::filesystem::path writeTemp(const std::string& name, const std::string& text) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path;
}

// The message of the std::invalid_argument that reading `text` throws ("" if none).
std::string readError(const std::string& name, const std::string& text) {
  try {
    WorldConfig::fromYamlFile(writeTemp(name, text));
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(WorldConfig, DefaultFileListsEveryKeyWithItsDefault) {
  EXPECT_EQ(WorldConfig::fromYamlFile(kDefaultConfig), WorldConfig{});
  std::set<std::string> listed;
  for (const auto& entry : YAML::LoadFile(kDefaultConfig.string())) {
    listed.insert(entry.first.as<std::string>());
  }
  const auto& names = WorldConfig::keyNames();
  EXPECT_EQ(listed, std::set<std::string>(names.begin(), names.end()));
}

TEST(WorldConfig, ReadsKeysAndKeepsOtherDefaults) {
  const WorldConfig config = WorldConfig::fromYamlFile(
      writeTemp("fvp_sim_ok.yaml", "leaf_count: 12\nmax_radius_m: 0.006\n"));
  EXPECT_EQ(config.leaf_count, 12);
  EXPECT_DOUBLE_EQ(config.max_radius_m, 0.006);
  EXPECT_DOUBLE_EQ(config.min_radius_m, WorldConfig{}.min_radius_m);
}

TEST(WorldConfig, UnknownKeyIsAnErrorNamingKeyAndFile) {
  const std::string error = readError("fvp_sim_unknown.yaml", "leaf_cout: 12\n");
  EXPECT_NE(error.find("unknown key 'leaf_cout'"), std::string::npos) << error;
  EXPECT_NE(error.find("fvp_sim_unknown.yaml"), std::string::npos) << error;
}

TEST(WorldConfig, OutOfRangeNamesKeyAndExpectedRange) {
  std::string error = readError("fvp_sim_range.yaml", "max_radius_m: 0.002\n");
  EXPECT_NE(error.find("'max_radius_m'"), std::string::npos) << error;
  EXPECT_NE(error.find("min_radius_m (0.003) <= max_radius_m <= 0.05"), std::string::npos) << error;
  EXPECT_NE(error.find("fvp_sim_range.yaml"), std::string::npos) << error;
  error = readError("fvp_sim_range2.yaml", "min_fruitlets: 0\n");
  EXPECT_NE(error.find("1 <= min_fruitlets <= 64"), std::string::npos) << error;
  error = readError("fvp_sim_range3.yaml", "tag_id: 587\n");
  EXPECT_NE(error.find("0 <= tag_id <= 586"), std::string::npos) << error;
}

TEST(WorldConfig, WrongTypeNamesKey) {
  std::string error = readError("fvp_sim_type.yaml", "leaf_count: many\n");
  EXPECT_NE(error.find("key 'leaf_count': expected an integer"), std::string::npos) << error;
  error = readError("fvp_sim_type2.yaml", "leaf_count: 2.5\n");
  EXPECT_NE(error.find("key 'leaf_count': expected an integer"), std::string::npos) << error;
  error = readError("fvp_sim_type3.yaml", "tag_size_m: [1, 2]\n");
  EXPECT_NE(error.find("key 'tag_size_m': expected a number"), std::string::npos) << error;
}

TEST(WorldConfig, UnreadableFileNamesIt) {
  try {
    WorldConfig::fromYamlFile("/nonexistent/world.yaml");
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/world.yaml"), std::string::npos);
  }
}

TEST(WorldConfig, TheClusterBranchMustLeaveTheTrunk) {
  WorldConfig config;
  config.cluster_height_m = 2.5;
  config.trunk_height_m = 2.0;
  try {
    config.validate("test");
    FAIL() << "a cluster above the trunk's top was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cluster_height_m"), std::string::npos) << e.what();
  }
}

TEST(WorldConfig, ValidateRejectsNaN) {
  WorldConfig config;
  config.leaf_region_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(config.validate(), std::invalid_argument);
}

TEST(WorldConfig, ToJsonHasEveryKey) {
  const std::string json = WorldConfig{}.toJson();
  for (const std::string& key : WorldConfig::keyNames()) {
    EXPECT_NE(json.find("\"" + key + "\""), std::string::npos) << key;
  }
}

// world_field_tree.yaml is the field preset on the tree: every key of world_field.yaml and of
// world_tree.yaml with the same value, and no key of its own (else the field-tree experiment
// would drift from the two worlds it claims to combine).
TEST(WorldConfig, TheFieldTreeIsTheFieldPresetOnTheTree) {
  const std::filesystem::path dir = std::filesystem::path(FVP_SOURCE_DIR) / "robot/sim/config";
  const YAML::Node field_tree = YAML::LoadFile((dir / "world_field_tree.yaml").string());
  std::set<std::string> copied;
  for (const char* part : {"world_field.yaml", "world_tree.yaml"})
    for (const auto& entry : YAML::LoadFile((dir / part).string())) {
      const std::string key = entry.first.as<std::string>();
      ASSERT_TRUE(field_tree[key]) << key << " of " << part << " is missing";
      EXPECT_EQ(field_tree[key].as<std::string>(), entry.second.as<std::string>())
          << key << " differs from " << part;
      copied.insert(key);
    }
  for (const auto& entry : field_tree)
    EXPECT_TRUE(copied.count(entry.first.as<std::string>())) << entry.first.as<std::string>();
  const WorldConfig config = WorldConfig::fromYamlFile(dir / "world_field_tree.yaml");
  EXPECT_EQ(config.cluster_count, 4);
  EXPECT_EQ(config.run_register_views, 1);
}

TEST(WorldConfig, TheSeasonTreeIsTheFieldTreeWithFruitletsNearSixMillimetres) {
  const std::filesystem::path dir = std::filesystem::path(FVP_SOURCE_DIR) / "robot/sim/config";
  const YAML::Node season = YAML::LoadFile((dir / "world_season.yaml").string());
  std::set<std::string> keys;
  for (const auto& entry : YAML::LoadFile((dir / "world_field_tree.yaml").string())) {
    const std::string key = entry.first.as<std::string>();
    ASSERT_TRUE(season[key]) << key << " of world_field_tree.yaml is missing";
    EXPECT_EQ(season[key].as<std::string>(), entry.second.as<std::string>()) << key;
    keys.insert(key);
  }
  for (const auto& entry : season) {
    const std::string key = entry.first.as<std::string>();
    EXPECT_TRUE(keys.count(key) || key == "min_radius_m" || key == "max_radius_m") << key;
  }
  const WorldConfig config = WorldConfig::fromYamlFile(dir / "world_season.yaml");
  EXPECT_EQ(config.min_radius_m, 0.003);  // 6 mm across
  EXPECT_EQ(config.max_radius_m, 0.005);
  EXPECT_EQ(config.season_day, 0.0);
}

TEST(WorldConfig, ErrorGroupsScaleTheirOwnKeysAndRefuseToLeaveTheirRanges) {
  const WorldConfig field =
      WorldConfig::fromYamlFile(std::string(FVP_SOURCE_DIR) + "/robot/sim/config/world_field.yaml");
  const WorldConfig half = field.withErrorsScaled("wind", 0.5);
  EXPECT_DOUBLE_EQ(half.wind_leaf_tip_m, 0.5 * field.wind_leaf_tip_m);
  EXPECT_DOUBLE_EQ(half.wind_fruitlet_swing_m, 0.5 * field.wind_fruitlet_swing_m);
  // Only the group: the others and the switches stay as they were.
  EXPECT_EQ(half.hand_eye_translation_sigma_m, field.hand_eye_translation_sigma_m);
  EXPECT_EQ(half.segmentation_boundary_px, field.segmentation_boundary_px);
  const WorldConfig none = field.withErrorsScaled("all", 0.0);
  EXPECT_EQ(none.hand_eye_rotation_sigma_deg, 0.0);
  EXPECT_EQ(none.stereo_vertical_misalignment_px, 0.0);
  EXPECT_EQ(none.segmentation_false_blobs, 0.0);
  EXPECT_EQ(none.segmentation_model, 1);
  EXPECT_EQ(none.fruitlet_green_fraction, 1.0);
  // Refused, not clamped (issue 38: a clamped point would be plotted at the wrong factor):
  // the message names the key, the value, the range and the largest factor that fits.
  try {
    field.withErrorsScaled("pose", 20.0);
    FAIL() << "expected pose=20 to be refused on the field preset";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("error scale pose=20: hand_eye_translation_sigma_m would be 0.03"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("outside its range 0 to 0.02"), std::string::npos) << m;
    EXPECT_NE(m.find("the largest factor this world config allows for pose is 13.3333"),
              std::string::npos)
        << m;
  }
  EXPECT_THROW(field.withErrorsScaled("pose", 1e308), std::invalid_argument);
  EXPECT_THROW(field.withErrorsScaled("all", 100.0), std::invalid_argument);
  // Up to the limit the factor holds exactly, and the result validates.
  const double limit = 0.02 / field.hand_eye_translation_sigma_m;
  const WorldConfig most = field.withErrorsScaled("pose", limit);
  EXPECT_DOUBLE_EQ(most.hand_eye_translation_sigma_m, 0.02);
  EXPECT_NO_THROW(most.validate());
  EXPECT_EQ(WorldConfig::errorGroups(),
            (std::vector<std::string>{"pose", "stereo", "wind", "segmentation", "light", "all"}));
  EXPECT_THROW(field.withErrorsScaled("sun", 1.0), std::invalid_argument);
  EXPECT_THROW(field.withErrorsScaled("pose", -1.0), std::invalid_argument);
  EXPECT_THROW(field.withErrorsScaled("pose", std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::robot::sim
