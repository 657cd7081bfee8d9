#include "fvp/robot/sim/world_config.h"
#include "fvp/robot/sim/object_ids.h"

#include "fvp/host/core/yaml_config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <variant>

namespace fvp::robot::sim {
namespace {

using host::formatNumber;

using Member = std::variant<int WorldConfig::*, double WorldConfig::*>;

// One YAML key: its field, its static range [lo, hi] and, for min/max pairs, the key whose
// value bounds it from below (max_x >= min_x). The ranges guard against nonsense, not taste.
struct KeySpec {
  const char* name;
  Member member;
  double lo;
  double hi;
  const char* at_least_key = nullptr;
};

constexpr double kTagFamilyCodes = 587;  // tag36h11 has 587 codes: ids 0..586

const std::vector<KeySpec>& keySpecs() {
  static const std::vector<KeySpec> specs = {
      {"min_fruitlets", &WorldConfig::min_fruitlets, 1, kMaxFruitlets},
      {"max_fruitlets", &WorldConfig::max_fruitlets, 1, kMaxFruitlets, "min_fruitlets"},
      {"min_radius_m", &WorldConfig::min_radius_m, 0.0005, 0.05},
      {"max_radius_m", &WorldConfig::max_radius_m, 0.0005, 0.05, "min_radius_m"},
      {"min_elongation", &WorldConfig::min_elongation, 0.5, 2.0},
      {"max_elongation", &WorldConfig::max_elongation, 0.5, 2.0, "min_elongation"},
      {"cluster_spread_m", &WorldConfig::cluster_spread_m, 0.001, 0.2},
      {"min_gap_m", &WorldConfig::min_gap_m, 0.0, 0.02},
      {"leaf_count", &WorldConfig::leaf_count, 0, 1000},
      {"min_leaf_length_m", &WorldConfig::min_leaf_length_m, 0.005, 0.3},
      {"max_leaf_length_m", &WorldConfig::max_leaf_length_m, 0.005, 0.3, "min_leaf_length_m"},
      {"min_leaf_width_m", &WorldConfig::min_leaf_width_m, 0.002, 0.3},
      {"max_leaf_width_m", &WorldConfig::max_leaf_width_m, 0.002, 0.3, "min_leaf_width_m"},
      {"leaf_region_m", &WorldConfig::leaf_region_m, 0.01, 1.0},
      {"max_leaf_curl_per_m", &WorldConfig::max_leaf_curl_per_m, 0.0, 50.0},
      {"front_leaf_fraction", &WorldConfig::front_leaf_fraction, 0.0, 1.0},
      {"tag_id", &WorldConfig::tag_id, 0, kTagFamilyCodes - 1},
      {"tag_size_m", &WorldConfig::tag_size_m, 0.005, 0.2},
      {"min_tag_distance_m", &WorldConfig::min_tag_distance_m, 0.0, 0.5},
      {"max_tag_distance_m", &WorldConfig::max_tag_distance_m, 0.0, 0.2, "min_tag_distance_m"},
      {"max_tag_tilt_deg", &WorldConfig::max_tag_tilt_deg, 0.0, 60.0},
      {"tag_side", &WorldConfig::tag_side, -1, 1},
      {"trunk_radius_m", &WorldConfig::trunk_radius_m, 0.005,
       0.15},  // the cluster hangs 0.2 m+ out
      {"trunk_height_m", &WorldConfig::trunk_height_m, 0.1, 10.0},
      {"cluster_height_m", &WorldConfig::cluster_height_m, 0.05, 10.0},
      {"branch_radius_m", &WorldConfig::branch_radius_m, 0.001, 0.1},
      {"extra_branch_count", &WorldConfig::extra_branch_count, 0, 20},
      {"cluster_count", &WorldConfig::cluster_count, 1, 8},
      {"min_cluster_spacing_m", &WorldConfig::min_cluster_spacing_m, 0.01, 2.0},
      {"cluster_height_spread_m", &WorldConfig::cluster_height_spread_m, 0.0, 2.0},
      {"start_view_distance_m", &WorldConfig::start_view_distance_m, 0.05, 5.0},
      // Errors of centimetres or degrees are a broken robot, not one to size fruitlets with.
      {"hand_eye_translation_sigma_m", &WorldConfig::hand_eye_translation_sigma_m, 0.0, 0.02},
      {"hand_eye_rotation_sigma_deg", &WorldConfig::hand_eye_rotation_sigma_deg, 0.0, 5.0},
      {"arm_position_error_m", &WorldConfig::arm_position_error_m, 0.0, 0.02},
      {"view_translation_sigma_m", &WorldConfig::view_translation_sigma_m, 0.0, 0.02},
      {"view_rotation_sigma_deg", &WorldConfig::view_rotation_sigma_deg, 0.0, 5.0},
      {"stereo_baseline_error", &WorldConfig::stereo_baseline_error, -0.05, 0.05},
      {"stereo_vertical_misalignment_px", &WorldConfig::stereo_vertical_misalignment_px, -5.0, 5.0},
      // Gusts that move leaf tips by centimetres blur any camera: no sizing then.
      {"wind_leaf_tip_m", &WorldConfig::wind_leaf_tip_m, 0.0, 0.02},
      {"wind_fruitlet_swing_m", &WorldConfig::wind_fruitlet_swing_m, 0.0, 0.01},
      {"fruitlet_green_fraction", &WorldConfig::fruitlet_green_fraction, 0.0, 1.0},
      {"segmentation_model", &WorldConfig::segmentation_model, 0, 1},
      {"segmentation_instances", &WorldConfig::segmentation_instances, 0, 1},
      {"segmentation_boundary_px", &WorldConfig::segmentation_boundary_px, 0.0, 5.0},
      {"segmentation_miss_rate", &WorldConfig::segmentation_miss_rate, 0.0, 0.9},
      {"segmentation_false_blobs", &WorldConfig::segmentation_false_blobs, 0.0, 20.0},
      // Ten times the flash saturates every lit surface: no camera would be exposed so.
      {"sun_strength", &WorldConfig::sun_strength, 0.0, 10.0},
      {"season_day", &WorldConfig::season_day, 0.0, kMaxSeasonDay},
      {"min_fastest_growth_mm_per_day", &WorldConfig::min_fastest_growth_mm_per_day, 0.0, 3.0},
      {"max_fastest_growth_mm_per_day", &WorldConfig::max_fastest_growth_mm_per_day, 0.0, 3.0,
       "min_fastest_growth_mm_per_day"},
      {"abscission_probability", &WorldConfig::abscission_probability, 0.0, 1.0},
      {"run_register_views", &WorldConfig::run_register_views, 0, 1},
  };
  return specs;
}

/// The file's keys: each spec's member read as its type.
const std::vector<host::YamlKey<WorldConfig>>& yamlKeys() {
  static const std::vector<host::YamlKey<WorldConfig>> keys = [] {
    std::vector<host::YamlKey<WorldConfig>> out;
    for (const KeySpec& spec : keySpecs())
      std::visit([&](auto member) { out.push_back(host::yamlField(spec.name, member)); },
                 spec.member);
    return out;
  }();
  return keys;
}

double valueOf(const WorldConfig& config, const Member& member) {
  return std::visit([&](auto field) { return static_cast<double>(config.*field); }, member);
}

const KeySpec& specNamed(const std::string& name) {
  for (const KeySpec& spec : keySpecs()) {
    if (name == spec.name) return spec;
  }
  throw std::logic_error("world config: no key spec named '" + name + "'");
}

}  // namespace

const std::vector<std::string>& WorldConfig::keyNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const KeySpec& spec : keySpecs()) out.emplace_back(spec.name);
    return out;
  }();
  return names;
}

