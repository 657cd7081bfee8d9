#include "fvp/robot/arm_config.h"

#include "fvp/host/core/yaml_config.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <variant>

namespace fvp::robot {
namespace {

using host::formatNumber;

using Member = std::variant<double ArmConfig::*, int ArmConfig::*, std::int64_t ArmConfig::*,
                            std::string ArmConfig::*, Eigen::Vector3d ArmConfig::*>;

// One YAML key: its field and the static range of each numeric value (vectors: per
// component). The ranges guard against nonsense, not taste.
struct KeySpec {
  const char* name;
  Member member;
  double lo = 0.0;
  double hi = 0.0;
};

const std::vector<KeySpec>& keySpecs() {
  static const std::vector<KeySpec> specs = {
      {"slider_travel_m", &ArmConfig::slider_travel_m, 0.0, 10.0},
      {"slider_origin_m", &ArmConfig::slider_origin_m, -10.0, 10.0},
      {"slider_yaw_deg", &ArmConfig::slider_yaw_deg, -360.0, 360.0},
      {"base_yaw_deg", &ArmConfig::base_yaw_deg, -360.0, 360.0},
      {"slider_max_velocity_m_s", &ArmConfig::slider_max_velocity_m_s, 1e-3, 5.0},
      {"slider_max_acceleration_m_s2", &ArmConfig::slider_max_acceleration_m_s2, 1e-3, 50.0},
      {"joint_limit_rad", &ArmConfig::joint_limit_rad, 0.1, 2.0 * std::numbers::pi},
      {"elbow_limit_rad", &ArmConfig::elbow_limit_rad, 0.1, std::numbers::pi},
      {"joint_max_velocity_rad_s", &ArmConfig::joint_max_velocity_rad_s, 1e-3, std::numbers::pi},
      {"joint_max_acceleration_rad_s2", &ArmConfig::joint_max_acceleration_rad_s2, 1e-3, 40.0},
      {"hand_eye_translation_m", &ArmConfig::hand_eye_translation_m, -0.5, 0.5},
      {"hand_eye_rpy_deg", &ArmConfig::hand_eye_rpy_deg, -360.0, 360.0},
      {"camera_body_radius_m", &ArmConfig::camera_body_radius_m, 0.0, 0.2},
      {"collision_padding_m", &ArmConfig::collision_padding_m, 0.0, 0.2},
      {"ground_z_m", &ArmConfig::ground_z_m, -10.0, 10.0},
      {"ik_slider_samples", &ArmConfig::ik_slider_samples, 1, 1000},
      {"planner", &ArmConfig::planner},
      {"planning_time_s", &ArmConfig::planning_time_s, 1e-3, 600.0},
      {"simplify_time_s", &ArmConfig::simplify_time_s, 0.0, 60.0},
      {"reproducible_planning_checks", &ArmConfig::reproducible_planning_checks, 100, 1e9},
      {"reproducible_simplify_checks", &ArmConfig::reproducible_simplify_checks, 0, 1e9},
      {"validity_step_rad", &ArmConfig::validity_step_rad, 1e-4, 0.5},
      {"retreat_share", &ArmConfig::retreat_share, 0.0, 0.5},
      {"trajectory_timing", &ArmConfig::trajectory_timing},
      {"workspace_samples", &ArmConfig::workspace_samples, 1000, 1e10},
      {"workspace_resolution_m", &ArmConfig::workspace_resolution_m, 0.005, 0.5},
      {"workspace_direction_bins", &ArmConfig::workspace_direction_bins, 1, 16},
      {"workspace_min_count", &ArmConfig::workspace_min_count, 1, 65535},
      {"workspace_seed", &ArmConfig::workspace_seed, 0, 9e15},
      {"workspace_cache_dir", &ArmConfig::workspace_cache_dir},
  };
  return specs;
}

/// The file's keys: each spec's member read as its type.
const std::vector<host::YamlKey<ArmConfig>>& yamlKeys() {
  static const std::vector<host::YamlKey<ArmConfig>> keys = [] {
    std::vector<host::YamlKey<ArmConfig>> out;
    for (const KeySpec& spec : keySpecs())
      std::visit([&](auto member) { out.push_back(host::yamlField(spec.name, member)); },
                 spec.member);
    return out;
  }();
  return keys;
}

void checkRange(const std::string& source, const KeySpec& spec, double value) {
  // `!(a <= b)` also rejects NaN.
  if (!(value >= spec.lo) || !(value <= spec.hi)) {
    throw std::invalid_argument(source + ": key '" + spec.name + "' = " + formatNumber(value) +
                                " is out of range; expected " + formatNumber(spec.lo) +
                                " <= " + spec.name + " <= " + formatNumber(spec.hi));
  }
}

}  // namespace

const std::vector<std::string>& knownPlanners() {
  static const std::vector<std::string> names = {
      "RRTConnect", "RRT", "RRTstar", "PRM", "KPIECE1", "BKPIECE1", "LBKPIECE1", "EST", "SBL"};
  return names;
}

const std::vector<std::string>& ArmConfig::keyNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const KeySpec& spec : keySpecs()) out.emplace_back(spec.name);
    return out;
  }();
  return names;
}

