// Information gain (paper Eq. 1-2) on small hand-made maps, against hand-computed values and
// a plain walk over MapEngine's own reads; grid and octomap engines agree; the info_gain
// kernel on every backend identical to the host walk.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "../map/synthetic_scan.h"
#include "backend_fixture.h"
#include "fvp/accel/backend.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/planner/info_gain_evaluator.h"

extern "C" {
#include "fvp_dda.h"
}

namespace fvp::host::planner {
namespace {

using map::MapConfig;
using Vec3f = Eigen::Vector3f;

MapConfig smallConfig() {
  MapConfig c;
  c.observation_min_m = {-0.25, -0.25, 0.0};
  c.observation_max_m = {0.25, 0.25, 0.5};
  return c;
}
const ClusterRegion kRegion({0.0, 0.0, 0.2}, 0.03);

ViewQuery query(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  ViewQuery q;
  q.T_world_camera.translation() = eye;
  q.target_m = target;
  return q;
}

// The gain of one ray the slow way: MapEngine's reads per fine voxel of the same walk.
double referenceGain(map::MapEngine& e, const Eigen::Vector3d& entry, const Eigen::Vector3d& end,
                     double max_d, std::uint32_t* n_c, bool* roi_weighted) {
  const map::GridGeometry& g = e.gridGeometry(map::MapLevel::kFine);
  const fvp_grid_params p = g.params();
  const float o[3] = {float(entry.x()), float(entry.y()), float(entry.z())};
  const float t[3] = {float(end.x()), float(end.y()), float(end.z())};
  fvp_dda d;
  *n_c = 0;
  double sum = 0.0;
  if (fvp_dda_init(&d, &p, o, t) != 0) return 0.0;
  for (;;) {
    const std::array<int, 3> idx{d.key[0], d.key[1], d.key[2]};
    const Eigen::Vector3d c = g.voxelCenter_m(idx);
    // The maps' own region test (voxel centre within the radius, in grid units).
    const fvp_region region = map::regionInGrid(g, e.region());
    if (fvp_region_contains(&region, idx[0], idx[1], idx[2])) {
      ++*n_c;
      const map::VoxelState s = e.fineState(c);
      if (s.occupancy == map::VoxelClass::kOccupied) break;
      if (s.occupancy == map::VoxelClass::kUnknown) {
        const double w = roiProximityWeight(e.roiDistance_m(idx), max_d);
        *roi_weighted |= w > 0.5;
        sum += std::lround(w * 8192.0) / 8192.0;
      }
    }
    const int axis = fvp_dda_next_axis(&d);
    if (axis < 0) break;
    fvp_dda_advance(&d, axis);
    if (d.key[axis] < 0 || d.key[axis] >= (&p.dim_x)[axis]) break;
  }
  return *n_c ? sum / *n_c : 0.0;
}

TEST(InfoGain, Eq1WeightByHand) {
  EXPECT_DOUBLE_EQ(roiProximityWeight(0.0, 0.02), 1.0);
  EXPECT_DOUBLE_EQ(roiProximityWeight(0.01, 0.02), 0.75);
  EXPECT_DOUBLE_EQ(roiProximityWeight(0.02, 0.02), 0.5);
  EXPECT_DOUBLE_EQ(roiProximityWeight(0.5, 0.02), 0.5);
}

TEST(InfoGain, UnknownRegionWithoutRoiGainsOneHalfAndMissesGainNothing) {
  auto e = map::createMapEngine("octomap", smallConfig(), kRegion, nullptr);
  InfoGainEvaluator gain({});
  EXPECT_THROW(gain.evaluate({}), std::logic_error);
  gain.refresh(*e);
  const std::vector<ViewQuery> q = {query({0.0, -0.2, 0.2}, {0.0, 0.0, 0.2}),
                                    query({0.2, 0.2, 0.2}, {0.2, 0.2, 0.0})};
  const auto r = gain.evaluate(q);
  // Every region voxel unknown and no ROI known: Eq. 1 gives 0.5 to each, so IG = 0.5.
  EXPECT_DOUBLE_EQ(r[0].ig, 0.5);
  EXPECT_GE(r[0].region_voxels, 29u);  // 3 cm of 1 mm voxels to the centre, or more
  EXPECT_FALSE(r[0].blocked);
  // A ray that never enters the region: N_c = 0, IG = 0.
  EXPECT_EQ(r[1].region_voxels, 0u);
  EXPECT_EQ(r[1].ig, 0.0);
}

TEST(InfoGain, OccupiedCoarseVoxelBeforeTheRegionBlocksTheView) {
  auto e = map::createMapEngine("octomap", smallConfig(), kRegion, nullptr);
  // One hit 10 cm in front of the region on the viewing line.
  e->integrate(map::testing::makeClouds({0.0, -0.24, 0.2}, {}, {Vec3f(0.0f, -0.13f, 0.2f)}));
  InfoGainEvaluator gain({});
  gain.refresh(*e);
  const auto r = gain.evaluate(std::vector{query({0.0, -0.2, 0.2}, {0.0, 0.0, 0.2})});
  EXPECT_TRUE(r[0].blocked);
  EXPECT_EQ(r[0].region_voxels, 0u);
  EXPECT_EQ(r[0].ig, 0.0);
}

TEST(InfoGain, TargetBehindAnOccupiedVoxelStopsThereByHand) {
  auto e = map::createMapEngine("octomap", smallConfig(), kRegion, nullptr);
  // An occupied (non-ROI) fine voxel at the region centre, seen from above: its ray marks
  // free voxels along +z only, off the viewing line below.
  e->integrate(
      map::testing::makeClouds({0.0005, 0.0005, 0.45}, {}, {Vec3f(0.0005f, 0.0005f, 0.2005f)}));
  ASSERT_EQ(e->fineState({0.0005, 0.0005, 0.2005}).occupancy, map::VoxelClass::kOccupied);
  InfoGainEvaluator gain({});
  gain.refresh(*e);
  // Viewing along +y through the occupied voxel to a target 1 cm behind it: the walk counts
  // the unknown voxels from the region's surface (weight 0.5 each) and the occupied one
  // (weight 0), then stops. So IG = 0.5 (N_c - 1) / N_c.
  const auto r = gain.evaluate(std::vector{query({0.0005, -0.2, 0.2005}, {0.0005, 0.01, 0.2005})});
  ASSERT_GT(r[0].region_voxels, 1u);
  EXPECT_EQ(r[0].region_voxels, 31u);  // y voxels -30 .. 0: 30 unknown + the occupied one
  EXPECT_DOUBLE_EQ(r[0].ig, 0.5 * (r[0].region_voxels - 1) / r[0].region_voxels);
  // Stopping short of it: all unknown.
  const auto before =
      gain.evaluate(std::vector{query({0.0005, -0.2, 0.2005}, {0.0005, -0.005, 0.2005})});
  EXPECT_DOUBLE_EQ(before[0].ig, 0.5);
}

TEST(InfoGain, SnapshotEqualsMapReadsOnRandomRays) {
  const std::uint64_t seed = 7;
  auto e = map::createMapEngine("octomap", smallConfig(), kRegion, nullptr);
  const auto world = map::testing::makeWorld(seed, kRegion.center_m(), 4);
  e->integrate(map::testing::renderScan(world, {0.0, -0.2, 0.25}, 64, 48, 0.6, seed).clouds());
  e->integrate(map::testing::renderScan(world, {0.15, -0.15, 0.2}, 64, 48, 0.6, seed + 1).clouds());
  InfoGainConfig config;
  config.max_d_m = 0.02;
  InfoGainEvaluator gain(config);
  gain.refresh(*e);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::size_t with_roi_weight = 0;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d target =
        kRegion.center_m() + 0.025 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    Eigen::Vector3d dir(u(rng), u(rng), u(rng));
    if (dir.norm() < 1e-3) continue;
    const Eigen::Vector3d eye = target + 0.25 * dir.normalized();
    const GainResult r = gain.evaluateRay(eye, target);
    if (r.blocked) continue;
    // Entry point as the evaluator computes it.
    const Eigen::Vector3d d = target - eye, f = eye - kRegion.center_m();
    const double a = d.squaredNorm(), b = 2 * f.dot(d), c = f.squaredNorm() - 0.03 * 0.03;
    const double disc = b * b - 4 * a * c;
    const double t = disc >= 0.0 ? (-b - std::sqrt(disc)) / (2 * a) : 2.0;
    if (t > 1.0) {  // the segment ends before the region: nothing to gain
      ASSERT_EQ(r.region_voxels, 0u) << i;
      ASSERT_EQ(r.ig, 0.0) << i;
      continue;
    }
    std::uint32_t n_c = 0;
    bool roi_weighted = false;
    const double want = referenceGain(*e, eye + t * d, target, 0.02, &n_c, &roi_weighted);
    ASSERT_EQ(r.region_voxels, n_c) << i;
    ASSERT_NEAR(r.ig, want, 1e-12) << i;
    with_roi_weight += roi_weighted;
  }
  EXPECT_GT(with_roi_weight, 10u);  // the ROI weighting was exercised
}

TEST(InfoGain, GridAndOctomapEnginesAgree) {
  auto backend = accel::createBackend("cpu");
  auto grid = map::createMapEngine("grid", smallConfig(), kRegion, backend.get());
  auto octo = map::createMapEngine("octomap", smallConfig(), kRegion, nullptr);
  const auto world = map::testing::makeWorld(11, kRegion.center_m(), 5);
  for (int v = 0; v < 3; ++v) {
    const auto scan = map::testing::renderScan(
        world, kRegion.center_m() + 0.2 * Eigen::Vector3d(std::cos(v), -1.0, 0.2 * v).normalized(),
        64, 48, 0.6, 11 + v);
    grid->integrate(scan.clouds());
    octo->integrate(scan.clouds());
  }
  for (GainMode mode : {GainMode::kSingleRay, GainMode::kFrustum}) {
    InfoGainConfig config;
    config.mode = mode;
    config.frustum_rays_x = 4;
    config.frustum_rays_y = 3;
    InfoGainEvaluator a(config), b(config);
    a.refresh(*grid);
    b.refresh(*octo);
    std::vector<ViewQuery> queries;
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d target =
          kRegion.center_m() + 0.02 * Eigen::Vector3d(u(rng), u(rng), u(rng));
      const Eigen::Vector3d eye =
          target + 0.25 * Eigen::Vector3d(u(rng), -1.0, u(rng)).normalized();
      ViewQuery q;
      q.T_world_camera = Eigen::Isometry3d::Identity();
      q.T_world_camera.translation() = eye;
      // Look at the target (z through it) for the frustum mode.
      const Eigen::Vector3d z = (target - eye).normalized();
      const Eigen::Vector3d x = z.unitOrthogonal(), y = z.cross(x);
      q.T_world_camera.linear() << x, y, z;
      q.target_m = target;
      queries.push_back(q);
    }
    const auto ra = a.evaluate(queries), rb = b.evaluate(queries);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < queries.size(); ++i)
      differ += ra[i].ig != rb[i].ig || ra[i].region_voxels != rb[i].region_voxels;
    // The engines agree on >= 99.9 % of voxel classes (docs/design.md section 5); gains over a
    // few hundred voxels each may differ where one voxel does.
    EXPECT_LE(differ, queries.size() / 50) << "mode " << int(mode);
  }
}

