#include "fvp/host/map/grid_geometry.h"

#include <cmath>
#include <stdexcept>

namespace fvp::host::map {
namespace {

int roundUpToBricks(std::int64_t voxels) {
  const std::int64_t bricks = (voxels + FVP_BRICK_EDGE - 1) / FVP_BRICK_EDGE;
  return static_cast<int>(bricks * FVP_BRICK_EDGE);
}

GridGeometry boxGeometry(const Eigen::Vector3d& min_m, const Eigen::Vector3d& max_m,
                         double voxel_size_m, const char* what) {
  GridGeometry g;
  g.voxel_size_m = voxel_size_m;
  std::int64_t voxels = 1;
  for (int a = 0; a < 3; ++a) {
    const auto lo = static_cast<std::int64_t>(std::floor(min_m[a] / voxel_size_m));
    const auto hi = static_cast<std::int64_t>(std::floor(max_m[a] / voxel_size_m));
    g.first_voxel[a] = lo;
    g.dims[a] = roundUpToBricks(hi - lo + 1);
    // The exact DDA needs every end point within 8192 voxels of the grid origin.
    if (g.dims[a] > 8192 || std::llabs(lo) > (std::int64_t{1} << 30))
      throw std::invalid_argument(std::string(what) + ": more than 8192 voxels along an axis");
    voxels *= g.dims[a];
  }
  // The brick table holds an int per brick of the box, allocated or not: keep it below
  // 256 MiB. (Allocated bricks are limited separately, BrickLayer::kMaxBricks.)
  if (voxels / FVP_BRICK_VOXELS >= (std::int64_t{1} << 26))
    throw std::invalid_argument(std::string(what) + ": a box of 2^26 bricks (8^3 voxels) or more");
  return g;
}

}  // namespace

accel::GridParams GridGeometry::params() const {
  return accel::makeGridParams(dims,
                               {static_cast<float>(first_voxel[0] * voxel_size_m),
                                static_cast<float>(first_voxel[1] * voxel_size_m),
                                static_cast<float>(first_voxel[2] * voxel_size_m)},
                               static_cast<float>(voxel_size_m));
}

std::array<std::int64_t, 3> GridGeometry::latticeIndex(const Eigen::Vector3d& p_m) const {
  return {static_cast<std::int64_t>(std::floor(p_m.x() / voxel_size_m)),
          static_cast<std::int64_t>(std::floor(p_m.y() / voxel_size_m)),
          static_cast<std::int64_t>(std::floor(p_m.z() / voxel_size_m))};
}

bool GridGeometry::gridIndex(const Eigen::Vector3d& p_m, std::array<int, 3>& index) const {
  if (!p_m.allFinite()) return false;
  const auto k = latticeIndex(p_m);
  for (int a = 0; a < 3; ++a) {
    const std::int64_t i = k[a] - first_voxel[a];
    if (i < 0 || i >= dims[a]) return false;
    index[a] = static_cast<int>(i);
  }
  return true;
}

Eigen::Vector3d GridGeometry::voxelCenter_m(const std::array<int, 3>& index) const {
  return {(first_voxel[0] + index[0] + 0.5) * voxel_size_m,
          (first_voxel[1] + index[1] + 0.5) * voxel_size_m,
          (first_voxel[2] + index[2] + 0.5) * voxel_size_m};
}

GridGeometry coarseGridGeometry(const MapConfig& config) {
  return boxGeometry(config.observation_min_m, config.observation_max_m, config.coarse_voxel_size_m,
                     "coarse map");
}

GridGeometry fineGridGeometry(const MapConfig& config, const ClusterRegion& region) {
  const Eigen::Vector3d r = Eigen::Vector3d::Constant(region.radius_m());
  return boxGeometry(region.center_m() - r, region.center_m() + r, config.fine_voxel_size_m,
                     "fine map");
}

fvp_region regionInGrid(const GridGeometry& grid, const ClusterRegion& region) {
  fvp_region r{};
  const double s = grid.voxel_size_m;
  r.center_x_vox = static_cast<float>(region.center_m().x() / s - grid.first_voxel[0]);
  r.center_y_vox = static_cast<float>(region.center_m().y() / s - grid.first_voxel[1]);
  r.center_z_vox = static_cast<float>(region.center_m().z() / s - grid.first_voxel[2]);
  const double radius_vox = region.radius_m() / s;
  r.radius_sq_vox = static_cast<float>(radius_vox * radius_vox);
  return r;
}

}  // namespace fvp::host::map
