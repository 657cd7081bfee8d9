// One frontier voxel of a fine map: a known voxel next to unknown space, the targets of the
// planner's samplers (paper, "Viewpoint Sampling").
//
// Definition, the same on both engines: a voxel inside the mapped region whose occupancy
// is known and that is ROI (ROI log-odds > 0) or free (occupancy log-odds <= occupied
// threshold), with at least one unknown face (6-)neighbour inside the mapped region.
// Neighbours outside the region are not unknown space of this map and are ignored.
#pragma once

#include <Eigen/Core>
#include <array>

namespace fvp::host::map {

struct FrontierVoxel {
  std::array<int, 3> index{};  ///< fine grid index
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  bool roi_frontier = false;          ///< known ROI voxel next to unknown space
  bool exploration_frontier = false;  ///< known free voxel next to unknown space
  /// Unit vector away from the unknown: the normalised sum of -offset over the unknown
  /// 26-neighbours inside the region; zero when that sum is zero.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

}  // namespace fvp::host::map
