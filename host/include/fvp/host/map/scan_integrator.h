// Scan integration into an occupancy layer (kernels scan_mark + scan_update): one scan's
// prepared points (finite, cut at max range, flagged; prepareScanPoints) already on the
// device. Bricks the rays reach that are not allocated are allocated (in ascending order,
// the same on every backend) and the idempotent mark pass runs again. The bricks whose
// voxels changed are reported to the layer, so readers refresh only those.
#pragma once

#include <Eigen/Core>
#include <memory>

#include "fvp/host/map/occupancy_layer.h"
#include "fvp/host/map/occupancy_model.h"

namespace fvp::host::map {

class ScanIntegrator {
 public:
  /// Adds the scan-mark channel to the layer.
  explicit ScanIntegrator(OccupancyLayer& layer);

  /// Returns the number of voxels updated.
  std::size_t integrate(accel::DeviceBuffer& points, std::uint32_t point_count,
                        const Eigen::Vector3f& sensor_m, const OccupancyModel& model);

 private:
  OccupancyLayer& layer_;
  BrickLayer::ChannelId marks_;
  std::unique_ptr<accel::DeviceBuffer> missing_, counter_;
};

}  // namespace fvp::host::map
