// A coarse occupancy map of a simulated world straight from its geometry (no rendering):
// points sampled densely on every surface (trunk and branches, leaves, fruitlets, tag
// plate) mark their voxels occupied. A stand-in for a fully observed coarse map in motion
// planning tests and benchmarks.
#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Geometry>
#include <memory>

#include "fvp/robot/sim/world.h"

namespace fvp::robot::sim {

/// Occupied voxels of `world` at `resolution_m`, limited to `bounds` (world frame).
std::unique_ptr<octomap::OcTree> worldOccupancy(const World& world, double resolution_m,
                                                const Eigen::AlignedBox3d& bounds);

}  // namespace fvp::robot::sim
