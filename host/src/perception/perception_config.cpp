// PerceptionConfig::fromYamlFile: the keys a user sets for their own orchard and tags.
#include <string>
#include <vector>

#include "fvp/host/core/yaml_config.h"
#include "fvp/host/perception/perception_pipeline.h"

namespace fvp::host {
namespace {

using C = PerceptionConfig;

/// Hue ranges in degrees [[from, to], ...] (wrapping through 0 when from > to) -> OpenCV's
/// half-degree hues.
std::vector<HueRange> hueRanges(const YAML::Node& node, const std::string& where) {
  const std::string expected = "a list of [from, to] hue ranges in degrees, 0 to 360";
  if (!node.IsSequence() || node.size() == 0)
    throw std::invalid_argument(where + ": expected " + expected);
  std::vector<HueRange> out;
  for (const YAML::Node& range : node) {
    if (!range.IsSequence() || range.size() != 2)
      throw std::invalid_argument(where + ": expected " + expected);
    const double from = readScalar<double>(range[0], where, expected);
    const double to = readScalar<double>(range[1], where, expected);
    if (from < 0 || from > 360 || to < 0 || to > 360)
      throw std::invalid_argument(where + ": expected " + expected + ", got [" +
                                  formatNumber(from) + ", " + formatNumber(to) + "]");
    out.push_back({std::min(179, int(from / 2.0)), std::min(179, int(to / 2.0))});
  }
  return out;
}

// The largest Cluster Region a config may ask for: a fruitlet cluster is ~0.1 m across (the
// default radius is 0.065 m); half a metre already holds a branch.
constexpr double kMaxRegionRadiusM = 0.5;

const std::vector<YamlKey<C>>& yamlKeys() {
  static const std::vector<YamlKey<C>> keys = {
      yamlField<C>(
          "tag_family", [](C & c) -> auto& { return c.tag.family; }),
      yamlField<C>(
          "tag_id", [](C & c) -> auto& { return c.tag.tag_id; }),
      yamlField<C>(
          "tag_size_m", [](C & c) -> auto& { return c.tag.tag_size_m; }),
      yamlField<C>(
          "tag_max_hamming", [](C & c) -> auto& { return c.tag.max_hamming; }),
      yamlField<C>(
          "region_radius_m", [](C & c) -> auto& { return c.region.radius_m; }),
      yamlField<C>(
          "region_offset_tag_m", [](C & c) -> auto& { return c.region.center_offset_tag_m; }),
      yamlField<C>(
          "region_center_m", [](C & c) -> auto& { return c.region.center_m; }),
      {"hsv_fruitlet_hues_deg",
       [](C& c, const YAML::Node& n, const std::string& where) {
         c.segmentation.fruitlet_hues = hueRanges(n, where);
       },
       [](const C& c) {
         nlohmann::json ranges = nlohmann::json::array();
         for (const HueRange& r : c.segmentation.fruitlet_hues)
           ranges.push_back({2.0 * r.min_h, 2.0 * r.max_h});
         return ranges;
       }},
      yamlField<C>(
          "hsv_min_saturation", [](C & c) -> auto& { return c.segmentation.min_saturation; }),
      yamlField<C>(
          "hsv_min_value", [](C & c) -> auto& { return c.segmentation.min_value; }),
  };
  return keys;
}

}  // namespace

std::string PerceptionConfig::toJson() const {
  return yamlConfigJson(yamlKeys(), *this).dump();
}

PerceptionConfig PerceptionConfig::fromYamlFile(const std::filesystem::path& path) {
  const std::string source = "perception config '" + path.string() + "'";
  PerceptionConfig config;
  readYamlConfig(path, source, yamlKeys(), config);
  // Here, by its key: the maps size themselves from the region, and a radius of 1e9 m
  // failed later with a voxel count naming neither the key nor the file.
  const double radius = config.region.radius_m;
  requireKey(radius > 0.0 && radius <= kMaxRegionRadiusM, source, "region_radius_m",
             "a radius above 0 and at most " + formatNumber(kMaxRegionRadiusM) +
                 " m (one fruitlet cluster), got " + formatNumber(radius));
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(source + ": " + e.what());
  }
  return config;
}

}  // namespace fvp::host
