// One full-resolution synthetic frame (1440 x 1080 rays, ~1.5 M points) into the octomap
// engine with the default map config: a timing record for the reference engine (heavy).
#include <gtest/gtest.h>

#include <iostream>

#include "fvp/host/map/octomap_map_engine.h"
#include "synthetic_scan.h"

namespace fvp::host::map {
namespace {

TEST(OctomapEngineFrame, FullResolutionFrame) {
  const MapConfig config;  // 1 cm coarse over the default box, 1 mm fine
  const ClusterRegion region({0.1, 0.2, 1.0}, kDefaultClusterRadiusM);
  OctomapMapEngine engine(config, region);
  const auto world = testing::makeWorld(3, region.center_m(), 8);
  const Eigen::Vector3d origin = region.center_m() + Eigen::Vector3d(0.2, -0.15, -0.15);
  // A field of view just wider than the region, as the camera frames the cluster.
  const auto scan = testing::renderScan(world, origin, 1440, 1080, 0.45, 5);
  const ScanStats stats = engine.integrate(scan.clouds());
  std::cout << "[ octomap frame ] points " << stats.points << " (roi " << scan.roi_points_m.size()
            << "), coarse voxels " << stats.coarse_voxels_updated << ", fine voxels "
            << stats.fine_voxels_updated << ", " << stats.seconds << " s, "
            << stats.points / stats.seconds / 1e6 << " M points/s\n";
  EXPECT_EQ(stats.points, 1440u * 1080u);
  EXPECT_GT(stats.fine_voxels_updated, 100000u);
}

}  // namespace
}  // namespace fvp::host::map
