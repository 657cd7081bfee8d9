#include "fvp/host/planner/rvp_config.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

#include "fvp/host/core/yaml_config.h"
#include "fvp/host/planner/planner_config.h"

namespace fvp::host::planner {
namespace {

using C = RvpConfig;

const std::vector<YamlKey<C>>& yamlKeys() {
  static const std::vector<YamlKey<C>> keys = {
      yamlField("roi_samples", &C::roi_samples),
      yamlField("exploration_samples", &C::exploration_samples),
      yamlField("sensor_min_m", &C::sensor_min_m),
      yamlField("sensor_max_m", &C::sensor_max_m),
      yamlField("alpha_per_m", &C::alpha_per_m),
      yamlField("roi_utility_threshold", &C::roi_utility_threshold),
      yamlField("exploration_rays_x", &C::exploration_rays_x),
      yamlField("exploration_rays_y", &C::exploration_rays_y),
      yamlField("exploration_fov_x_deg", &C::exploration_fov_x_deg),
      yamlField("exploration_box_half_m", &C::exploration_box_half_m),
      yamlField("seed", &C::seed),
  };
  return keys;
}

}  // namespace

RvpConfig RvpConfig::fromYamlFile(const std::filesystem::path& path) {
  const std::string source = "rvp config '" + path.string() + "'";
  RvpConfig c;
  readYamlConfig(path, source, yamlKeys(), c);
  c.validate(source);
  return c;
}

void RvpConfig::validate(const std::string& source) const {
  // Each count bounded before they are added (two large ints overflow), the rays so that
  // nx * ny stays an int; every double in a finite range (`!(x >= lo)` style: NaN fails).
  requireKey(roi_samples >= 0 && roi_samples <= kMaxCandidateSamples, source, "roi_samples",
             "0 to 100000 candidates a round (each is ray cast every round)");
  requireKey(exploration_samples >= 0 && exploration_samples <= kMaxCandidateSamples, source,
             "exploration_samples",
             "0 to 100000 candidates a round (each is ray cast every round)");
  requireKey(roi_samples + exploration_samples > 0, source, "roi_samples",
             "non-negative sample counts, not both 0");
  requireKey(sensor_min_m > 0.0 && sensor_max_m >= sensor_min_m && sensor_max_m < 5.0, source,
             "sensor_max_m", "0 < sensor_min_m <= sensor_max_m < 5 m");
  requireKey(alpha_per_m >= 0.0 && alpha_per_m < 100.0, source, "alpha_per_m",
             "a cost weight in [0, 100) per metre");
  requireKey(roi_utility_threshold >= -10.0 && roi_utility_threshold <= 10.0, source,
             "roi_utility_threshold", "a utility in [-10, 10]");
  requireKey(exploration_rays_x >= 1 && exploration_rays_x <= 256, source, "exploration_rays_x",
             "1 to 256 rays");
  requireKey(exploration_rays_y >= 1 && exploration_rays_y <= 256, source, "exploration_rays_y",
             "1 to 256 rays");
  requireKey(exploration_fov_x_deg > 0.0 && exploration_fov_x_deg < 170.0, source,
             "exploration_fov_x_deg", "an angle in (0, 170) degrees");
  requireKey(exploration_box_half_m > 0.0 && exploration_box_half_m < 5.0, source,
             "exploration_box_half_m", "a distance in (0, 5) m");
}

std::string RvpConfig::toJson() const {
  return yamlConfigJson(yamlKeys(), *this).dump();
}

}  // namespace fvp::host::planner
