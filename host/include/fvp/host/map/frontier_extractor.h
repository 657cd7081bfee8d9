// Frontier extraction over an occupancy layer with ROI (kernel frontier; definition in
// frontier_voxel.h): allocated voxels are classified on the device, frontiers are appended
// in any order and sorted here by grid index, so results are the same on every backend.
// After the first extraction only the bricks a scan changed since the last one, and the
// bricks around them, are classified again: a voxel's class reads its 26 neighbours, so no
// other voxel's can have changed. The rest are kept, and the result is a full extraction's.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "fvp/host/map/frontier_voxel.h"
#include "fvp/host/map/occupancy_layer.h"

namespace fvp::host::map {

/// What the last extract() classified.
struct FrontierExtractionStats {
  bool full = true;                   ///< every allocated brick (first call, new threshold)
  std::size_t classified_bricks = 0;  ///< bricks whose voxels were classified again
  std::size_t allocated_bricks = 0;   ///< of the layer's
};

class FrontierExtractor {
 public:
  /// Throws std::logic_error without ROI.
  explicit FrontierExtractor(OccupancyLayer& layer);
  /// Frontier voxels, sorted by grid index (z, then y, then x).
  std::vector<FrontierVoxel> extract(float occupied_logodds);
  const FrontierExtractionStats& lastStats() const { return stats_; }

 private:
  /// Allocation indices of the bricks changed since the last extraction and of every
  /// allocated brick among their 26 neighbours; marks their grid ids in `reclassified`.
  std::vector<std::uint32_t> bricksToReclassify(std::vector<char>& reclassified) const;
  /// Runs the kernel over the bricks whose coordinates `coords` holds; sorted by grid index.
  std::vector<FrontierVoxel> classify(accel::DeviceBuffer& coords, std::size_t bricks,
                                      float occupied_logodds);

  OccupancyLayer& layer_;
  std::unique_ptr<accel::DeviceBuffer> counter_;
  std::uint32_t capacity_ = 4096;  ///< entries of the output list; grows to what was found
  std::unique_ptr<accel::DeviceBuffer> changed_coords_;  ///< coordinates of bricks to classify
  std::size_t changed_coords_capacity_ = 0;              ///< in bricks
  // The last extraction: its frontiers, the layer's change count and the threshold it read.
  std::vector<FrontierVoxel> last_;
  bool have_last_ = false;
  std::uint64_t last_change_count_ = 0;
  float last_occupied_logodds_ = 0.0f;
  FrontierExtractionStats stats_;
};

}  // namespace fvp::host::map
