#pragma once

#include <cmath>
#include <cstdint>

namespace fvp::host::map {

enum class VoxelClass : std::uint8_t { kUnknown, kFree, kOccupied };

/// The class of an occupancy log-odds, one rule for both engines: unknown when never
/// updated (NaN, the grid engine's marker; the octomap engine has no node and never asks),
/// occupied when strictly above occupied_log_odds (OctoMap's isNodeOccupied uses >=, which
/// differs only at exactly the threshold), free otherwise.
inline VoxelClass classifyLogOdds(float log_odds, float occupied_log_odds) {
  if (std::isnan(log_odds)) return VoxelClass::kUnknown;
  return log_odds > occupied_log_odds ? VoxelClass::kOccupied : VoxelClass::kFree;
}

/// What a map knows about one voxel. ROI is meaningful for fine maps only: a voxel is ROI
/// when its ROI log-odds is above 0 (docs/design.md section 5).
struct VoxelState {
  VoxelClass occupancy = VoxelClass::kUnknown;
  bool roi = false;
  // Written out, not defaulted: the C++17 ROS layer includes this header (ros/CMakeLists.txt).
  friend bool operator==(const VoxelState& a, const VoxelState& b) {
    return a.occupancy == b.occupancy && a.roi == b.roi;
  }
  friend bool operator!=(const VoxelState& a, const VoxelState& b) { return !(a == b); }
};

}  // namespace fvp::host::map
