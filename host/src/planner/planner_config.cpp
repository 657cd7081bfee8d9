#include "fvp/host/planner/planner_config.h"

#include <nlohmann/json.hpp>
#include <vector>

#include "fvp/host/core/yaml_config.h"

namespace fvp::host::planner {
namespace {

using C = PlannerConfig;

const std::vector<YamlKey<C>>& yamlKeys() {
  static const std::vector<YamlKey<C>> keys = {
      yamlField("roi_samples", &C::roi_samples),
      yamlField("exploration_samples", &C::exploration_samples),
      yamlField("sensor_min_m", &C::sensor_min_m),
      yamlField("sensor_max_m", &C::sensor_max_m),
      yamlField("max_d_m", &C::max_d_m),
      yamlField("alpha_per_m", &C::alpha_per_m),
      yamlField("utility_threshold", &C::utility_threshold),
      yamlField("threshold_decay", &C::threshold_decay),
      yamlField("max_sampling_rounds", &C::max_sampling_rounds),
      yamlField("seed", &C::seed),
      yamlField("camera_clearance_m", &C::camera_clearance_m),
      yamlField("gain_mode", &C::gain_mode),
      yamlField("frustum_rays_x", &C::frustum_rays_x),
      yamlField("frustum_rays_y", &C::frustum_rays_y),
      yamlField("embree_cull", &C::embree_cull),
      yamlField("sizing_samples", &C::sizing_samples),
  };
  return keys;
}

}  // namespace

PlannerConfig PlannerConfig::fromYamlFile(const std::filesystem::path& path) {
  const std::string source = "planner config '" + path.string() + "'";
  PlannerConfig config;
  readYamlConfig(path, source, yamlKeys(), config);
  config.validate(source);
  return config;
}

void PlannerConfig::validate(const std::string& source) const {
  requireKey(roi_samples >= 0 && roi_samples <= kMaxCandidateSamples, source, "roi_samples",
             "0 to 100000 candidates a round (each is ray cast every round)");
  requireKey(exploration_samples >= 0 && exploration_samples <= kMaxCandidateSamples, source,
             "exploration_samples",
             "0 to 100000 candidates a round (each is ray cast every round)");
  requireKey(roi_samples + exploration_samples > 0, source, "roi_samples",
             "at least one candidate per round (roi_samples + exploration_samples > 0)");
  requireKey(sensor_min_m > 0.0 && sensor_min_m < 5.0, source, "sensor_min_m",
             "a distance in (0, 5) m");
  requireKey(sensor_max_m >= sensor_min_m && sensor_max_m < 5.0, source, "sensor_max_m",
             "a distance in [sensor_min_m, 5) m");
  requireKey(max_d_m > 0.0 && max_d_m < 1.0, source, "max_d_m", "a distance in (0, 1) m");
  requireKey(alpha_per_m >= 0.0 && alpha_per_m < 100.0, source, "alpha_per_m",
             "a cost weight in [0, 100) per metre");
  requireKey(utility_threshold >= -10.0 && utility_threshold <= 10.0, source, "utility_threshold",
             "a utility in [-10, 10]");
  requireKey(threshold_decay > 0.0 && threshold_decay < 1.0, source, "threshold_decay",
             "a factor b in (0, 1)");
  requireKey(camera_clearance_m >= 0.0 && camera_clearance_m < 1.0, source, "camera_clearance_m",
             "a distance in [0, 1) m");
  requireKey(gain_mode == "single_ray" || gain_mode == "frustum", source, "gain_mode",
             "single_ray or frustum");
  requireKey(frustum_rays_x >= 1 && frustum_rays_x <= 256, source, "frustum_rays_x",
             "1 to 256 rays");
  requireKey(frustum_rays_y >= 1 && frustum_rays_y <= 256, source, "frustum_rays_y",
             "1 to 256 rays");
  requireKey(sizing_samples >= 0 && sizing_samples <= kMaxCandidateSamples, source,
             "sizing_samples", "0 to 100000 candidates a round (each is ray cast every round)");
  requireKey(max_sampling_rounds >= 1 && max_sampling_rounds <= 1000, source, "max_sampling_rounds",
             "1 to 1000 rounds");
}

std::string PlannerConfig::toJson() const {
  return yamlConfigJson(yamlKeys(), *this).dump();
}

}  // namespace fvp::host::planner
