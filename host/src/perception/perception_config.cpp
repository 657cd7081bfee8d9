// PerceptionConfig::fromYamlFile: the keys a user sets for their own orchard and tags.
#include <functional>
#include <string>
#include <vector>

#include "fvp/host/core/yaml_config.h"
#include "fvp/host/perception/perception_pipeline.h"

namespace fvp::host {
namespace {

struct KeySpec {
  const char* name;
  std::function<void(PerceptionConfig&, const YAML::Node&, const std::string&)> read;
};

Eigen::Vector3d vector3(const YAML::Node& node, const std::string& where) {
  if (!node.IsSequence() || node.size() != 3)
    throw std::invalid_argument(where + ": expected a list of 3 numbers [x, y, z] in metres");
  return {readScalar<double>(node[0], where, "a number"),
          readScalar<double>(node[1], where, "a number"),
          readScalar<double>(node[2], where, "a number")};
}

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

const std::vector<KeySpec>& keySpecs() {
  static const std::vector<KeySpec> specs = {
      {"tag_family",
       [](auto& c, auto& n, auto& w) { c.tag.family = readScalar<std::string>(n, w, "a name"); }},
      {"tag_id",
       [](auto& c, auto& n, auto& w) { c.tag.tag_id = readScalar<int>(n, w, "an integer"); }},
      {"tag_size_m",
       [](auto& c, auto& n, auto& w) { c.tag.tag_size_m = readScalar<double>(n, w, "a number"); }},
      {"tag_max_hamming",
       [](auto& c, auto& n, auto& w) { c.tag.max_hamming = readScalar<int>(n, w, "an integer"); }},
      {"region_radius_m",
       [](auto& c, auto& n, auto& w) { c.region.radius_m = readScalar<double>(n, w, "a number"); }},
      {"region_offset_tag_m",
       [](auto& c, auto& n, auto& w) { c.region.center_offset_tag_m = vector3(n, w); }},
      {"region_center_m", [](auto& c, auto& n, auto& w) { c.region.center_m = vector3(n, w); }},
      {"hsv_fruitlet_hues_deg",
       [](auto& c, auto& n, auto& w) { c.segmentation.fruitlet_hues = hueRanges(n, w); }},
      {"hsv_min_saturation",
       [](auto& c, auto& n, auto& w) {
         c.segmentation.min_saturation = readScalar<int>(n, w, "an integer in [0, 255]");
       }},
      {"hsv_min_value",
       [](auto& c, auto& n, auto& w) {
         c.segmentation.min_value = readScalar<int>(n, w, "an integer in [0, 255]");
       }},
  };
  return specs;
}

}  // namespace

PerceptionConfig PerceptionConfig::fromYamlFile(const std::filesystem::path& path) {
  const std::string source = "perception config '" + path.string() + "'";
  const YAML::Node root = readYamlMapping(path, source);
  PerceptionConfig config;
  if (!root.IsNull())
    for (const auto& item : root) {
      const std::string key = keyString(item.first, source);
      findKeySpec(keySpecs(), key, source)
          .read(config, item.second, source + ": key '" + key + "'");
    }
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(source + ": " + e.what());
  }
  return config;
}

}  // namespace fvp::host
