#include "fvp/host/map/map_engine_registry.h"

#include <stdexcept>

#include "fvp/accel/backend.h"

#include "fvp/host/map/grid_map_engine.h"
#include "fvp/host/map/octomap_map_engine.h"

namespace fvp::host::map {

MapEngineRegistry::MapEngineRegistry() : NamedRegistry<MapEngineEntry>("map engine") {
  add({"grid", true,
       [](const MapConfig& config, const ClusterRegion& region, accel::Backend* backend) {
         return std::unique_ptr<MapEngine>(
             std::make_unique<GridMapEngine>(config, region, *backend));
       }});
  add({"octomap", false, [](const MapConfig& config, const ClusterRegion& region, accel::Backend*) {
         return std::unique_ptr<MapEngine>(std::make_unique<OctomapMapEngine>(config, region));
       }});
}

MapEngineRegistry& MapEngineRegistry::instance() {
  static MapEngineRegistry registry;
  return registry;
}

void MapEngineRegistry::add(MapEngineEntry entry) {
  if (!entry.create)
    throw std::invalid_argument("map engine registry: '" + entry.name + "' has no create function");
  NamedRegistry<MapEngineEntry>::add(std::move(entry));
}

bool mapEngineNeedsBackend(std::string_view engine) {
  return MapEngineRegistry::instance().at(engine).needs_backend;
}

std::unique_ptr<accel::Backend> createBackendFor(std::string_view engine,
                                                 accel::BackendChoice backend) {
  if (!mapEngineNeedsBackend(engine) && backend == accel::BackendChoice::kAuto) return nullptr;
  return accel::createBackend(backend);
}

}  // namespace fvp::host::map
