#include "fvp/host/planner/rvp_config.h"

#include <functional>
#include <nlohmann/json.hpp>
#include <vector>

#include "fvp/host/core/yaml_config.h"

namespace fvp::host::planner {
namespace {

struct KeySpec {
  const char* name;
  std::function<void(RvpConfig&, const YAML::Node&)> read;
};

const std::vector<KeySpec>& keySpecs() {
  static const std::vector<KeySpec> specs = {
      {"roi_samples", [](RvpConfig& c, const YAML::Node& n) { c.roi_samples = n.as<int>(); }},
      {"exploration_samples",
       [](RvpConfig& c, const YAML::Node& n) { c.exploration_samples = n.as<int>(); }},
      {"sensor_min_m", [](RvpConfig& c, const YAML::Node& n) { c.sensor_min_m = n.as<double>(); }},
      {"sensor_max_m", [](RvpConfig& c, const YAML::Node& n) { c.sensor_max_m = n.as<double>(); }},
      {"alpha_per_m", [](RvpConfig& c, const YAML::Node& n) { c.alpha_per_m = n.as<double>(); }},
      {"roi_utility_threshold",
       [](RvpConfig& c, const YAML::Node& n) { c.roi_utility_threshold = n.as<double>(); }},
      {"exploration_rays_x",
       [](RvpConfig& c, const YAML::Node& n) { c.exploration_rays_x = n.as<int>(); }},
      {"exploration_rays_y",
       [](RvpConfig& c, const YAML::Node& n) { c.exploration_rays_y = n.as<int>(); }},
      {"exploration_fov_x_deg",
       [](RvpConfig& c, const YAML::Node& n) { c.exploration_fov_x_deg = n.as<double>(); }},
      {"exploration_box_half_m",
       [](RvpConfig& c, const YAML::Node& n) { c.exploration_box_half_m = n.as<double>(); }},
      {"seed", [](RvpConfig& c, const YAML::Node& n) { c.seed = n.as<std::int64_t>(); }},
  };
  return specs;
}

void require(bool ok, const std::string& source, const char* key, const char* expected) {
  if (!ok) throw std::invalid_argument(source + ": key '" + key + "': expected " + expected);
}

}  // namespace

RvpConfig RvpConfig::fromYamlFile(const std::filesystem::path& path) {
  const std::string source = "rvp config '" + path.string() + "'";
  const YAML::Node root = readYamlMapping(path, source);
  RvpConfig c;
  if (root.IsNull()) return c;
  for (const auto& item : root) {
    const std::string key = keyString(item.first, source);
    const KeySpec& spec = findKeySpec(keySpecs(), key, source);
    try {
      spec.read(c, item.second);
    } catch (const YAML::Exception&) {
      throw std::invalid_argument(source + ": key '" + key + "': expected a number");
    }
  }
  c.validate(source);
  return c;
}

void RvpConfig::validate(const std::string& source) const {
  require(roi_samples >= 0 && exploration_samples >= 0 && roi_samples + exploration_samples > 0,
          source, "roi_samples", "non-negative sample counts, not both 0");
  require(sensor_min_m > 0.0 && sensor_max_m >= sensor_min_m && sensor_max_m < 5.0, source,
          "sensor_max_m", "0 < sensor_min_m <= sensor_max_m < 5 m");
  require(alpha_per_m >= 0.0, source, "alpha_per_m", "a non-negative weight");
  require(exploration_rays_x >= 1 && exploration_rays_y >= 1, source, "exploration_rays_x",
          "at least one ray per axis");
  require(exploration_fov_x_deg > 0.0 && exploration_fov_x_deg < 170.0, source,
          "exploration_fov_x_deg", "an angle in (0, 170) degrees");
  require(exploration_box_half_m > 0.0 && exploration_box_half_m < 5.0, source,
          "exploration_box_half_m", "a distance in (0, 5) m");
}

std::string RvpConfig::toJson() const {
  const nlohmann::ordered_json j = {{"roi_samples", roi_samples},
                                    {"exploration_samples", exploration_samples},
                                    {"sensor_min_m", sensor_min_m},
                                    {"sensor_max_m", sensor_max_m},
                                    {"alpha_per_m", alpha_per_m},
                                    {"roi_utility_threshold", roi_utility_threshold},
                                    {"exploration_rays_x", exploration_rays_x},
                                    {"exploration_rays_y", exploration_rays_y},
                                    {"exploration_fov_x_deg", exploration_fov_x_deg},
                                    {"exploration_box_half_m", exploration_box_half_m},
                                    {"seed", seed}};
  return j.dump();
}

}  // namespace fvp::host::planner
