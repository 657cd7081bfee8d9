// RVP's parameters (the baseline planner, rvp_planner.h): every field is a key of the same
// name in host/config/rvp_default.yaml, which documents the defaults. Kept apart from the
// planner so the reader builds on its own (yaml-cpp, nlohmann_json).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace fvp::host::planner {

struct RvpConfig {
  int roi_samples = 100;          ///< paper's protocol
  int exploration_samples = 100;  ///< paper's protocol
  double sensor_min_m = 0.3;      ///< Zaenker's sensor range
  double sensor_max_m = 0.5;
  double alpha_per_m = 0.2;            ///< utility = IG - alpha * distance
  double roi_utility_threshold = 0.2;  ///< the ROI set is used above this
  int exploration_rays_x = 8, exploration_rays_y = 6;
  double exploration_fov_x_deg = 80.0;
  /// Half-edge of the box around the Cluster Region centre that exploration positions are
  /// drawn from (the reachable workspace near the cluster; reachability filters it).
  double exploration_box_half_m = 0.5;
  std::int64_t seed = 1;
  static RvpConfig fromYamlFile(const std::filesystem::path& path);
  void validate(const std::string& source = "rvp config") const;
  std::string toJson() const;
};

}  // namespace fvp::host::planner
