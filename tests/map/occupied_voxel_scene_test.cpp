// The Embree scene over occupied voxels against the DDA traversal (kernels/fvp_dda.h on the
// cpu backend): same first occupied voxel, same occlusion verdict, before and after
// incremental brick updates.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include "fvp/accel/backend.h"
#include "fvp/accel/ray_workload.h"
#include "fvp/host/map/occupied_voxel_scene.h"

namespace fvp::host::map {
namespace {

using Index = std::array<int, 3>;

GridGeometry testGrid() {
  GridGeometry g;
  g.voxel_size_m = 0.01;
  g.first_voxel = {-32, -24, 5};
  g.dims = {64, 48, 40};
  return g;
}

int linear(const GridGeometry& g, const Index& i) {
  return i[0] + g.dims[0] * (i[1] + g.dims[1] * i[2]);
}

// Blobs, plates and scattered voxels: 1 = occupied, 0 = not.
std::vector<float> randomOccupancy(const GridGeometry& g, std::uint64_t seed) {
  std::vector<float> occ(static_cast<std::size_t>(g.voxelCount()), 0.0f);
  std::mt19937_64 rng(seed);
  auto set = [&](int x, int y, int z) {
    if (x >= 0 && y >= 0 && z >= 0 && x < g.dims[0] && y < g.dims[1] && z < g.dims[2])
      occ[static_cast<std::size_t>(linear(g, {x, y, z}))] = 1.0f;
  };
  std::uniform_int_distribution<int> ux(0, g.dims[0] - 1), uy(0, g.dims[1] - 1),
      uz(0, g.dims[2] - 1);
  std::uniform_int_distribution<int> ur(1, 5);
  for (int b = 0; b < 14; ++b) {  // spheres
    const int cx = ux(rng), cy = uy(rng), cz = uz(rng), r = ur(rng);
    for (int z = cz - r; z <= cz + r; ++z)
      for (int y = cy - r; y <= cy + r; ++y)
        for (int x = cx - r; x <= cx + r; ++x)
          if ((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz) <= r * r)
            set(x, y, z);
  }
  for (int p = 0; p < 4; ++p) {  // thin plates (leaves)
    const int cx = ux(rng), cy = uy(rng), cz = uz(rng);
    for (int y = cy - 6; y <= cy + 6; ++y)
      for (int x = cx - 6; x <= cx + 6; ++x) set(x, y, cz);
  }
  for (int v = 0; v < 1500; ++v) set(ux(rng), uy(rng), uz(rng));  // scattered
  return occ;
}

std::vector<Index> occupiedList(const GridGeometry& g, const std::vector<float>& occ) {
  std::vector<Index> list;
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = 0; x < g.dims[0]; ++x)
        if (occ[static_cast<std::size_t>(linear(g, {x, y, z}))] > 0.5f) list.push_back({x, y, z});
  return list;
}

struct Agreement {
  std::size_t rays = 0, hits = 0, same_voxel = 0, same_nudged_voxel = 0, same_occlusion = 0;
  double percent(std::size_t n) const { return 100.0 * static_cast<double>(n) / rays; }
};

// Embree's first hits and occlusion verdicts against the DDA on the same occupancy.
Agreement compareWithDda(const OccupiedVoxelScene& scene, const std::vector<float>& occ,
                         const std::vector<accel::Ray>& rays) {
  const GridGeometry& g = scene.grid();
  accel::DenseGrid dense;
  dense.params = g.params();
  dense.occupancy = occ;
  dense.field.assign(occ.size(), 0.0f);
  auto backend = accel::createBackend(accel::BackendKind::kCpu);
  const std::vector<accel::RayResult> dda = accel::traverseOnBackend(*backend, dense, rays, 0.5f);
  const std::vector<std::optional<VoxelHit>> hits = scene.firstHits(rays);
  const std::vector<std::uint8_t> occluded = scene.occludedBatch(rays);
  const accel::GridParams& p = dense.params;

  Agreement a;
  for (std::size_t r = 0; r < rays.size(); ++r) {
    // A ray starting inside an occupied voxel stops there in the DDA but sees that voxel's
    // exit face in Embree; views start in free space, so such rays are left out.
    Index o{static_cast<int>(std::floor((rays[r].origin_m[0] - p.origin_x_m) / p.voxel_size_m)),
            static_cast<int>(std::floor((rays[r].origin_m[1] - p.origin_y_m) / p.voxel_size_m)),
            static_cast<int>(std::floor((rays[r].origin_m[2] - p.origin_z_m) / p.voxel_size_m))};
    if (scene.isOccupied(o)) continue;
    ++a.rays;
    const bool dda_hit = dda[r].status == FVP_RAY_HIT_OCCUPIED;
    a.hits += dda_hit;
    a.same_occlusion += (occluded[r] != 0) == dda_hit;
    if (!dda_hit) {
      a.same_voxel += !hits[r].has_value();
      a.same_nudged_voxel += !hits[r].has_value();
      continue;
    }
    if (!hits[r]) continue;
    a.same_voxel += linear(g, hits[r]->voxel) == dda[r].stop_voxel;
    // The voxel containing the hit point nudged a little further along the ray.
    Eigen::Vector3f d(rays[r].end_m[0] - rays[r].origin_m[0],
                      rays[r].end_m[1] - rays[r].origin_m[1],
                      rays[r].end_m[2] - rays[r].origin_m[2]);
    const Eigen::Vector3f q = hits[r]->point_m + d.normalized() * (1e-4f * p.voxel_size_m);
    const Index n{static_cast<int>(std::floor((q.x() - p.origin_x_m) / p.voxel_size_m)),
                  static_cast<int>(std::floor((q.y() - p.origin_y_m) / p.voxel_size_m)),
                  static_cast<int>(std::floor((q.z() - p.origin_z_m) / p.voxel_size_m))};
    a.same_nudged_voxel += linear(g, n) == dda[r].stop_voxel;
  }
  return a;
}

TEST(OccupiedVoxelScene, FacesOfSingleAndAdjacentVoxelsAcrossBricks) {
  OccupiedVoxelScene scene(testGrid());
  scene.setOccupied({7, 3, 3}, true);
  EXPECT_EQ(scene.commit(), 1u);
  EXPECT_EQ(scene.faceCount(), 6u);
  scene.setOccupied({8, 3, 3}, true);  // next brick: both bricks change
  EXPECT_EQ(scene.commit(), 2u);
  EXPECT_EQ(scene.faceCount(), 10u);
  EXPECT_EQ(scene.brickGeometryCount(), 2u);
  scene.setOccupied({7, 3, 3}, false);
  scene.commit();
  EXPECT_EQ(scene.faceCount(), 6u);
  EXPECT_EQ(scene.brickGeometryCount(), 1u);
  EXPECT_EQ(scene.occupiedCount(), 1u);
  EXPECT_THROW(scene.setOccupied({64, 0, 0}, true), std::out_of_range);
  EXPECT_THROW(scene.setOccupied({0, -1, 0}, true), std::out_of_range);
}

TEST(OccupiedVoxelScene, AxisRayHitsTheNearFaceAndOcclusionEndsAtTheSegment) {
  const GridGeometry g = testGrid();
  OccupiedVoxelScene scene(g, {{10, 10, 10}});
  const Eigen::Vector3d c = g.voxelCenter_m({10, 10, 10});
  const Eigen::Vector3f from = (c - Eigen::Vector3d(0.1, 0.0, 0.0)).cast<float>();
  const auto hit = scene.firstHit(from, Eigen::Vector3f::UnitX());
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->voxel, (Index{10, 10, 10}));
  EXPECT_NEAR(hit->t, 0.095f, 1e-6f);
  EXPECT_FALSE(scene.firstHit(from, -Eigen::Vector3f::UnitX()).has_value());
  EXPECT_FALSE(scene.firstHit(from, Eigen::Vector3f::UnitX(), 0.0f, 0.09f).has_value());
  EXPECT_FALSE(scene.occluded(from, (c - Eigen::Vector3d(0.006, 0.0, 0.0)).cast<float>()));
  EXPECT_TRUE(scene.occluded(from, (c - Eigen::Vector3d(0.004, 0.0, 0.0)).cast<float>()));
  EXPECT_TRUE(scene.occluded(from, (c + Eigen::Vector3d(0.1, 0.0, 0.0)).cast<float>()));
  EXPECT_FALSE(scene.firstHit(from, Eigen::Vector3f::Zero()).has_value());
}

