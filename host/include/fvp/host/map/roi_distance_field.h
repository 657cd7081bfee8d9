// Paper Eq. 1's d_i over an occupancy layer with ROI (kernel roi_distance): the Euclidean
// distance in voxels from every allocated voxel to the nearest known ROI voxel (ROI
// log-odds > 0), capped at a radius. Three separable passes over the bricks near ROI (the
// rest is the cap); the result is a channel of the layer, per brick slot on the device,
// for the information-gain kernels. Host reads download it once per computation, per slot
// (never expanded densely).
#pragma once

#include <array>
#include <atomic>
#include <mutex>
#include <optional>
#include <vector>

#include "fvp/host/map/occupancy_layer.h"

namespace fvp::host::map {

class RoiDistanceField {
 public:
  /// Throws std::logic_error without ROI. The distance channel is added to the layer by the
  /// first compute().
  explicit RoiDistanceField(OccupancyLayer& layer);

  /// Computes the field for the layer's current contents; with on-touch allocation, first
  /// allocates the bricks within radius_vox of ROI bricks (the passes carry distances through
  /// them).
  void compute(int radius_vox);
  /// True when compute() ran after the layer's last change and allocation.
  bool current() const;
  int radiusVox() const { return radius_vox_; }
  /// The per-slot distances on the device (valid while current()); throws std::logic_error
  /// before the first compute().
  accel::DeviceBuffer& distanceVox();
  /// d_i of one voxel as of the last compute(): the cap where no brick is allocated.
  /// Throws std::logic_error before the first compute().
  float distanceVoxAt(const std::array<int, 3>& index) const;
  /// The same, dense over the grid (x fastest): for tests against brute force.
  std::vector<float> dense() const;
  /// Allocated bricks where the last compute() changed some voxel's distance from what the
  /// one before gave (every allocated brick after the first compute or a new radius).
  const std::vector<std::uint32_t>& changedBricks() const { return changed_bricks_; }

 private:
  /// Per brick of the grid: whether it lies within the radius of a brick holding ROI.
  std::vector<char> roiHalo(int radius_vox) const;
  /// The host mirror of the current distances, downloaded if not yet; callers hold the lock.
  void downloadMirrorLocked() const;
  /// Compares the new distances (mirror_) with the previous ones per allocated brick.
  void findChangedBricks(const std::vector<float>& previous, int previous_radius_vox);

  OccupancyLayer& layer_;
  std::optional<BrickLayer::ChannelId> distance_;
  int radius_vox_ = 0;
  std::size_t computed_slots_ = 0;
  std::uint64_t computed_change_ = 0, computed_layout_ = 0;
  bool computed_ = false;
  mutable std::mutex mirror_mutex_;
  mutable std::vector<float> mirror_;
  mutable std::atomic<bool> mirror_ready_{false};
  std::vector<std::uint32_t> changed_bricks_;
};

}  // namespace fvp::host::map
