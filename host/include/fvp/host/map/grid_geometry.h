// Where the coarse and fine voxel lattices lie, shared by both map engines so that their
// voxels coincide with OctoMap's keys: voxel k of an axis covers [k, k+1) * voxel size in
// world coordinates, and a grid is a box of such voxels starting at first_voxel.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "fvp/accel/kernel_types.h"
#include "fvp/host/core/cluster_region.h"
#include "fvp/host/map/map_config.h"

extern "C" {
#include "fvp_map.h"
}

namespace fvp::host::map {

struct GridGeometry {
  double voxel_size_m = 0.0;
  std::array<std::int64_t, 3> first_voxel{};  ///< world lattice index of grid voxel (0,0,0)
  std::array<int, 3> dims{};                  ///< voxels per axis, multiples of 8 (bricks)

  /// Kernel view: float origin of voxel (0,0,0) and fixed-point scale.
  accel::GridParams params() const;
  /// World lattice index of the voxel containing p (floor(p / voxel_size)).
  std::array<std::int64_t, 3> latticeIndex(const Eigen::Vector3d& p_m) const;
  /// Grid index of p, or false when p is outside the grid.
  bool gridIndex(const Eigen::Vector3d& p_m, std::array<int, 3>& index) const;
  Eigen::Vector3d voxelCenter_m(const std::array<int, 3>& index) const;
  std::int64_t voxelCount() const { return std::int64_t{dims[0]} * dims[1] * dims[2]; }
};

/// The coarse grid: the observation box snapped outward to whole bricks of voxels.
GridGeometry coarseGridGeometry(const MapConfig& config);
/// The fine grid: the Cluster Region's bounding cube snapped outward to whole bricks.
GridGeometry fineGridGeometry(const MapConfig& config, const ClusterRegion& region);
/// The Cluster Region sphere in a grid's voxel units (for fvp_region_contains).
fvp_region regionInGrid(const GridGeometry& grid, const ClusterRegion& region);

}  // namespace fvp::host::map