TEST(InfoGain, EmbreeCullingRemovesOnlyBlockedRays) {
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  auto e = map::createMapEngine("grid", smallConfig(), kRegion, cpu.get());
  const auto world = map::testing::makeWorld(5, kRegion.center_m(), 5);
  for (int v = 0; v < 3; ++v)
    e->integrate(map::testing::renderScan(
                     world,
                     kRegion.center_m() +
                         0.22 * Eigen::Vector3d(0.5 * std::cos(v), -1.0, 0.2 * v).normalized(),
                     48, 36, 0.6, 5 + v)
                     .clouds());
  std::vector<ViewQuery> queries;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d target =
        kRegion.center_m() + 0.02 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    queries.push_back(
        query(target + 0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized(), target));
  }
  InfoGainConfig plain, culling;
  culling.embree_cull = true;
  InfoGainEvaluator a(plain), b(culling, cpu.get());
  a.refresh(*e);
  b.refresh(*e);
  EvaluateStats stats;
  const auto want = a.evaluate(queries), got = b.evaluate(queries, &stats);
  std::size_t blocked = 0, differ = 0;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    blocked += want[i].blocked;
    differ += got[i].ig != want[i].ig || got[i].blocked != want[i].blocked;
  }
  EXPECT_GT(blocked, 100u);  // the back plane blocks many of these views
  // Embree culls (nearly) exactly the rays the walk finds blocked before the region; it
  // tests voxel faces where the walk tests the lattice, so a grazing ray may differ.
  EXPECT_NEAR(double(stats.culled), double(blocked), 0.01 * queries.size());
  EXPECT_LE(differ, queries.size() / 100);
  EXPECT_EQ(stats.walked + stats.culled, stats.rays);
}

