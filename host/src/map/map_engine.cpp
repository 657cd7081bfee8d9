#include "fvp/host/map/map_engine.h"

#include <chrono>
#include <stdexcept>
#include <string>

#include "fvp/host/map/map_engine_registry.h"

namespace fvp::host::map {

MapEngine::~MapEngine() = default;

ScanStats MapEngine::integrate(const LabeledClouds& clouds) {
  const auto t0 = std::chrono::steady_clock::now();
  ++scans_;
  ScanStats stats;
  const auto points = prepareScanPoints(clouds, config_.sensor_max_range_m, stats);
  integrateScan(clouds.sensor_origin_m, points, stats);
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return stats;
}

void MapEngine::moveToRegion(const ClusterRegion& region) {
  if (!(region.radius_m() > 0.0) || !region.center_m().allFinite())
    throw std::invalid_argument(
        "moveToRegion: the Cluster Region needs a finite centre and a positive radius");
  region_ = region;
  scenes_[1] = SceneState{};  // the fine scene described the old region's voxels
  placeFineMap();
  change_logs_[1] = BrickChangeLog(gridGeometry(MapLevel::kFine));  // a new epoch
}

BrickChangeLog& MapEngine::changeLog(MapLevel level) {
  BrickChangeLog& log = change_logs_[level == MapLevel::kCoarse ? 0 : 1];
  // Placed here, not in the constructor: the lattice comes from the engine (virtual).
  if (log.brickCount() == 0) log.reset(gridGeometry(level));
  return log;
}

BrickChanges MapEngine::changesSince(MapLevel level, const ChangeCursor& since) {
  syncChangeLogs();
  BrickChanges changes = changeLog(level).changesSince(since);
  if (!recordsBrickChanges()) {
    changes.all = true;
    changes.bricks.clear();
  }
  return changes;
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

void checkMapEngineChoice(std::string_view engine, const accel::Backend* backend) {
  const MapEngineEntry& entry = MapEngineRegistry::instance().at(engine);
  if (entry.needs_backend && !backend)
    throw std::invalid_argument("map engine '" + entry.name + "' needs a compute backend");
}

std::unique_ptr<MapEngine> createMapEngine(std::string_view engine, const MapConfig& config,
                                           const ClusterRegion& region, accel::Backend* backend) {
  checkMapEngineChoice(engine, backend);
  return MapEngineRegistry::instance().at(engine).create(config, region, backend);
}

}  // namespace fvp::host::map
