// Frontier extraction over an occupancy layer with ROI (kernel frontier; definition in
// frontier_voxel.h): every allocated voxel is classified on the device, frontiers are
// appended in any order and sorted here by grid index, so results are the same on every
// backend.
#pragma once

#include <memory>
#include <vector>

#include "fvp/host/map/frontier_voxel.h"
#include "fvp/host/map/occupancy_layer.h"

namespace fvp::host::map {

class FrontierExtractor {
 public:
  /// Throws std::logic_error without ROI.
  explicit FrontierExtractor(OccupancyLayer& layer);
  /// Frontier voxels, sorted by grid index (z, then y, then x).
  std::vector<FrontierVoxel> extract(float occupied_logodds);

 private:
  OccupancyLayer& layer_;
  std::unique_ptr<accel::DeviceBuffer> counter_;
  std::uint32_t capacity_ = 4096;  ///< entries of the output list; grows to what was found
};

}  // namespace fvp::host::map
