// One planning iteration on a simulated map (docs/design.md section 9, `fvp plan`): a world from
// a seed, a map from K views orbiting the cluster, then one planAndMove of the chosen planner
// with the workspace tree as the reachability filter and the real motion planner moving the
// arm from the world's start configuration. Writes plan.json and candidates.ply (camera
// positions coloured by utility) so people can inspect and tune a planner.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "fvp/accel/backend_choice.h"

namespace fvp::trials {

struct PlanOnceOptions {
  std::string planner = "fvp";  ///< fvp | rvp
  std::uint64_t seed = 1;
  int views = 5;  ///< K views over a 90 degree arc around the cluster
  accel::BackendChoice backend = accel::BackendChoice::kAuto;
  std::string engine;  ///< empty: the planner's default
  std::filesystem::path world_config, planner_config;
  std::filesystem::path out_dir;  ///< plan.json, candidates.ply
  /// A robot's capture set (docs/capture-format.md) instead of simulated views: the map
  /// from every capture, the camera at the last capture's pose; every candidate is taken
  /// as reachable (the robot's own planner makes the move) and the best is chosen.
  std::filesystem::path captures_dir;
  std::filesystem::path perception_config;  ///< tag, Cluster Region, HSV (fvp size --config)
};

/// Returns plan.json's object: {"chosen", "candidates": [{"kind", "position_m", "target_m",
/// "ig", "utility", "reachable"}], "timings_s", "config", ...}.
nlohmann::json planOnce(const PlanOnceOptions& options);

}  // namespace fvp::trials
