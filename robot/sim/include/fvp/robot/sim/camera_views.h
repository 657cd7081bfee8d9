// Camera poses for simulated views: the OpenCV optical frame (x right, y down, z forward)
// of the left camera, as T_world_camera.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "fvp/robot/sim/world.h"

namespace fvp::robot::sim {

/// Camera at eye_m looking at target_m, image "down" as close to world -z as possible.
Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye_m, const Eigen::Vector3d& target_m);

/// `count` views of the cluster from the start view's distance, spread evenly over
/// `arc_deg` about the vertical through the cluster centre; the middle one is the start
/// view's direction. count >= 1; arc_deg in [0, 360].
std::vector<Eigen::Isometry3d> orbitViews(const World& world, int count, double arc_deg);

}  // namespace fvp::robot::sim
