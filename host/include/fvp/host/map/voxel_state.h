#pragma once

#include <cstdint>

namespace fvp::host::map {

enum class VoxelClass : std::uint8_t { kUnknown, kFree, kOccupied };

/// What a map knows about one voxel. ROI is meaningful for fine maps only: a voxel is ROI
/// when its ROI log-odds is above 0 (DESIGN.md section 5).
struct VoxelState {
  VoxelClass occupancy = VoxelClass::kUnknown;
  bool roi = false;
  friend bool operator==(const VoxelState&, const VoxelState&) = default;
};

}  // namespace fvp::host::map
