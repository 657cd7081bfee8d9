// The "grid" map engine: coarse and fine maps as bricked voxel storage on a compute backend
// (cpu, opencl or vulkan), integrated by the scan kernels. Default for FVP: the planner's
// information-gain kernel reads these buffers directly.
#pragma once

#include <octomap/OcTree.h>
#include <memory>

#include "fvp/accel/backend.h"
#include "fvp/host/map/bricked_voxel_grid.h"
#include "fvp/host/map/map_engine.h"

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
  BrickedVoxelGrid& coarse() { return *coarse_; }
  BrickedVoxelGrid& fine() { return *fine_; }
  const BrickedVoxelGrid& coarse() const { return *coarse_; }
  const BrickedVoxelGrid& fine() const { return *fine_; }

  void updateRoiDistance(double max_d_m) override;
  double roiDistance_m(const std::array<int, 3>& fine_index) const override;
  std::vector<FrontierVoxel> frontiers() override;
  const octomap::OcTree& coarseOcTree() override;

 protected:
  void integrateScan(const Eigen::Vector3d& sensor_origin_m,
                     const std::vector<accel::ScanPoint>& points, ScanStats& stats) override;

 private:
  std::unique_ptr<octomap::OcTree> buildCoarseTree() const;

  accel::Backend& backend_;
  std::unique_ptr<BrickedVoxelGrid> coarse_, fine_;
  // The fine map's ROI distance is as of distance_scans_ scans with cap distance_max_d_m_.
  double distance_max_d_m_ = -1.0;
  std::size_t distance_scans_ = 0;
  std::unique_ptr<octomap::OcTree> coarse_tree_;
  std::size_t coarse_tree_scans_ = 0;
};

}  // namespace fvp::host::map
