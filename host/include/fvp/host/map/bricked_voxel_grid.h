// Device-resident bricked voxel storage of one map on a compute backend: a brick table
// over the grid, per-slot occupancy (and ROI) log-odds pools, scan marks. Bricks of 8^3
// voxels are allocated on first touch by a scan (or up front for small grids), so a 1 mm
// map of a whole observation box costs only what the sensor has seen. The kernels
// (kernels/fvp_map_kernels.h) read this layout directly; the host keeps the brick table.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "fvp/accel/backend.h"
#include "fvp/host/map/frontier_voxel.h"
#include "fvp/host/map/grid_geometry.h"
#include "fvp/host/map/occupancy_model.h"

namespace fvp::host::map {

class BrickedVoxelGrid {
 public:
  /// The most bricks one grid may allocate: kernels index slots (brick * 512 + voxel) with
  /// 32-bit ints.
  static constexpr std::size_t kMaxBricks = (std::size_t{1} << 22) - 1;

  enum class Allocation {
    kUpFront,  ///< every brick of the grid box at construction
    kOnTouch,  ///< bricks as scans reach them
  };

  /// region: voxels outside it are never mapped (the fine map's Cluster Region).
  BrickedVoxelGrid(accel::Backend& backend, const GridGeometry& geometry, bool with_roi,
                   std::optional<fvp_region> region, Allocation allocation);
  ~BrickedVoxelGrid();
  BrickedVoxelGrid(const BrickedVoxelGrid&) = delete;
  BrickedVoxelGrid& operator=(const BrickedVoxelGrid&) = delete;

  const GridGeometry& geometry() const { return geometry_; }
  accel::BrickedGridParams params() const { return params_; }
  bool hasRoi() const { return with_roi_; }
  std::size_t allocatedBricks() const { return brick_coords_.size() / 3; }
  std::size_t slotCount() const { return allocatedBricks() * accel::kBrickVoxels; }
  /// Device bytes held (pools, marks, tables).
  std::size_t deviceBytes() const;

  /// Integrates one scan whose prepared points (finite, cut at max range, flagged) are
  /// on the device. Returns the number of voxels updated.
  std::size_t integrate(accel::DeviceBuffer& points, std::uint32_t point_count,
                        const Eigen::Vector3f& sensor_m, const OccupancyModel& model);

  /// Occupancy / ROI log-odds of a grid voxel, NaN when unknown (or not mapped).
  /// Reads a host copy refreshed after each integrate() on first use.
  float occupancyAt(const std::array<int, 3>& index) const;
  float roiAt(const std::array<int, 3>& index) const;
  /// Visits every allocated voxel: f(index, occupancy_logodds, roi_logodds).
  template <typename F>
  void forEachVoxel(F&& f) const;

  /// Replaces the contents with dense arrays over the grid (x fastest; NaN = unknown),
  /// allocating every brick. For tests and for loading maps.
  void assignDense(const std::vector<float>& occupancy, const std::vector<float>& roi);

  /// Paper Eq. 1's d_i: Euclidean distance in voxels from every allocated voxel to the
  /// nearest known ROI voxel, capped at radius_vox, per brick slot on the device (for the
  /// information-gain kernels) until the next scan or allocation.
  void computeRoiDistance(int radius_vox);
  /// d_i of one voxel as of the last computeRoiDistance() (the cap where no brick is
  /// allocated); the per-slot result is downloaded once, on the first query.
  float roiDistanceVoxAt(const std::array<int, 3>& index) const;
  /// The same, dense over the grid (x fastest): for tests against brute force.
  std::vector<float> roiDistanceVox(int radius_vox);
  const accel::DeviceBuffer* roiDistanceBuffer() const { return distance_.get(); }

  /// Frontier voxels, sorted by grid index (deterministic on every backend).
  std::vector<FrontierVoxel> extractFrontiers(float occupied_logodds);

  // Device buffers for other kernels (information gain).
  const accel::DeviceBuffer& brickTableBuffer() const { return *table_buf_; }
  const accel::DeviceBuffer& occupancyBuffer() const { return *occupancy_; }
  const accel::DeviceBuffer& roiBuffer() const { return *roi_; }

 private:
  int brickIndex(int bx, int by, int bz) const {
    return bx + params_.bricks_x * (by + params_.bricks_y * bz);
  }
  bool brickInsideRegion(int bx, int by, int bz) const;
  void allocate(const std::vector<int>& brick_ids);
  void allocateRoiHalo(int radius_vox);
  void ensurePoolCapacity(std::size_t bricks);
  void uploadTables();
  void refreshHostCopy() const;
  std::int64_t slotOf(const std::array<int, 3>& index) const;

  accel::Backend& backend_;
  GridGeometry geometry_;
  bool with_roi_;
  Allocation allocation_;
  accel::BrickedGridParams params_{};
  std::vector<int> table_;         // brick -> allocation index (| FVP_BRICK_INSIDE) or kNoBrick
  std::vector<int> brick_coords_;  // allocation index -> brick grid coordinates (x, y, z)
  std::size_t pool_bricks_ = 0;    // capacity of the device pools, in bricks

  std::unique_ptr<accel::DeviceBuffer> table_buf_, coords_buf_, missing_, counter_;
  std::unique_ptr<accel::DeviceBuffer> occupancy_, roi_, marks_;
  std::unique_ptr<accel::DeviceBuffer> distance_;

  mutable std::mutex host_mutex_;
  mutable bool host_stale_ = true;
  mutable std::vector<float> host_occupancy_, host_roi_, host_distance_;
  int distance_radius_vox_ = 0;
};

template <typename F>
void BrickedVoxelGrid::forEachVoxel(F&& f) const {
  refreshHostCopy();
  const std::size_t bricks = allocatedBricks();
  for (std::size_t b = 0; b < bricks; ++b)
    for (int local = 0; local < accel::kBrickVoxels; ++local) {
      const std::size_t slot = b * accel::kBrickVoxels + local;
      const std::array<int, 3> index{brick_coords_[3 * b] * 8 + (local & 7),
                                     brick_coords_[3 * b + 1] * 8 + ((local >> 3) & 7),
                                     brick_coords_[3 * b + 2] * 8 + (local >> 6)};
      f(index, host_occupancy_[slot], with_roi_ ? host_roi_[slot] : std::nanf(""));
    }
}

}  // namespace fvp::host::map
