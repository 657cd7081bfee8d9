// The one point preparation of both engines (scan_points.h): what it cuts and counts, and
// that both engines report and apply it alike.
#include "fvp/host/map/scan_points.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fvp/accel/backend.h"
#include "fvp/host/map/grid_map_engine.h"
#include "fvp/host/map/octomap_map_engine.h"
#include "synthetic_scan.h"

namespace fvp::host::map {
namespace {

using Vec3f = Eigen::Vector3f;

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

MapConfig smallConfig() {
  MapConfig c;
  c.observation_min_m = {-0.3, -0.3, -0.3};
  c.observation_max_m = {0.3, 0.3, 1.0};
  c.sensor_max_range_m = 0.6;
  return c;
}

const ClusterRegion kRegion(Eigen::Vector3d(0.0, 0.0, 0.3), 0.04);

// Two invalid points, two beyond the 0.6 m range (one ROI), three measurements.
LabeledClouds mixedClouds() {
  const Eigen::Vector3d origin(0.0051, 0.0052, 0.0053);
  return testing::makeClouds(
      origin, {Vec3f(kNan, 0.0f, 0.3f), Vec3f(0.0151f, 0.0152f, 0.3053f), Vec3f(0.0f, 0.0f, 0.9f)},
      {Vec3f(0.0f, kInf, 0.3f), Vec3f(0.0151f, 0.0052f, 0.2553f), Vec3f(0.0051f, 0.0052f, 0.8053f),
       Vec3f(-0.0149f, 0.0052f, 0.3153f)});
}

TEST(ScanPoints, SkipsNonFinitePointsAndCutsFarOnesAtMaxRange) {
  const LabeledClouds clouds = mixedClouds();
  ScanStats stats;
  const auto points = prepareScanPoints(clouds, 0.6, stats);
  EXPECT_EQ(stats.points, 7u);
  EXPECT_EQ(stats.skipped_invalid, 2u);
  EXPECT_EQ(stats.truncated, 2u);
  ASSERT_EQ(points.size(), 5u);
  // ROI points first, in order; the cut ray keeps no flag (no hit, so no ROI either).
  EXPECT_EQ(points[0].flags, FVP_POINT_HIT | FVP_POINT_ROI);
  EXPECT_EQ(points[1].flags, 0u);
  EXPECT_EQ(points[2].flags, FVP_POINT_HIT);
  EXPECT_EQ(points[3].flags, 0u);
  EXPECT_EQ(points[4].flags, FVP_POINT_HIT);
  for (const std::size_t cut : {1u, 3u}) {
    const Eigen::Vector3d end(points[cut].x_m, points[cut].y_m, points[cut].z_m);
    EXPECT_NEAR((end - clouds.sensor_origin_m).norm(), 0.6, 1e-6);
  }
  EXPECT_EQ(points[0].z_m, 0.3053f);  // measurements pass unchanged
}

TEST(ScanPoints, BothEnginesCountAndCutAlike) {
  const LabeledClouds clouds = mixedClouds();
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  GridMapEngine grid(smallConfig(), kRegion, *cpu);
  OctomapMapEngine octo(smallConfig(), kRegion);
  const ScanStats g = grid.integrate(clouds);
  const ScanStats o = octo.integrate(clouds);
  EXPECT_EQ(g.points, 7u);
  EXPECT_EQ(g.skipped_invalid, 2u);
  EXPECT_EQ(g.truncated, 2u);
  EXPECT_EQ(o.points, g.points);
  EXPECT_EQ(o.skipped_invalid, g.skipped_invalid);
  EXPECT_EQ(o.truncated, g.truncated);
  // Along the cut ray straight up the coarse column (0, 0): free up to the cut at
  // z = 0.6053 (coarse voxel 60), that voxel and everything beyond it unknown, on both
  // engines; the measurement at (0.0151, 0.0052, 0.2553) is a hit.
  for (MapEngine* e : std::initializer_list<MapEngine*>{&grid, &octo}) {
    SCOPED_TRACE(std::string(e->engineName()));
    for (const double z : {0.105, 0.405, 0.595})
      EXPECT_EQ(e->coarseClass({0.005, 0.005, z}), VoxelClass::kFree);
    EXPECT_EQ(e->coarseClass({0.005, 0.005, 0.605}), VoxelClass::kUnknown);
    EXPECT_EQ(e->coarseClass({0.005, 0.005, 0.805}), VoxelClass::kUnknown);
    EXPECT_EQ(e->coarseClass({0.0155, 0.0055, 0.255}), VoxelClass::kOccupied);
  }
}

TEST(ScanPoints, OneClassificationRule) {
  const float occupied = OccupancyModel{}.occupiedLogOdds();
  EXPECT_EQ(classifyLogOdds(kNan, occupied), VoxelClass::kUnknown);
  EXPECT_EQ(classifyLogOdds(occupied, occupied), VoxelClass::kFree);  // strict >
  EXPECT_EQ(classifyLogOdds(std::nextafter(occupied, 1.0f), occupied), VoxelClass::kOccupied);
  EXPECT_EQ(classifyLogOdds(-0.4f, occupied), VoxelClass::kFree);
}

}  // namespace
}  // namespace fvp::host::map
