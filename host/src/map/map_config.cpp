#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <functional>
#include <map>
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

MapConfig MapConfig::fromYamlFile(const std::filesystem::path& path) {
  const std::string source = "map config '" + path.string() + "'";
  const YAML::Node root = readYamlMapping(path, source);
  MapConfig config;
  if (root.IsNull()) return config;
  auto number = [&](const YAML::Node& node, const std::string& key) {
    return readScalar<double>(node, source + ": key '" + key + "'", "a number");
  };
  auto vector3 = [&](const YAML::Node& node, const std::string& key) {
    if (!node.IsSequence() || node.size() != 3)
      throw std::invalid_argument(source + ": " + key + ": expected a list of 3 numbers [x, y, z]");
    return Eigen::Vector3d(number(node[0], key), number(node[1], key), number(node[2], key));
  };
  const std::map<std::string, std::function<void(const YAML::Node&, const std::string&)>> keys = {
      {"coarse_voxel_size_m", [&](auto& n, auto& k) { config.coarse_voxel_size_m = number(n, k); }},
      {"fine_voxel_size_m", [&](auto& n, auto& k) { config.fine_voxel_size_m = number(n, k); }},
      {"observation_min_m", [&](auto& n, auto& k) { config.observation_min_m = vector3(n, k); }},
      {"observation_max_m", [&](auto& n, auto& k) { config.observation_max_m = vector3(n, k); }},
      {"fine_map_extent",
       [&](auto& n, auto& k) {
         config.fine_map_extent = parseFineMapExtent(
             n.IsScalar() ? n.template as<std::string>() : "", source + ": " + k);
       }},
      {"sensor_max_range_m", [&](auto& n, auto& k) { config.sensor_max_range_m = number(n, k); }},
      {"prob_hit", [&](auto& n, auto& k) { config.model.prob_hit = number(n, k); }},
      {"prob_miss", [&](auto& n, auto& k) { config.model.prob_miss = number(n, k); }},
      {"clamp_min", [&](auto& n, auto& k) { config.model.clamp_min = number(n, k); }},
      {"clamp_max", [&](auto& n, auto& k) { config.model.clamp_max = number(n, k); }},
      {"occupied_prob", [&](auto& n, auto& k) { config.model.occupied_prob = number(n, k); }},
  };
  for (const auto& entry : root) {
    const std::string key = keyString(entry.first, source);
    const auto it = keys.find(key);
    if (it == keys.end()) {
      std::string known;
      for (const auto& [name, _] : keys) known += (known.empty() ? "" : ", ") + name;
      throw std::invalid_argument(source + ": unknown key '" + key + "' (known: " + known + ")");
    }
    it->second(entry.second, key);
  }
  config.validate(source);
  return config;
}

}  // namespace fvp::host::map
