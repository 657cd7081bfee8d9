// An occupancy (+ ROI) map as a brick layer with two channels of log-odds (NaN = unknown),
// and a host mirror for reads that is refreshed brick by brick: only the bricks changed
// since the last read are downloaded. The kernels read and write the channels directly;
// operations over the layer are ScanIntegrator, RoiDistanceField and FrontierExtractor.
#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <mutex>
#include <optional>
#include <vector>

#include "fvp/host/map/brick_layer.h"

namespace fvp::host::map {

class OccupancyLayer {
 public:
  OccupancyLayer(accel::Backend& backend, const GridGeometry& geometry, bool with_roi,
                 std::optional<fvp_region> region, BrickAllocation allocation);

  BrickLayer& bricks() { return bricks_; }
  const BrickLayer& bricks() const { return bricks_; }
  const GridGeometry& geometry() const { return bricks_.geometry(); }
  bool hasRoi() const { return with_roi_; }
  accel::DeviceBuffer& occupancy() { return bricks_.channel(occupancy_); }
  /// The ROI channel; throws std::logic_error in a map without ROI.
  accel::DeviceBuffer& roi();

  /// Occupancy / ROI log-odds of a grid voxel; NaN when unknown, not allocated or (ROI)
  /// the map has no ROI.
  float occupancyAt(const std::array<int, 3>& index) const;
  float roiAt(const std::array<int, 3>& index) const;
  /// Visits every allocated voxel: f(index, occupancy_logodds, roi_logodds).
  template <typename F>
  void forEachVoxel(F&& f) const;
  /// Visits the voxels of one allocated brick: f(index, occupancy_logodds, roi_logodds).
  template <typename F>
  void forEachVoxelOfBrick(std::size_t allocated_brick, F&& f) const;

  /// Replaces the contents with dense arrays over the grid (x fastest; NaN = unknown),
  /// allocating every brick. For tests and for loading maps.
  void assignDense(const std::vector<float>& occupancy, const std::vector<float>& roi);

 private:
  void refreshMirror() const;

  BrickLayer bricks_;
  bool with_roi_;
  BrickLayer::ChannelId occupancy_;
  std::optional<BrickLayer::ChannelId> roi_;
  mutable std::mutex mirror_mutex_;
  mutable std::vector<float> mirror_occupancy_, mirror_roi_;
  // What the mirror holds (atomic: refreshMirror checks them without the lock).
  mutable std::atomic<std::uint64_t> mirror_change_count_{0};
  mutable std::atomic<std::size_t> mirror_slots_{0};
};

template <typename F>
void OccupancyLayer::forEachVoxelOfBrick(std::size_t b, F&& f) const {
  refreshMirror();
  for (int in_brick = 0; in_brick < accel::kBrickVoxels; ++in_brick) {
    const std::size_t slot = b * accel::kBrickVoxels + in_brick;
    f(bricks_.voxelOfSlot(slot), mirror_occupancy_[slot],
      with_roi_ ? mirror_roi_[slot] : std::nanf(""));
  }
}

template <typename F>
void OccupancyLayer::forEachVoxel(F&& f) const {
  for (std::size_t b = 0; b < bricks_.allocatedBricks(); ++b) forEachVoxelOfBrick(b, f);
}

}  // namespace fvp::host::map