void WorldConfig::validate(const std::string& source) const {
  for (const KeySpec& spec : keySpecs()) {
    const double value = valueOf(*this, spec.member);
    double lo = spec.lo;
    std::string lo_text = formatNumber(spec.lo);
    if (spec.at_least_key != nullptr) {
      const double other = valueOf(*this, specNamed(spec.at_least_key).member);
      if (other > lo) {
        lo = other;
        lo_text = std::string(spec.at_least_key) + " (" + formatNumber(other) + ")";
      }
    }
    // `!(a <= b)` also rejects NaN.
    if (!(value >= lo) || !(value <= spec.hi)) {
      throw std::invalid_argument(source + ": key '" + spec.name + "' = " + formatNumber(value) +
                                  " is out of range; expected " + lo_text + " <= " + spec.name +
                                  " <= " + formatNumber(spec.hi));
    }
  }
  if (cluster_count * max_fruitlets > kMaxFruitlets) {
    throw std::invalid_argument(source + ": cluster_count (" + formatNumber(cluster_count) +
                                ") x max_fruitlets (" + formatNumber(max_fruitlets) +
                                "): expected at most " + formatNumber(kMaxFruitlets) +
                                " fruitlets in a world (the renderer's object ids)");
  }
  if (tag_id + cluster_count > kTagFamilyCodes) {
    throw std::invalid_argument(source + ": tag_id (" + formatNumber(tag_id) +
                                ") + cluster_count (" + formatNumber(cluster_count) +
                                "): cluster k carries tag id tag_id + k, "
                                "expected at most 586 (tag36h11)");
  }
  if (cluster_height_m > trunk_height_m) {
    throw std::invalid_argument(source + ": cluster_height_m = " + formatNumber(cluster_height_m) +
                                ": expected at most trunk_height_m (" +
                                formatNumber(trunk_height_m) +
                                "): the fruiting branch leaves the trunk");
  }
}

