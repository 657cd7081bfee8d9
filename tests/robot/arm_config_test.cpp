// The arm's YAML config: defaults file, errors naming file and key.
#include <gtest/gtest.h>

#include <fstream>

#include "fvp/robot/arm_config.h"

namespace fvp::robot {
namespace {

std::filesystem::path writeTemp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("fvp_arm_config_" + name + ".yaml");
  std::ofstream(path) << text;
  return path;
}

std::string errorOf(const std::string& text) {
  try {
    ArmConfig::fromYamlFile(writeTemp("bad", text));
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ArmConfig, DefaultFileMatchesDefaults) {
  const ArmConfig from_file = ArmConfig::fromYamlFile(std::filesystem::path(FVP_SOURCE_DIR) /
                                                      "robot/config/arm_default.yaml");
  EXPECT_EQ(from_file.toJson(), ArmConfig{}.toJson());
  // The defaults file lists every key.
  std::ifstream in(std::filesystem::path(FVP_SOURCE_DIR) / "robot/config/arm_default.yaml");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const std::string& key : ArmConfig::keyNames())
    EXPECT_NE(text.find("\n" + key + ":"), std::string::npos) << key;
}

TEST(ArmConfig, ReadsValuesAndVectors) {
  const ArmConfig c = ArmConfig::fromYamlFile(
      writeTemp("good", "slider_travel_m: 2.0\nslider_origin_m: [0.1, -0.9, 0.6]\nplanner: PRM\n"));
  EXPECT_EQ(c.slider_travel_m, 2.0);
  EXPECT_EQ(c.slider_origin_m, Eigen::Vector3d(0.1, -0.9, 0.6));
  EXPECT_EQ(c.planner, "PRM");
}

TEST(ArmConfig, ErrorsNameFileAndKey) {
  std::string e = errorOf("slider_travel_m: -1\n");
  EXPECT_NE(e.find("fvp_arm_config_bad.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("'slider_travel_m'"), std::string::npos) << e;
  e = errorOf("no_such_key: 1\n");
  EXPECT_NE(e.find("unknown key 'no_such_key'"), std::string::npos) << e;
  e = errorOf("slider_origin_m: [1, 2]\n");
  EXPECT_NE(e.find("key 'slider_origin_m': expected a list of 3 numbers"), std::string::npos) << e;
  e = errorOf("planner: Dijkstra\n");
  EXPECT_NE(e.find("'planner'"), std::string::npos) << e;
  // The simulated clock is the simulator's (robot/sim/sim_clock.h), not the arm's.
  e = errorOf("clock: fixed\n");
  EXPECT_NE(e.find("unknown key 'clock'"), std::string::npos) << e;
  e = errorOf("ik_slider_samples: many\n");
  EXPECT_NE(e.find("key 'ik_slider_samples': expected an integer"), std::string::npos) << e;
}

}  // namespace
}  // namespace fvp::robot
