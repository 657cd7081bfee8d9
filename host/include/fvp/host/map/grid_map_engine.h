// The "grid" map engine: coarse and fine maps as occupancy brick layers on a compute backend
// (cpu, opencl or vulkan), with the operations over them (scan integration, the fine map's
// ROI distance field and frontiers) as kernels. Default for FVP: the planner's
// information-gain kernels read these device buffers directly. Host-side views (voxel
// queries, Embree scenes, the coarse OcTree) are refreshed from changed bricks only.
#pragma once

#include <octomap/OcTree.h>
#include <memory>

#include "fvp/accel/backend.h"
#include "fvp/host/map/frontier_extractor.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/map/occupancy_layer.h"
#include "fvp/host/map/roi_distance_field.h"
#include "fvp/host/map/scan_integrator.h"

namespace fvp::host::map {

/// Grids of at most this many voxels get every brick up front; larger ones (RVP's 1 mm map
/// of the whole observation box) allocate bricks as scans reach them.
inline constexpr std::int64_t kDefaultUpFrontVoxelLimit = 64LL << 20;

class GridMapEngine final : public MapEngine {
 public:
  GridMapEngine(const MapConfig& config, const ClusterRegion& region, accel::Backend& backend);

  std::string_view engineName() const override { return "grid"; }
  VoxelClass coarseClass(const Eigen::Vector3d& p_m) const override;
  VoxelState fineState(const Eigen::Vector3d& p_m) const override;
  void exportCoarse(const std::filesystem::path& bt_path) const override;
  void exportFine(const std::filesystem::path& ot_path) const override;
  const GridGeometry& gridGeometry(MapLevel level) const override;
  std::vector<std::array<int, 3>> occupiedVoxels(MapLevel level) const override;

  accel::Backend& backend() const { return backend_; }
  OccupancyLayer& coarse() { return coarse_; }
  OccupancyLayer& fine() { return fine_->layer; }
  const OccupancyLayer& coarse() const { return coarse_; }
  const OccupancyLayer& fine() const { return fine_->layer; }
  /// The fine map's ROI distance field (device-resident per slot; see updateRoiDistance).
  RoiDistanceField& fineRoiDistance() { return fine_->distance; }

  void updateRoiDistance(double max_d_m) override;
  double roiDistance_m(const std::array<int, 3>& fine_index) const override;
  std::vector<FrontierVoxel> frontiers() override;
  /// What the last frontiers() classified again (the bricks changed since the call before).
  const FrontierExtractionStats& frontierStats() const { return fine_->frontiers.lastStats(); }
  const octomap::OcTree& coarseOcTree() override;

 protected:
  void integrateScan(const Eigen::Vector3d& sensor_origin_m,
                     const std::vector<accel::ScanPoint>& points, ScanStats& stats) override;
  void refreshScene(MapLevel level, OccupiedVoxelScene& scene, bool fresh) override;
  void placeFineMap() override;
  /// Records the bricks the layers stamped since the last sync in the change logs.
  void syncChangeLogs() override;
  bool recordsBrickChanges() const override { return true; }

 private:
  /// Writes the coarse voxels of bricks changed after change count `since` into tree.
  void writeCoarseBricks(octomap::OcTree& tree, std::uint64_t since) const;

  /// The fine map over one Cluster Region's cube, with what reads and writes it; replaced
  /// whole when the map moves to another region.
  struct FineLevel {
    FineLevel(accel::Backend& backend, const MapConfig& config, const ClusterRegion& region);
    OccupancyLayer layer;
    ScanIntegrator integrator;
    RoiDistanceField distance;
    FrontierExtractor frontiers;
  };

  accel::Backend& backend_;
  OccupancyLayer coarse_;
  ScanIntegrator coarse_integrator_;
  std::unique_ptr<FineLevel> fine_;
  double distance_max_d_m_ = -1.0;  ///< the cap of the last updateRoiDistance()
  std::unique_ptr<octomap::OcTree> coarse_tree_;
  std::uint64_t coarse_tree_change_ = 0;    ///< coarse change count the tree reflects
  std::uint64_t scene_change_[2] = {0, 0};  ///< change count each level's scene reflects
  std::uint64_t log_change_[2] = {0, 0};    ///< change count each level's change log reflects
};

}  // namespace fvp::host::map
