#pragma once

#include <cstddef>

namespace fvp::host::map {

/// Counts of one scan integration. Bad points are expected events: counted, never written.
struct ScanStats {
  std::size_t points = 0;           ///< points offered (ROI + other)
  std::size_t skipped_invalid = 0;  ///< NaN or infinite coordinates
  std::size_t truncated = 0;        ///< beyond sensor_max_range_m: free ray only, no hit
  std::size_t coarse_voxels_updated = 0;
  std::size_t fine_voxels_updated = 0;
  double seconds = 0.0;  ///< wall time of the integration
};

}  // namespace fvp::host::map