TEST(OccupiedVoxelScene, FirstHitsAndOcclusionMatchTheDda) {
  const GridGeometry g = testGrid();
  const std::vector<float> occ = randomOccupancy(g, 5);
  const auto t0 = std::chrono::steady_clock::now();
  OccupiedVoxelScene scene(g, occupiedList(g, occ));
  const double build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  accel::RayOptions options;
  options.count = 40000;
  options.outside_fraction = 0.3f;
  const auto rays = accel::makeRandomRays(g.params(), options, 17);
  const Agreement a = compareWithDda(scene, occ, rays);
  std::cout << "[ embree vs dda ] rays " << a.rays << ", dda hits " << a.hits << ", occupied "
            << scene.occupiedCount() << ", faces " << scene.faceCount() << ", build " << build_ms
            << " ms; same voxel " << a.percent(a.same_voxel) << " %, nudged point "
            << a.percent(a.same_nudged_voxel) << " %, occlusion " << a.percent(a.same_occlusion)
            << " %\n";
  EXPECT_GT(a.hits, a.rays / 4);
  EXPECT_GE(a.percent(a.same_voxel), 99.9);
  EXPECT_GE(a.percent(a.same_nudged_voxel), 99.9);
  EXPECT_GE(a.percent(a.same_occlusion), 99.9);
}

