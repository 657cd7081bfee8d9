#include "fvp/host/map/grid_map_engine.h"

#include <octomap/OcTree.h>

#include <cmath>
#include <stdexcept>

#include "fvp/host/map/octomap_io.h"
#include "fvp/host/map/roi_octree.h"

namespace fvp::host::map {
namespace {

BrickAllocation allocationFor(const GridGeometry& g) {
  return g.voxelCount() <= kDefaultUpFrontVoxelLimit ? BrickAllocation::kUpFront
                                                     : BrickAllocation::kOnTouch;
}

// Validates before any member is built from the config.
const MapConfig& validated(const MapConfig& config) {
  config.validate();
  if (config.fine_map_extent != FineMapExtent::kClusterRegion)
    throw std::invalid_argument(
        "grid engine: fine_map_extent observation_box is not supported (its fine map is the "
        "Cluster Region's dense cube); use the octomap engine");
  return config;
}

}  // namespace

GridMapEngine::FineLevel::FineLevel(accel::Backend& backend, const MapConfig& config,
                                    const ClusterRegion& region)
    : layer(backend, fineGridGeometry(config, region), /*with_roi=*/true,
            regionInGrid(fineGridGeometry(config, region), region),
            allocationFor(fineGridGeometry(config, region))),
      integrator(layer),
      distance(layer),
      frontiers(layer) {}

GridMapEngine::GridMapEngine(const MapConfig& config, const ClusterRegion& region,
                             accel::Backend& backend)
    : MapEngine(validated(config), region),
      backend_(backend),
      coarse_(backend, coarseGridGeometry(config), /*with_roi=*/false, std::nullopt,
              allocationFor(coarseGridGeometry(config))),
      coarse_integrator_(coarse_),
      fine_(std::make_unique<FineLevel>(backend, config, region)) {}

void GridMapEngine::placeFineMap() {
  fine_ = std::make_unique<FineLevel>(backend_, config(), region());
  distance_max_d_m_ = -1.0;
  scene_change_[1] = 0;
  log_change_[1] = 0;
}

void GridMapEngine::syncChangeLogs() {
  for (MapLevel level : {MapLevel::kCoarse, MapLevel::kFine}) {
    const BrickLayer& bricks =
        level == MapLevel::kCoarse ? coarse_.bricks() : fine_->layer.bricks();
    std::uint64_t& synced = log_change_[level == MapLevel::kCoarse ? 0 : 1];
    if (synced == bricks.changeCount()) continue;
    // The layer stamps allocated bricks; the log counts bricks of the grid's table.
    const auto& stamps = bricks.brickChangeStamps();
    const auto& coords = bricks.brickCoords();
    std::vector<int> changed;
    for (std::size_t b = 0; b < stamps.size(); ++b)
      if (stamps[b] > synced)
        changed.push_back(bricks.brickIndex(coords[3 * b], coords[3 * b + 1], coords[3 * b + 2]));
    changeLog(level).markBricks(changed);
    synced = bricks.changeCount();
  }
}

void GridMapEngine::integrateScan(const Eigen::Vector3d& sensor_origin_m,
                                  const std::vector<accel::ScanPoint>& points, ScanStats& stats) {
  // Every end point lies within max range of the sensor; the exact walk needs it within
  // 8192 voxels of each grid's corner (fvp_dda.h), else its rays would be dropped.
  for (const OccupancyLayer* layer : {&coarse_, &fine_->layer}) {
    const GridGeometry& g = layer->geometry();
    for (int a = 0; a < 3; ++a) {
      const double from_corner_vox =
          std::abs(sensor_origin_m[a] / g.voxel_size_m - static_cast<double>(g.first_voxel[a])) +
          config().sensor_max_range_m / g.voxel_size_m;
      if (!(from_corner_vox < 8000.0)) {
        throw std::invalid_argument("map integration: sensor origin " +
                                    std::to_string(sensor_origin_m[a]) + " m (axis " +
                                    std::to_string(a) + ") plus sensor_max_range_m lies " +
                                    std::to_string(from_corner_vox) +
                                    " voxels from a map's corner; at most 8000 are walked exactly");
      }
    }
  }
  if (!points.empty() && sensor_origin_m.allFinite()) {
    auto buffer = backend_.createBufferFrom(points);
    const Eigen::Vector3f sensor = sensor_origin_m.cast<float>();
    const auto n = static_cast<std::uint32_t>(points.size());
    stats.coarse_voxels_updated = coarse_integrator_.integrate(*buffer, n, sensor, config().model);
    stats.fine_voxels_updated = fine_->integrator.integrate(*buffer, n, sensor, config().model);
  }
}

VoxelClass GridMapEngine::coarseClass(const Eigen::Vector3d& p_m) const {
  std::array<int, 3> index;
  if (!coarse_.geometry().gridIndex(p_m, index)) return VoxelClass::kUnknown;
  return classifyLogOdds(coarse_.occupancyAt(index), config().model.occupiedLogOdds());
}

VoxelState GridMapEngine::fineState(const Eigen::Vector3d& p_m) const {
  std::array<int, 3> index;
  if (!fine_->layer.geometry().gridIndex(p_m, index)) return {};
  VoxelState s;
  s.occupancy = classifyLogOdds(fine_->layer.occupancyAt(index), config().model.occupiedLogOdds());
  s.roi = s.occupancy != VoxelClass::kUnknown && fine_->layer.roiAt(index) > 0.0f;
  return s;
}

// Exports build the same OctoMap trees the octomap engine holds and write them with its
// writers (octomap_io.h), so both engines produce interchangeable files.
void GridMapEngine::exportCoarse(const std::filesystem::path& bt_path) const {
  octomap::OcTree tree(config().coarse_voxel_size_m);
  tree.setOccupancyThres(config().model.occupied_prob);
  writeCoarseBricks(tree, 0);
  writeCoarseBt(tree, bt_path);
}

void GridMapEngine::exportFine(const std::filesystem::path& ot_path) const {
  RoiOcTree tree(config().fine_voxel_size_m);
  tree.setOccupancyThres(config().model.occupied_prob);
  fine_->layer.forEachVoxel([&](const std::array<int, 3>& index, float occupancy, float roi) {
    if (std::isnan(occupancy)) return;
    const Eigen::Vector3d c = fine_->layer.geometry().voxelCenter_m(index);
    RoiOcTreeNode* node =
        tree.setNodeValue(octomap::point3d(c.x(), c.y(), c.z()), occupancy, /*lazy_eval=*/true);
    node->setRoiLogOdds(std::isnan(roi) ? 0.0f : roi);
  });
  tree.updateInnerOccupancy();
  writeFineOt(tree, ot_path);
}

const GridGeometry& GridMapEngine::gridGeometry(MapLevel level) const {
  return level == MapLevel::kCoarse ? coarse_.geometry() : fine_->layer.geometry();
}

std::vector<std::array<int, 3>> GridMapEngine::occupiedVoxels(MapLevel level) const {
  const OccupancyLayer& grid = level == MapLevel::kCoarse ? coarse_ : fine_->layer;
  const float occupied = config().model.occupiedLogOdds();
  std::vector<std::array<int, 3>> voxels;
  grid.forEachVoxel([&](const std::array<int, 3>& index, float occupancy, float) {
    if (classifyLogOdds(occupancy, occupied) == VoxelClass::kOccupied) voxels.push_back(index);
  });
  return voxels;
}

void GridMapEngine::updateRoiDistance(double max_d_m) {
  if (!(max_d_m > 0.0)) throw std::invalid_argument("updateRoiDistance: max_d_m must be positive");
  if (distance_max_d_m_ == max_d_m && fine_->distance.current()) return;
  const double voxel = fine_->layer.geometry().voxel_size_m;
  const int radius_vox = std::max(1, static_cast<int>(std::ceil(max_d_m / voxel)));
  fine_->distance.compute(radius_vox);
  // d_i enters what readers derive from the fine map (the gain snapshot's weights).
  const BrickLayer& bricks = fine_->layer.bricks();
  std::vector<int> changed;
  for (std::uint32_t b : fine_->distance.changedBricks()) {
    const int* c = &bricks.brickCoords()[3 * std::size_t(b)];
    changed.push_back(bricks.brickIndex(c[0], c[1], c[2]));
  }
  changeLog(MapLevel::kFine).markBricks(changed);
  distance_max_d_m_ = max_d_m;
}

double GridMapEngine::roiDistance_m(const std::array<int, 3>& fine_index) const {
  if (distance_max_d_m_ < 0.0)
    throw std::logic_error("roiDistance_m: call updateRoiDistance() first");
  // Outside the grid distanceVoxAt gives the cap radius, ceil(max_d / voxel): max_d here.
  return std::min(fine_->distance.distanceVoxAt(fine_index) * fine_->layer.geometry().voxel_size_m,
                  distance_max_d_m_);
}

std::vector<FrontierVoxel> GridMapEngine::frontiers() {
  return fine_->frontiers.extract(config().model.occupiedLogOdds());
}

void GridMapEngine::writeCoarseBricks(octomap::OcTree& tree, std::uint64_t since) const {
  const auto& stamps = coarse_.bricks().brickChangeStamps();
  for (std::size_t b = 0; b < stamps.size(); ++b) {
    if (stamps[b] <= since) continue;
    coarse_.forEachVoxelOfBrick(b, [&](const std::array<int, 3>& index, float occupancy, float) {
      if (std::isnan(occupancy)) return;
      const Eigen::Vector3d c = coarse_.geometry().voxelCenter_m(index);
      tree.setNodeValue(octomap::point3d(c.x(), c.y(), c.z()), occupancy, /*lazy_eval=*/true);
    });
  }
  tree.updateInnerOccupancy();
}

const octomap::OcTree& GridMapEngine::coarseOcTree() {
  if (!coarse_tree_) {
    coarse_tree_ = std::make_unique<octomap::OcTree>(config().coarse_voxel_size_m);
    coarse_tree_->setOccupancyThres(config().model.occupied_prob);
    coarse_tree_change_ = 0;
  }
  // Known voxels stay known: changed bricks only overwrite values.
  if (coarse_tree_change_ != coarse_.bricks().changeCount()) {
    writeCoarseBricks(*coarse_tree_, coarse_tree_change_);
    coarse_tree_change_ = coarse_.bricks().changeCount();
  }
  return *coarse_tree_;
}

void GridMapEngine::refreshScene(MapLevel level, OccupiedVoxelScene& scene, bool fresh) {
  const OccupancyLayer& layer = level == MapLevel::kCoarse ? coarse_ : fine_->layer;
  std::uint64_t& synced = scene_change_[level == MapLevel::kCoarse ? 0 : 1];
  if (fresh) synced = 0;
  const float occupied = config().model.occupiedLogOdds();
  const auto& stamps = layer.bricks().brickChangeStamps();
  for (std::size_t b = 0; b < stamps.size(); ++b) {
    if (stamps[b] <= synced) continue;
    layer.forEachVoxelOfBrick(b, [&](const std::array<int, 3>& index, float occupancy, float) {
      scene.setOccupiedUnchecked(index, occupancy > occupied);  // NaN (unknown) fails
    });
  }
  synced = layer.bricks().changeCount();
}

}  // namespace fvp::host::map
