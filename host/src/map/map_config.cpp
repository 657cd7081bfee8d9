#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <stdexcept>
#include <string>

#include "fvp/host/core/yaml_config.h"
#include "fvp/host/map/map_config.h"
#include "fvp/host/map/occupancy_model.h"

namespace fvp::host::map {
namespace {

void requireRange(double value, double lo, double hi, const std::string& field, bool open = true) {
  const bool ok = open ? (value > lo && value < hi) : (value >= lo && value <= hi);
  if (!ok) {
    throw std::invalid_argument(field + " = " + formatNumber(value) + ": expected a value in " +
                                (open ? "(" : "[") + formatNumber(lo) + ", " + formatNumber(hi) +
                                (open ? ")" : "]"));
  }
}

using C = MapConfig;

const std::vector<YamlKey<C>>& yamlKeys() {
  static const std::vector<YamlKey<C>> keys = {
      yamlField("coarse_voxel_size_m", &C::coarse_voxel_size_m),
      yamlField("fine_voxel_size_m", &C::fine_voxel_size_m),
      yamlField("observation_min_m", &C::observation_min_m),
      yamlField("observation_max_m", &C::observation_max_m),
      {"fine_map_extent",
       [](C& c, const YAML::Node& n, const std::string& where) {
         c.fine_map_extent =
             parseFineMapExtent(readScalar<std::string>(n, where, "a string"), where);
       },
       [](const C& c) { return nlohmann::json(toString(c.fine_map_extent)); }},
      yamlField("sensor_max_range_m", &C::sensor_max_range_m),
      yamlField<C>(
          "prob_hit", [](C & c) -> auto& { return c.model.prob_hit; }),
      yamlField<C>(
          "prob_miss", [](C & c) -> auto& { return c.model.prob_miss; }),
      yamlField<C>(
          "clamp_min", [](C & c) -> auto& { return c.model.clamp_min; }),
      yamlField<C>(
          "clamp_max", [](C & c) -> auto& { return c.model.clamp_max; }),
      yamlField<C>(
          "occupied_prob", [](C & c) -> auto& { return c.model.occupied_prob; }),
  };
  return keys;
}

}  // namespace

std::string toString(FineMapExtent extent) {
  return extent == FineMapExtent::kObservationBox ? "observation_box" : "cluster_region";
}

FineMapExtent parseFineMapExtent(const std::string& text, const std::string& field) {
  if (text == "cluster_region") return FineMapExtent::kClusterRegion;
  if (text == "observation_box") return FineMapExtent::kObservationBox;
  throw std::invalid_argument(field + ": expected cluster_region or observation_box, got '" + text +
                              "'");
}

void OccupancyModel::validate(const std::string& source) const {
  requireRange(prob_hit, 0.5, 1.0, source + ".prob_hit");
  requireRange(prob_miss, 0.0, 0.5, source + ".prob_miss");
  requireRange(clamp_min, 0.0, 0.5, source + ".clamp_min");
  requireRange(clamp_max, 0.5, 1.0, source + ".clamp_max");
  requireRange(occupied_prob, clamp_min, clamp_max, source + ".occupied_prob");
}

void MapConfig::validate(const std::string& source) const {
  requireRange(coarse_voxel_size_m, 1e-4, 1.0, source + ".coarse_voxel_size_m");
  requireRange(fine_voxel_size_m, 1e-4, 1.0, source + ".fine_voxel_size_m");
  requireRange(sensor_max_range_m, 0.0, 100.0, source + ".sensor_max_range_m");
  for (int a = 0; a < 3; ++a) {
    if (!(observation_max_m[a] > observation_min_m[a]) || !observation_min_m.allFinite() ||
        !observation_max_m.allFinite()) {
      throw std::invalid_argument(source + ".observation_max_m must exceed " + source +
                                  ".observation_min_m on every axis");
    }
  }
  // The exact DDA walks end points within 8192 voxels of a grid's corner; rays up to
  // max range from a sensor near the box must stay well inside that.
  const double max_range_vox =
      sensor_max_range_m / std::min(coarse_voxel_size_m, fine_voxel_size_m);
  if (max_range_vox >= 4096.0) {
    throw std::invalid_argument(source + ".sensor_max_range_m / " + source +
                                ".fine_voxel_size_m = " + std::to_string(max_range_vox) +
                                ": expected fewer than 4096 voxels per ray");
  }
  model.validate(source + ".model");
}

std::string MapConfig::toJson() const {
  return yamlConfigJson(yamlKeys(), *this).dump();
}

MapConfig MapConfig::fromYamlFile(const std::filesystem::path& path) {
  const std::string source = "map config '" + path.string() + "'";
  MapConfig config;
  readYamlConfig(path, source, yamlKeys(), config);
  config.validate(source);
  return config;
}

}  // namespace fvp::host::map