TEST(OccupiedVoxelScene, IncrementalUpdatesRebuildOnlyChangedBricks) {
  const GridGeometry g = testGrid();
  std::vector<float> occ = randomOccupancy(g, 21);
  OccupiedVoxelScene scene(g, occupiedList(g, occ));
  const std::size_t total_bricks = static_cast<std::size_t>(g.voxelCount() / FVP_BRICK_VOXELS);

  // A "scan": a few small changes in one corner of the grid.
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> u(0, 15);
  for (int k = 0; k < 60; ++k) {
    const Index i{u(rng), u(rng), u(rng)};
    const bool value = (k % 3) != 0;
    scene.setOccupied(i, value);
    occ[static_cast<std::size_t>(linear(g, i))] = value ? 1.0f : 0.0f;
  }
  EXPECT_TRUE(scene.hasPendingChanges());
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t rebuilt = scene.commit();
  const double commit_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_FALSE(scene.hasPendingChanges());
  EXPECT_LE(rebuilt, 27u);  // bricks 0..2 per axis at most
  EXPECT_GT(rebuilt, 0u);
  std::cout << "[ incremental ] rebuilt " << rebuilt << " of " << total_bricks << " bricks in "
            << commit_ms << " ms\n";

  accel::RayOptions options;
  options.count = 20000;
  options.outside_fraction = 0.3f;
  const auto rays = accel::makeRandomRays(g.params(), options, 29);
  const Agreement a = compareWithDda(scene, occ, rays);
  EXPECT_GE(a.percent(a.same_voxel), 99.9);
  EXPECT_GE(a.percent(a.same_occlusion), 99.9);

  // The same state built from scratch: identical answers.
  OccupiedVoxelScene fresh(g, occupiedList(g, occ));
  EXPECT_EQ(fresh.faceCount(), scene.faceCount());
  EXPECT_EQ(fresh.occupiedCount(), scene.occupiedCount());
  const auto h1 = scene.firstHits(rays);
  const auto h2 = fresh.firstHits(rays);
  std::size_t same = 0;
  for (std::size_t r = 0; r < rays.size(); ++r) {
    same += h1[r].has_value() == h2[r].has_value() && (!h1[r] || h1[r]->voxel == h2[r]->voxel);
  }
  EXPECT_GE(100.0 * same / rays.size(), 99.9);

  // Clearing everything removes every geometry.
  scene.assignOccupied({});
  scene.commit();
  EXPECT_EQ(scene.faceCount(), 0u);
  EXPECT_EQ(scene.brickGeometryCount(), 0u);
  EXPECT_FALSE(scene.firstHits(rays)[0].has_value());
}

TEST(OccupiedVoxelScene, SingleRayAndPacketQueriesAgree) {
  const GridGeometry g = testGrid();
  const std::vector<float> occ = randomOccupancy(g, 8);
  OccupiedVoxelScene scene(g, occupiedList(g, occ));
  accel::RayOptions options;
  options.count = 3001;  // not a multiple of 16: a partial last packet
  const auto rays = accel::makeRandomRays(g.params(), options, 4);
  const auto packet_hits = scene.firstHits(rays);
  const auto packet_occluded = scene.occludedBatch(rays);
  for (std::size_t r = 0; r < rays.size(); ++r) {
    const Eigen::Vector3f o(rays[r].origin_m[0], rays[r].origin_m[1], rays[r].origin_m[2]);
    const Eigen::Vector3f e(rays[r].end_m[0], rays[r].end_m[1], rays[r].end_m[2]);
    const auto single = scene.firstHit(o, e - o, 0.0f, 1.0f);
    ASSERT_EQ(single.has_value(), packet_hits[r].has_value()) << r;
    if (single) {
      EXPECT_EQ(single->voxel, packet_hits[r]->voxel) << r;
    }
    EXPECT_EQ(scene.occluded(o, e), packet_occluded[r] != 0) << r;
  }
}

}  // namespace
}  // namespace fvp::host::map
