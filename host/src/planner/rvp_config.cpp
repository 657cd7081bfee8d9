#include "fvp/host/planner/rvp_config.h"

#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <type_traits>
#include <vector>

#include "fvp/host/core/yaml_config.h"

namespace fvp::host::planner {
namespace {

struct KeySpec {
  const char* name;
  std::function<void(RvpConfig&, const YAML::Node&, const std::string&)> read;
};

/// A spec that reads key into member as an integer or a finite number.
template <typename T>
KeySpec field(const char* name, T RvpConfig::*member) {
  return {name, [member](RvpConfig& c, const YAML::Node& n, const std::string& where) {
            c.*member = readScalar<T>(n, where, std::is_integral_v<T> ? "an integer" : "a number");
          }};
}

const std::vector<KeySpec>& keySpecs() {
  static const std::vector<KeySpec> specs = {
      field("roi_samples", &RvpConfig::roi_samples),
      field("exploration_samples", &RvpConfig::exploration_samples),
      field("sensor_min_m", &RvpConfig::sensor_min_m),
      field("sensor_max_m", &RvpConfig::sensor_max_m),
      field("alpha_per_m", &RvpConfig::alpha_per_m),
      field("roi_utility_threshold", &RvpConfig::roi_utility_threshold),
      field("exploration_rays_x", &RvpConfig::exploration_rays_x),
      field("exploration_rays_y", &RvpConfig::exploration_rays_y),
      field("exploration_fov_x_deg", &RvpConfig::exploration_fov_x_deg),
      field("exploration_box_half_m", &RvpConfig::exploration_box_half_m),
      field("seed", &RvpConfig::seed),
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
    findKeySpec(keySpecs(), key, source).read(c, item.second, source + ": key '" + key + "'");
  }
  c.validate(source);
  return c;
}

void RvpConfig::validate(const std::string& source) const {
  // Each count bounded before they are added (two large ints overflow), the rays so that
  // nx * ny stays an int; every double in a finite range (`!(x >= lo)` style: NaN fails).
  require(roi_samples >= 0 && roi_samples <= 10'000'000, source, "roi_samples",
          "0 to 10000000 candidates");
  require(exploration_samples >= 0 && exploration_samples <= 10'000'000, source,
          "exploration_samples", "0 to 10000000 candidates");
  require(roi_samples + exploration_samples > 0, source, "roi_samples",
          "non-negative sample counts, not both 0");
  require(sensor_min_m > 0.0 && sensor_max_m >= sensor_min_m && sensor_max_m < 5.0, source,
          "sensor_max_m", "0 < sensor_min_m <= sensor_max_m < 5 m");
  require(alpha_per_m >= 0.0 && alpha_per_m < 100.0, source, "alpha_per_m",
          "a cost weight in [0, 100) per metre");
  require(roi_utility_threshold >= -10.0 && roi_utility_threshold <= 10.0, source,
          "roi_utility_threshold", "a utility in [-10, 10]");
  require(exploration_rays_x >= 1 && exploration_rays_x <= 256, source, "exploration_rays_x",
          "1 to 256 rays");
  require(exploration_rays_y >= 1 && exploration_rays_y <= 256, source, "exploration_rays_y",
          "1 to 256 rays");
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
