#include "fvp/host/map/map_engine.h"

#include <stdexcept>
#include <string>

#include "fvp/host/map/grid_map_engine.h"
#include "fvp/host/map/octomap_map_engine.h"

namespace fvp::host::map {

std::unique_ptr<MapEngine> createMapEngine(std::string_view engine, const MapConfig& config,
                                           const ClusterRegion& region, accel::Backend* backend) {
  if (engine == "grid") {
    if (!backend) throw std::invalid_argument("map engine 'grid' needs a compute backend");
    return std::make_unique<GridMapEngine>(config, region, *backend);
  }
  if (engine == "octomap") return std::make_unique<OctomapMapEngine>(config, region);
  throw std::invalid_argument("unknown map engine '" + std::string(engine) +
                              "': expected grid or octomap");
}

}  // namespace fvp::host::map
