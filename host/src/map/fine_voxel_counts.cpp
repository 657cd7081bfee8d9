#include "fvp/host/map/fine_voxel_counts.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace fvp::host::map {

FineVoxelCounts fineVoxelsWithin(const MapEngine& map, const Eigen::Vector3d& center_m,
                                 double radius_m) {
  FineVoxelCounts counts;
  const GridGeometry& grid = map.gridGeometry(MapLevel::kFine);
  if (!(radius_m >= 0.0) || !std::isfinite(radius_m) || !center_m.allFinite() ||
      !(grid.voxel_size_m > 0.0))
    return counts;
  // The ball's bounding box of voxels, clipped to the grid.
  const auto first = grid.latticeIndex(center_m.array() - radius_m);
  const auto last = grid.latticeIndex(center_m.array() + radius_m);
  std::array<int, 3> lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    lo[a] =
        static_cast<int>(std::clamp<std::int64_t>(first[a] - grid.first_voxel[a], 0, grid.dims[a]));
    hi[a] = static_cast<int>(
        std::clamp<std::int64_t>(last[a] - grid.first_voxel[a], -1, grid.dims[a] - 1));
  }
  for (int z = lo[2]; z <= hi[2]; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int x = lo[0]; x <= hi[0]; ++x) {
        const std::array<int, 3> index{x, y, z};
        const Eigen::Vector3d c = grid.voxelCenter_m(index);
        if ((c - center_m).norm() > radius_m) continue;
        switch (map.fineState(c).occupancy) {
          case VoxelClass::kUnknown:
            ++counts.unknown;
            break;
          case VoxelClass::kFree:
            ++counts.free;
            break;
          case VoxelClass::kOccupied:
            ++counts.occupied;
            break;
        }
      }
  return counts;
}

}  // namespace fvp::host::map
