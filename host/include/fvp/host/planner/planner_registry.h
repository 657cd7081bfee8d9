// Viewpoint planners by name (OMPL's planner allocators are the model): `fvp run --planner`,
// `fvp plan`, the experiment runner and the Python module create planners only through
// here, so a new planner is one class and one entry. FVP and RVP are built in; a program can
// add its own before it creates one.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "fvp/host/core/named_registry.h"
#include "fvp/host/map/map_config.h"
#include "fvp/host/planner/view_planner.h"

namespace fvp::accel {
class Backend;
}

namespace fvp::host::planner {

struct PlannerEntry {
  std::string name;            ///< what --planner takes, e.g. "fvp"
  std::string label;           ///< in tables and figures, e.g. "FVP (ours)"
  std::string default_engine;  ///< the map engine it runs on unless told otherwise
  /// Reads and checks the planner's YAML config (an empty path: the defaults) and creates
  /// the planner. seed: the trial's; backend: where its kernels may run (may be null).
  /// Throws std::invalid_argument / std::runtime_error for a bad config.
  std::function<std::unique_ptr<ViewPlanner>(const std::filesystem::path& config_yaml,
                                             std::uint64_t seed, accel::Backend* backend)>
      create;
  /// The maps it plans on with a given engine (default: MapConfig{}).
  std::function<map::MapConfig(std::string_view engine)> map_config;
};

class PlannerRegistry : public NamedRegistry<PlannerEntry> {
 public:
  /// The process's registry, holding the built-in entries.
  static PlannerRegistry& instance();

  /// Also throws std::invalid_argument when create is missing.
  void add(PlannerEntry entry);

 private:
  PlannerRegistry();
};

/// PlannerRegistry::instance().at(name).create(config_yaml, seed, backend).
std::unique_ptr<ViewPlanner> createPlanner(std::string_view name,
                                           const std::filesystem::path& config_yaml,
                                           std::uint64_t seed, accel::Backend* backend);
/// The planner's map config for an engine.
map::MapConfig plannerMapConfig(std::string_view planner, std::string_view engine);

}  // namespace fvp::host::planner