void ArmConfig::validate(const std::string& source) const {
  for (const KeySpec& spec : keySpecs()) {
    std::visit(
        [&](auto field) {
          using T = std::decay_t<decltype(this->*field)>;
          if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
            for (int i = 0; i < 3; ++i) checkRange(source, spec, (this->*field)[i]);
          } else if constexpr (std::is_arithmetic_v<T>) {
            checkRange(source, spec, static_cast<double>(this->*field));
          }
        },
        spec.member);
  }
  bool planner_known = false;
  for (const std::string& name : knownPlanners()) planner_known |= name == planner;
  if (!planner_known) {
    std::string list;
    for (const std::string& name : knownPlanners()) list += (list.empty() ? "" : ", ") + name;
    throw std::invalid_argument(source + ": key 'planner' = '" + planner +
                                "' is not a known OMPL planner; expected one of " + list);
  }
  if (trajectory_timing != "rest_to_rest" && trajectory_timing != "blended")
    throw std::invalid_argument(source + ": key 'trajectory_timing' = '" + trajectory_timing +
                                "' is not a timing; expected rest_to_rest or blended");
  if (const std::uint64_t bytes = workspaceTreeBytes(); bytes > kMaxWorkspaceTreeBytes)
    throw std::invalid_argument(
        source + ": keys 'workspace_resolution_m' = " + formatNumber(workspace_resolution_m) +
        ", 'workspace_direction_bins' = " + std::to_string(workspace_direction_bins) +
        " and 'workspace_samples' = " + std::to_string(workspace_samples) +
        " ask for a workspace tree of " + formatNumber(double(bytes) / double(1 << 30)) +
        " GiB; expected at most " + std::to_string(kMaxWorkspaceTreeBytes >> 30) +
        " GiB (a coarser resolution or fewer bins)");
}

std::uint64_t ArmConfig::workspaceTreeBytes() const {
  // As WorkspaceTree::build lays it out: one slot a sample, counts over the arm grid, then
  // the grid swept along the slider (16-bit counts) and a flag a cell.
  const double reach = kUr5ReachM + hand_eye_translation_m.norm() + camera_body_radius_m;
  const double arm_cells = std::ceil(2.0 * reach / workspace_resolution_m);
  const double shifts = std::round(slider_travel_m / workspace_resolution_m);
  const double bins = 6.0 * workspace_direction_bins * workspace_direction_bins;
  const double arm_total = arm_cells * arm_cells * arm_cells;
  const double cells = (arm_cells + shifts) * arm_cells * arm_cells;
  const double bytes =
      4.0 * double(workspace_samples) + 4.0 * arm_total * bins + 2.0 * cells * bins + cells;
  return bytes >= 1.8e19 ? UINT64_MAX : static_cast<std::uint64_t>(bytes);
}

ArmConfig ArmConfig::fromYamlFile(const std::filesystem::path& path) {
  const std::string source = "arm config '" + path.string() + "'";
  ArmConfig config;
  host::readYamlConfig(path, source, yamlKeys(), config);
  config.validate(source);
  return config;
}

std::string ArmConfig::toJson() const {
  // workspace_cache_dir is a path: any bytes (a YAML file's, $HOME's), not always UTF-8, which
  // JSON needs. Invalid bytes become U+FFFD instead of a type_error thrown at the end of a run.
  return host::yamlConfigJson(yamlKeys(), *this)
      .dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace fvp::robot