// ---------------------------------------------------------------------------------------
// The info_gain kernel on every backend against the host walk (no backend): identical
// integers, so identical gains, on fresh random maps and candidates.

using InfoGainBackends = fvp::testing::BackendFixture;

TEST_P(InfoGainBackends, KernelEqualsHostWalkOnRandomMapsAndCandidates) {
  const std::uint64_t seed = fvp::testing::freshSeed();
  SCOPED_TRACE(fvp::testing::replayHint(seed));
  auto e = map::createMapEngine("grid", smallConfig(), kRegion, cpu_.get());
  const auto world = map::testing::makeWorld(seed, kRegion.center_m(), 5);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  for (int v = 0; v < 3; ++v) {
    const Eigen::Vector3d dir(u(rng), -1.0, 0.3 * u(rng));
    e->integrate(map::testing::renderScan(world, kRegion.center_m() + 0.22 * dir.normalized(), 48,
                                          36, 0.6, seed + v)
                     .clouds());
  }
  // Candidates all around: in front of the scans (free and unknown space), behind the back
  // plane (blocked in the coarse map) and inside the region (no coarse walk).
  std::vector<ViewQuery> queries;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d target =
        kRegion.center_m() + 0.025 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    const Eigen::Vector3d dir = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const double distance = i % 10 == 0 ? 0.02 * unit(rng) : 0.05 + 0.3 * unit(rng);
    ViewQuery q;
    q.T_world_camera.translation() = target + distance * dir;
    const Eigen::Vector3d z = -dir, x = z.unitOrthogonal(), y = z.cross(x);
    q.T_world_camera.linear() << x, y, z;
    q.target_m = target;
    queries.push_back(q);
  }
  for (GainMode mode : {GainMode::kSingleRay, GainMode::kFrustum}) {
    InfoGainConfig config;
    config.mode = mode;
    config.max_d_m = 0.02;
    config.frustum_rays_x = 5;
    config.frustum_rays_y = 4;
    InfoGainEvaluator host(config), device(config, backend_.get());
    host.refresh(*e);
    device.refresh(*e);
    EXPECT_STREQ(device.walkDevice(), accel::toString(GetParam()).data());
    // A small batch first, then the whole set: the kept device buffers grow between calls.
    const std::span<const ViewQuery> few(queries.data(), 10);
    const auto got_few = device.evaluate(few);
    const auto want = host.evaluate(queries), got = device.evaluate(queries);
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < few.size(); ++i) ASSERT_EQ(got_few[i].ig, want[i].ig) << i;
    std::size_t blocked = 0, gaining = 0;
    for (std::size_t i = 0; i < queries.size(); ++i) {
      ASSERT_EQ(got[i].ig, want[i].ig) << "mode " << int(mode) << " query " << i;
      ASSERT_EQ(got[i].region_voxels, want[i].region_voxels) << i;
      ASSERT_EQ(got[i].voxel_steps, want[i].voxel_steps) << i;
      ASSERT_EQ(got[i].blocked, want[i].blocked) << i;
      blocked += want[i].blocked;
      gaining += want[i].ig > 0.0;
    }
    // Both the coarse blocking and the fine gain were exercised.
    if (mode == GainMode::kSingleRay) {
      EXPECT_GT(blocked, 0u);
    }
    EXPECT_GT(gaining, queries.size() / 4);
  }
}

FVP_INSTANTIATE_FOR_ALL_BACKENDS(InfoGainBackends);

}  // namespace
}  // namespace fvp::host::planner
