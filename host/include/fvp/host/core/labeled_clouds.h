// World-frame point clouds of one view: ROI (segmented fruitlet pixels) and everything else
// with a valid disparity, for the fine ROI map / TSDF and the occupancy maps.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fvp/host/core/perception_stats.h"

namespace fvp::host {

struct LabeledClouds {
  std::vector<Eigen::Vector3f> roi_points_m;    ///< world frame
  std::vector<Eigen::Vector3f> other_points_m;  ///< world frame
  PerceptionStats stats;
  Eigen::Vector3d sensor_origin_m = Eigen::Vector3d::Zero();  ///< left camera centre, world
};

}  // namespace fvp::host
