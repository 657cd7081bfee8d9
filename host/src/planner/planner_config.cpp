#include "fvp/host/planner/planner_config.h"

#include <functional>
#include <nlohmann/json.hpp>
#include <vector>

#include "fvp/host/core/yaml_config.h"

namespace fvp::host::planner {
namespace {

struct KeySpec {
  const char* name;
  std::function<void(PlannerConfig&, const YAML::Node&, const std::string&)> read;
};

template <typename T>
T as(const YAML::Node& node, const std::string& where, const char* expected) {
  return readScalar<T>(node, where, expected);
}

const std::vector<KeySpec>& keySpecs() {
  static const std::vector<KeySpec> specs = {
      {"roi_samples",
       [](auto& c, auto& n, auto& w) { c.roi_samples = as<int>(n, w, "an integer"); }},
      {"exploration_samples",
       [](auto& c, auto& n, auto& w) { c.exploration_samples = as<int>(n, w, "an integer"); }},
      {"sensor_min_m",
       [](auto& c, auto& n, auto& w) { c.sensor_min_m = as<double>(n, w, "a number"); }},
      {"sensor_max_m",
       [](auto& c, auto& n, auto& w) { c.sensor_max_m = as<double>(n, w, "a number"); }},
      {"max_d_m", [](auto& c, auto& n, auto& w) { c.max_d_m = as<double>(n, w, "a number"); }},
      {"alpha_per_m",
       [](auto& c, auto& n, auto& w) { c.alpha_per_m = as<double>(n, w, "a number"); }},
      {"utility_threshold",
       [](auto& c, auto& n, auto& w) { c.utility_threshold = as<double>(n, w, "a number"); }},
      {"threshold_decay",
       [](auto& c, auto& n, auto& w) { c.threshold_decay = as<double>(n, w, "a number"); }},
      {"max_sampling_rounds",
       [](auto& c, auto& n, auto& w) { c.max_sampling_rounds = as<int>(n, w, "an integer"); }},
      {"seed", [](auto& c, auto& n, auto& w) { c.seed = as<std::int64_t>(n, w, "an integer"); }},
      {"camera_clearance_m",
       [](auto& c, auto& n, auto& w) { c.camera_clearance_m = as<double>(n, w, "a number"); }},
      {"gain_mode",
       [](auto& c, auto& n, auto& w) { c.gain_mode = as<std::string>(n, w, "a string"); }},
      {"frustum_rays_x",
       [](auto& c, auto& n, auto& w) { c.frustum_rays_x = as<int>(n, w, "an integer"); }},
      {"frustum_rays_y",
       [](auto& c, auto& n, auto& w) { c.frustum_rays_y = as<int>(n, w, "an integer"); }},
      {"embree_cull",
       [](auto& c, auto& n, auto& w) { c.embree_cull = as<bool>(n, w, "true or false"); }},
  };
  return specs;
}

void require(bool ok, const std::string& source, const char* key, const std::string& expected) {
  if (!ok) throw std::invalid_argument(source + ": key '" + key + "': expected " + expected);
}

}  // namespace

PlannerConfig PlannerConfig::fromYamlFile(const std::filesystem::path& path) {
  const std::string source = "planner config '" + path.string() + "'";
  const YAML::Node root = readYamlMapping(path, source);
  PlannerConfig config;
  if (root.IsNull()) return config;
  for (const auto& item : root) {
    const std::string key = keyString(item.first, source);
    findKeySpec(keySpecs(), key, source).read(config, item.second, source + ": key '" + key + "'");
  }
  config.validate(source);
  return config;
}

void PlannerConfig::validate(const std::string& source) const {
  require(roi_samples >= 0 && roi_samples <= 10'000'000, source, "roi_samples",
          "0 to 10000000 candidates");
  require(exploration_samples >= 0 && exploration_samples <= 10'000'000, source,
          "exploration_samples", "0 to 10000000 candidates");
  require(roi_samples + exploration_samples > 0, source, "roi_samples",
          "at least one candidate per round (roi_samples + exploration_samples > 0)");
  require(sensor_min_m > 0.0 && sensor_min_m < 5.0, source, "sensor_min_m",
          "a distance in (0, 5) m");
  require(sensor_max_m >= sensor_min_m && sensor_max_m < 5.0, source, "sensor_max_m",
          "a distance in [sensor_min_m, 5) m");
  require(max_d_m > 0.0 && max_d_m < 1.0, source, "max_d_m", "a distance in (0, 1) m");
  require(alpha_per_m >= 0.0 && alpha_per_m < 100.0, source, "alpha_per_m",
          "a cost weight in [0, 100) per metre");
  require(utility_threshold >= -10.0 && utility_threshold <= 10.0, source, "utility_threshold",
          "a utility in [-10, 10]");
  require(threshold_decay > 0.0 && threshold_decay < 1.0, source, "threshold_decay",
          "a factor b in (0, 1)");
  require(camera_clearance_m >= 0.0 && camera_clearance_m < 1.0, source, "camera_clearance_m",
          "a distance in [0, 1) m");
  require(gain_mode == "single_ray" || gain_mode == "frustum", source, "gain_mode",
          "single_ray or frustum");
  require(frustum_rays_x >= 1 && frustum_rays_x <= 256, source, "frustum_rays_x", "1 to 256 rays");
  require(frustum_rays_y >= 1 && frustum_rays_y <= 256, source, "frustum_rays_y", "1 to 256 rays");
  require(max_sampling_rounds >= 1 && max_sampling_rounds <= 1000, source, "max_sampling_rounds",
          "1 to 1000 rounds");
}

std::string PlannerConfig::toJson() const {
  const nlohmann::ordered_json j = {{"roi_samples", roi_samples},
                                    {"exploration_samples", exploration_samples},
                                    {"sensor_min_m", sensor_min_m},
                                    {"sensor_max_m", sensor_max_m},
                                    {"max_d_m", max_d_m},
                                    {"alpha_per_m", alpha_per_m},
                                    {"utility_threshold", utility_threshold},
                                    {"threshold_decay", threshold_decay},
                                    {"max_sampling_rounds", max_sampling_rounds},
                                    {"seed", seed},
                                    {"camera_clearance_m", camera_clearance_m},
                                    {"gain_mode", gain_mode},
                                    {"frustum_rays_x", frustum_rays_x},
                                    {"frustum_rays_y", frustum_rays_y},
                                    {"embree_cull", embree_cull}};
  return j.dump();
}

}  // namespace fvp::host::planner
