// The fine voxels of a ball by class: what the map has seen of a small place (a remembered
// fruitlet's, SizingGuidance's placeSeenEmpty).
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "fvp/host/map/map_engine.h"

namespace fvp::host::map {

struct FineVoxelCounts {
  std::size_t unknown = 0, free = 0, occupied = 0;
  std::size_t total() const { return unknown + free + occupied; }
};

/// Counts the fine voxels whose centres lie within radius_m of center_m (none outside the fine
/// grid; none for a radius negative or not finite, or a centre not finite). A solid body's inside
/// stays unknown, since rays end at its surface: a ball seen mostly free holds nothing solid.
FineVoxelCounts fineVoxelsWithin(const MapEngine& map, const Eigen::Vector3d& center_m,
                                 double radius_m);

}  // namespace fvp::host::map
