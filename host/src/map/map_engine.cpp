#include "fvp/host/map/map_engine.h"

#include <stdexcept>
#include <string>

#include "fvp/host/map/grid_map_engine.h"
#include "fvp/host/map/octomap_map_engine.h"

namespace fvp::host::map {

MapEngine::~MapEngine() = default;

ScanStats MapEngine::integrate(const Eigen::Vector3d& sensor_origin_m,
                               const std::vector<Eigen::Vector3f>& roi_points_m,
                               const std::vector<Eigen::Vector3f>& other_points_m) {
  ++scans_;
  return integrateScan(sensor_origin_m, roi_points_m, other_points_m);
}

const OccupiedVoxelScene& MapEngine::occupiedScene(MapLevel level) {
  SceneState& state = scenes_[level == MapLevel::kCoarse ? 0 : 1];
  const bool fresh = !state.scene;
  if (fresh) state.scene = std::make_unique<OccupiedVoxelScene>(gridGeometry(level));
  if (fresh || state.synced_scans != scans_) {
    refreshScene(level, *state.scene, fresh);
    state.scene->commit();
    state.synced_scans = scans_;
  }
  return *state.scene;
}

void MapEngine::refreshScene(MapLevel level, OccupiedVoxelScene& scene, bool) {
  scene.assignOccupied(occupiedVoxels(level));
}

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
