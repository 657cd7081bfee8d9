#include "fvp/host/planner/planner_registry.h"

#include <stdexcept>

#include "fvp/host/planner/fvp_planner.h"
#include "fvp/host/planner/planner_config.h"
#include "fvp/host/planner/rvp_config.h"
#include "fvp/host/planner/rvp_planner.h"

namespace fvp::host::planner {

PlannerRegistry::PlannerRegistry() : NamedRegistry<PlannerEntry>("planner") {
  add({"fvp",
       "FVP (ours)",
       "grid",
       [](const std::filesystem::path& yaml, std::uint64_t seed, accel::Backend* backend) {
         const PlannerConfig config =
             yaml.empty() ? PlannerConfig{} : PlannerConfig::fromYamlFile(yaml);
         return std::unique_ptr<ViewPlanner>(std::make_unique<FvpPlanner>(config, seed, backend));
       },
       {}});
  // RVP on OctoMap as the original: one 1 mm ROI octree over the whole observation space.
  // The grid engine has no whole-space fine map, so RVP on it plans on the coarse + fine
  // (Cluster Region) pair (docs/planner.md).
  add({"rvp", "RVP (ours)", "octomap",
       [](const std::filesystem::path& yaml, std::uint64_t seed, accel::Backend*) {
         const RvpConfig config = yaml.empty() ? RvpConfig{} : RvpConfig::fromYamlFile(yaml);
         return std::unique_ptr<ViewPlanner>(std::make_unique<RvpPlanner>(config, seed));
       },
       [](std::string_view engine) {
         map::MapConfig config;
         if (engine == "octomap") config.fine_map_extent = map::FineMapExtent::kObservationBox;
         return config;
       }});
}

PlannerRegistry& PlannerRegistry::instance() {
  static PlannerRegistry registry;
  return registry;
}

void PlannerRegistry::add(PlannerEntry entry) {
  if (!entry.create)
    throw std::invalid_argument("planner registry: '" + entry.name + "' has no create function");
  if (entry.label.empty()) entry.label = entry.name;
  if (entry.default_engine.empty()) entry.default_engine = "grid";
  NamedRegistry<PlannerEntry>::add(std::move(entry));
}

std::unique_ptr<ViewPlanner> createPlanner(std::string_view name,
                                           const std::filesystem::path& config_yaml,
                                           std::uint64_t seed, accel::Backend* backend) {
  return PlannerRegistry::instance().at(name).create(config_yaml, seed, backend);
}

map::MapConfig plannerMapConfig(std::string_view planner, std::string_view engine) {
  const PlannerEntry& entry = PlannerRegistry::instance().at(planner);
  return entry.map_config ? entry.map_config(engine) : map::MapConfig{};
}

}  // namespace fvp::host::planner