WorldConfig WorldConfig::fromYamlFile(const std::filesystem::path& path) {
  const std::string source = "world config '" + path.string() + "'";
  WorldConfig config;
  host::readYamlConfig(path, source, yamlKeys(), config);
  config.validate(source);
  return config;
}

namespace {

const std::vector<std::pair<std::string, std::vector<std::string>>>& errorGroupMembers() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> members = {
      {"pose",
       {"hand_eye_translation_sigma_m", "hand_eye_rotation_sigma_deg", "arm_position_error_m",
        "view_translation_sigma_m", "view_rotation_sigma_deg"}},
      {"stereo", {"stereo_baseline_error", "stereo_vertical_misalignment_px"}},
      {"wind", {"wind_leaf_tip_m", "wind_fruitlet_swing_m"}},
      {"segmentation",
       {"segmentation_boundary_px", "segmentation_miss_rate", "segmentation_false_blobs"}},
      {"light", {"sun_strength"}}};
  return members;
}

/// The largest factor that keeps `value` x factor within [lo, hi] (value != 0).
double largestFactor(double value, double lo, double hi) {
  return value > 0 ? hi / value : lo / value;
}

}  // namespace

const std::vector<std::string>& WorldConfig::errorGroups() {
  static const std::vector<std::string> groups = [] {
    std::vector<std::string> out;
    for (const auto& [name, keys] : errorGroupMembers()) out.push_back(name);
    out.push_back("all");
    return out;
  }();
  return groups;
}

WorldConfig WorldConfig::withErrorsScaled(const std::string& group, double factor) const {
  if (!(factor >= 0.0) || !std::isfinite(factor))
    throw std::invalid_argument("error scale: expected a factor >= 0, got " + formatNumber(factor));
  const bool all = group == "all";
  bool known = all;
  // First the largest factor every magnitude of the group allows: a clamped magnitude
  // would make the sweep point another factor than the one the manifest records.
  std::vector<std::pair<double WorldConfig::*, const KeySpec*>> scaled;
  double limit = HUGE_VAL;
  const KeySpec* limiting = nullptr;
  for (const auto& [name, keys] : errorGroupMembers()) {
    if (!all && name != group) continue;
    known = true;
    for (const std::string& key : keys) {
      const KeySpec& spec = specNamed(key);
      const auto* field = std::get_if<double WorldConfig::*>(&spec.member);
      if (!field) continue;
      scaled.emplace_back(*field, &spec);
      const double value = this->**field;
      if (value != 0.0 && largestFactor(value, spec.lo, spec.hi) < limit) {
        limit = largestFactor(value, spec.lo, spec.hi);
        limiting = &spec;
      }
    }
  }
  if (!known)
    throw std::invalid_argument("error scale: unknown error group '" + group +
                                "'; expected pose, stereo, wind, segmentation, light or all");
  if (factor > limit) {
    const double value = this->*std::get<double WorldConfig::*>(limiting->member);
    throw std::invalid_argument(
        "error scale " + group + "=" + formatNumber(factor) + ": " + limiting->name + " would be " +
        formatNumber(value * factor) + " (" + formatNumber(value) + " x " + formatNumber(factor) +
        "), outside its range " + formatNumber(limiting->lo) + " to " + formatNumber(limiting->hi) +
        "; the largest factor this world config allows for " + group + " is " +
        formatNumber(limit));
  }
  WorldConfig out = *this;
  // The clamp only absorbs rounding at factor == limit.
  for (const auto& [field, spec] : scaled)
    out.*field = std::clamp(this->*field * factor, spec->lo, spec->hi);
  return out;
}

std::string WorldConfig::toJson() const {
  return host::yamlConfigJson(yamlKeys(), *this).dump();
}

bool operator==(const WorldConfig&, const WorldConfig&) = default;

}  // namespace fvp::robot::sim
