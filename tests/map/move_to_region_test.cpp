// MapEngine::moveToRegion, on both engines: the coarse map keeps every voxel it knew, the
// fine map starts empty over the new region, and after the move a scan gives exactly the
// fine map a fresh engine placed on that region gets from it.
#include <gtest/gtest.h>

#include <memory>

#include "fvp/accel/backend.h"
#include "fvp/host/map/grid_map_engine.h"
#include "fvp/host/map/octomap_map_engine.h"
#include "synthetic_scan.h"

namespace fvp::host::map {
namespace {

MapConfig boxConfig() {
  MapConfig config;
  config.observation_min_m = {-0.6, -0.6, -0.2};
  config.observation_max_m = {0.6, 0.6, 0.6};
  return config;
}

const ClusterRegion kFirst{Eigen::Vector3d(-0.15, 0.01, 0.31), 0.05};
const ClusterRegion kSecond{Eigen::Vector3d(0.17, -0.02, 0.29), 0.05};

std::unique_ptr<MapEngine> makeEngine(const std::string& name, const ClusterRegion& region,
                                      accel::Backend& cpu) {
  if (name == "grid") return std::make_unique<GridMapEngine>(boxConfig(), region, cpu);
  return std::make_unique<OctomapMapEngine>(boxConfig(), region);
}

// Every fine voxel's state over the fine grid's box.
std::vector<VoxelState> fineStates(const MapEngine& map) {
  const GridGeometry& g = map.gridGeometry(MapLevel::kFine);
  std::vector<VoxelState> states;
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = 0; x < g.dims[0]; ++x)
        states.push_back(map.fineState(g.voxelCenter_m({x, y, z})));
  return states;
}

testing::SyntheticScan scanOf(const ClusterRegion& region, std::uint64_t seed) {
  const auto world = testing::makeWorld(seed, region.center_m());
  return testing::renderScan(world, region.center_m() + Eigen::Vector3d(0.02, -0.3, 0.05), 240, 180,
                             0.8, seed);
}

class MoveToRegion : public ::testing::TestWithParam<std::string> {
 protected:
  std::unique_ptr<accel::Backend> cpu = accel::createBackend(accel::BackendKind::kCpu);
};

TEST_P(MoveToRegion, KeepsTheCoarseMapAndStartsTheFineMapOverTheNewRegion) {
  const auto map = makeEngine(GetParam(), kFirst, *cpu);
  map->integrate(scanOf(kFirst, 3).clouds());
  const auto coarse_before = map->occupiedVoxels(MapLevel::kCoarse);
  ASSERT_GT(coarse_before.size(), 50u);
  ASSERT_GT(map->occupiedVoxels(MapLevel::kFine).size(), 500u);
  map->updateRoiDistance(0.01);
  (void)map->occupiedScene(MapLevel::kFine);

  map->moveToRegion(kSecond);
  EXPECT_EQ(map->region().center_m(), kSecond.center_m());
  EXPECT_EQ(map->occupiedVoxels(MapLevel::kCoarse), coarse_before);
  EXPECT_TRUE(map->occupiedVoxels(MapLevel::kFine).empty());
  EXPECT_TRUE(map->frontiers().empty());
  EXPECT_EQ(map->fineState(kFirst.center_m()).occupancy, VoxelClass::kUnknown);
  EXPECT_EQ(map->occupiedScene(MapLevel::kFine).occupiedCount(), 0u);
  EXPECT_THROW((void)map->roiDistance_m({0, 0, 0}), std::logic_error);

  // After the move a scan of the second cluster gives exactly a fresh engine's fine map.
  const auto fresh = makeEngine(GetParam(), kSecond, *cpu);
  EXPECT_EQ(map->gridGeometry(MapLevel::kFine).first_voxel,
            fresh->gridGeometry(MapLevel::kFine).first_voxel);
  const auto scan = scanOf(kSecond, 4);
  map->integrate(scan.clouds());
  fresh->integrate(scan.clouds());
  EXPECT_GT(map->occupiedVoxels(MapLevel::kFine).size(), 500u);
  EXPECT_TRUE(fineStates(*map) == fineStates(*fresh));
  EXPECT_EQ(map->frontiers().size(), fresh->frontiers().size());
  EXPECT_EQ(map->occupiedScene(MapLevel::kFine).occupiedCount(),
            fresh->occupiedScene(MapLevel::kFine).occupiedCount());
  // The coarse map holds both clusters' views, the fresh one only the second's.
  EXPECT_GT(map->occupiedVoxels(MapLevel::kCoarse).size(),
            fresh->occupiedVoxels(MapLevel::kCoarse).size());
}

TEST_P(MoveToRegion, RejectsARegionWithoutExtent) {
  const auto map = makeEngine(GetParam(), kFirst, *cpu);
  EXPECT_THROW(map->moveToRegion(ClusterRegion(kSecond.center_m(), 0.0)), std::invalid_argument);
  EXPECT_THROW(map->moveToRegion(ClusterRegion(Eigen::Vector3d::Constant(NAN), 0.05)),
               std::invalid_argument);
  EXPECT_EQ(map->region().center_m(), kFirst.center_m());
}

INSTANTIATE_TEST_SUITE_P(Engines, MoveToRegion, ::testing::Values("grid", "octomap"));

}  // namespace
}  // namespace fvp::host::map
