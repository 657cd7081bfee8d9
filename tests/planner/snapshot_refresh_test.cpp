// The gain snapshot updated from the bricks a view changed (InfoGainEvaluator::refresh after
// MapEngine::changesSince) equals a fresh build of it byte for byte: after every scan of a
// random sequence, on both map engines, and on every backend's device copy (the sparse
// upload); moving the fine map to another region rebuilds it. The change log itself
// (BrickChangeLog) by hand.
#include <gtest/gtest.h>

#include <random>

#include "../map/synthetic_scan.h"
#include "backend_fixture.h"
#include "fvp/accel/backend.h"
#include "fvp/host/map/brick_change_log.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/map/octomap_map_engine.h"
#include "fvp/host/planner/info_gain_evaluator.h"

namespace fvp::host::planner {
namespace {

map::MapConfig smallConfig() {
  map::MapConfig c;
  c.observation_min_m = {-0.25, -0.25, 0.0};
  c.observation_max_m = {0.25, 0.25, 0.5};
  return c;
}
const ClusterRegion kRegion({0.0, 0.0, 0.2}, 0.03);

/// A view of the region from a random side, 0.15-0.3 m away.
LabeledClouds randomView(const map::testing::SyntheticWorld& world, const ClusterRegion& region,
                         std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), distance_m(0.15, 0.3);
  const Eigen::Vector3d dir = Eigen::Vector3d(u(rng), u(rng), 0.4 * u(rng)).normalized();
  return map::testing::renderScan(world, region.center_m() + distance_m(rng) * dir, 48, 36, 0.6,
                                  rng())
      .clouds();
}

/// The updated evaluator against a fresh full build over the same map, byte for byte, and
/// (with a backend) against its own device copy.
void expectSameAsFreshBuild(const InfoGainEvaluator& updated, map::MapEngine& map,
                            const std::string& context) {
  InfoGainEvaluator fresh(updated.config());
  fresh.refresh(map);
  ASSERT_TRUE(fresh.lastRefresh().full);
  const auto same = [](std::span<const std::uint32_t> a, std::span<const std::uint32_t> b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end());
  };
  EXPECT_TRUE(same(updated.fineWords(), fresh.fineWords())) << context << ": fine codes";
  EXPECT_TRUE(same(updated.coarseWords(), fresh.coarseWords())) << context << ": coarse";
  if (std::string(updated.walkDevice()) == "host") return;
  const std::vector<std::uint32_t> device_fine = updated.deviceFineWords();
  const std::vector<std::uint32_t> device_coarse = updated.deviceCoarseWords();
  EXPECT_TRUE(same(device_fine, fresh.fineWords())) << context << ": device fine codes";
  EXPECT_TRUE(same(device_coarse, fresh.coarseWords())) << context << ": device coarse";
}

/// Integrates `views` random views, refreshing after each, and checks every refresh.
void checkSequence(map::MapEngine& map, InfoGainEvaluator& evaluator, std::uint64_t seed,
                   int views) {
  const auto world = map::testing::makeWorld(seed, map.region().center_m(), 5);
  std::mt19937_64 rng(seed);
  std::size_t updated_refreshes = 0;
  for (int v = 0; v < views; ++v) {
    map.integrate(randomView(world, map.region(), rng));
    evaluator.refresh(map);
    const SnapshotRefreshStats& r = evaluator.lastRefresh();
    if (!r.full) {
      ++updated_refreshes;
      // A view of a small region changes bricks, not the whole map.
      EXPECT_GT(r.fine_bricks + r.coarse_bricks, 0u) << "view " << v;
    }
    expectSameAsFreshBuild(evaluator, map, "view " + std::to_string(v));
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_EQ(updated_refreshes, std::size_t(views - 1)) << "only the first refresh builds whole";
  // No new scan: nothing to rewrite, nothing to send.
  evaluator.refresh(map);
  EXPECT_FALSE(evaluator.lastRefresh().full);
  EXPECT_EQ(evaluator.lastRefresh().fine_bricks + evaluator.lastRefresh().coarse_bricks, 0u);
  EXPECT_EQ(evaluator.lastRefresh().upload_bytes, 0u);
}

using SnapshotRefreshBackends = fvp::testing::BackendFixture;

// Grid engine and evaluator on the backend under test: the map's change record, the sparse
// update and its upload (PoCL, lavapipe; FVP_VULKAN_STAGING=1 for the staging copies).
TEST_P(SnapshotRefreshBackends, UpdatedSnapshotEqualsFreshBuildAfterEveryScan) {
  const std::uint64_t seed = fvp::testing::freshSeed();
  SCOPED_TRACE(fvp::testing::replayHint(seed));
  auto map = map::createMapEngine("grid", smallConfig(), kRegion, backend_.get());
  InfoGainEvaluator evaluator(InfoGainConfig{}, backend_.get());
  checkSequence(*map, evaluator, seed, 6);
}

FVP_INSTANTIATE_FOR_ALL_BACKENDS(SnapshotRefreshBackends);

TEST(SnapshotRefresh, OctomapEngineUpdatedSnapshotEqualsFreshBuild) {
  const std::uint64_t seed = fvp::testing::freshSeed();
  SCOPED_TRACE(fvp::testing::replayHint(seed));
  auto map = map::createMapEngine("octomap", smallConfig(), kRegion, nullptr);
  InfoGainEvaluator evaluator{InfoGainConfig{}};
  checkSequence(*map, evaluator, seed, 5);
}

TEST(SnapshotRefresh, UploadsLessThanTheWholeSnapshot) {
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  auto map = map::createMapEngine("grid", smallConfig(), kRegion, cpu.get());
  const auto world = map::testing::makeWorld(11, kRegion.center_m(), 5);
  std::mt19937_64 rng(11);
  InfoGainEvaluator evaluator(InfoGainConfig{}, cpu.get());
  map->integrate(randomView(world, kRegion, rng));
  evaluator.refresh(*map);
  ASSERT_EQ(evaluator.lastRefresh().upload_bytes, evaluator.snapshotBytes());
  map->integrate(randomView(world, kRegion, rng));
  evaluator.refresh(*map);
  EXPECT_GT(evaluator.lastRefresh().upload_bytes, 0u);
  EXPECT_LT(evaluator.lastRefresh().upload_bytes, evaluator.snapshotBytes());
}

TEST(SnapshotRefresh, AnotherRegionOrMapRebuildsWhole) {
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  for (const char* engine : {"grid", "octomap"}) {
    SCOPED_TRACE(engine);
    auto map = map::createMapEngine(engine, smallConfig(), kRegion, cpu.get());
    const auto world = map::testing::makeWorld(3, kRegion.center_m(), 5);
    std::mt19937_64 rng(3);
    InfoGainEvaluator evaluator(InfoGainConfig{}, cpu.get());
    map->integrate(randomView(world, kRegion, rng));
    evaluator.refresh(*map);
    const ClusterRegion next({0.05, 0.0, 0.2}, 0.03);
    map->moveToRegion(next);
    map->integrate(randomView(world, next, rng));
    evaluator.refresh(*map);
    EXPECT_TRUE(evaluator.lastRefresh().full);
    expectSameAsFreshBuild(evaluator, *map, "after moveToRegion");
    // Another map of the same lattice: its cursor epochs differ.
    auto other = map::createMapEngine(engine, smallConfig(), next, cpu.get());
    other->integrate(randomView(world, next, rng));
    evaluator.refresh(*other);
    EXPECT_TRUE(evaluator.lastRefresh().full);
    expectSameAsFreshBuild(evaluator, *other, "another map");
  }
}

TEST(SnapshotRefresh, SeveralScansBetweenRefreshesAndAMoveWithoutAScan) {
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  for (const char* engine : {"grid", "octomap"}) {
    SCOPED_TRACE(engine);
    auto map = map::createMapEngine(engine, smallConfig(), kRegion, cpu.get());
    const auto world = map::testing::makeWorld(5, kRegion.center_m(), 5);
    std::mt19937_64 rng(5);
    InfoGainEvaluator evaluator(InfoGainConfig{}, cpu.get());
    map->integrate(randomView(world, kRegion, rng));
    evaluator.refresh(*map);
    for (int i = 0; i < 3; ++i) map->integrate(randomView(world, kRegion, rng));
    evaluator.refresh(*map);
    EXPECT_FALSE(evaluator.lastRefresh().full);
    expectSameAsFreshBuild(evaluator, *map, "three scans, one refresh");
    // A moved region with no scan since: the scan count is the same, the snapshot is not.
    map->moveToRegion(ClusterRegion({0.02, 0.01, 0.2}, 0.03));
    evaluator.refresh(*map);
    EXPECT_TRUE(evaluator.lastRefresh().full);
    expectSameAsFreshBuild(evaluator, *map, "moved, no scan");
  }
}

/// An engine of a program's own that records no changes (the octomap engine with its change
/// recording disowned): every refresh must rebuild.
class UnrecordedOctomapEngine : public map::OctomapMapEngine {
 public:
  using OctomapMapEngine::OctomapMapEngine;
  bool recordsBrickChanges() const override { return false; }
};

TEST(SnapshotRefresh, AnEngineThatRecordsNoChangesIsRebuiltEveryTime) {
  UnrecordedOctomapEngine map(smallConfig(), kRegion);
  const auto world = map::testing::makeWorld(7, kRegion.center_m(), 5);
  std::mt19937_64 rng(7);
  InfoGainEvaluator evaluator{InfoGainConfig{}};
  for (int v = 0; v < 2; ++v) {
    map.integrate(randomView(world, kRegion, rng));
    evaluator.refresh(map);
    EXPECT_TRUE(evaluator.lastRefresh().full) << "view " << v;
    expectSameAsFreshBuild(evaluator, map, "view " + std::to_string(v));
  }
}

TEST(BrickChangeLog, ReportsBricksChangedAfterACursorAndAllForAnotherEpoch) {
  map::GridGeometry g;
  g.voxel_size_m = 0.001;
  g.dims = {16, 16, 24};  // 2 x 2 x 3 bricks
  map::BrickChangeLog log(g);
  EXPECT_EQ(log.brickCount(), 12u);
  EXPECT_TRUE(log.changesSince(map::ChangeCursor{}).all);  // a reader that never synced
  const map::ChangeCursor start = log.cursor();
  const map::BrickChanges none = log.changesSince(start);
  EXPECT_FALSE(none.all);
  EXPECT_TRUE(none.bricks.empty());
  log.markVoxel({9, 0, 0});   // brick 1
  log.markVoxel({15, 7, 0});  // brick 1 again
  log.markVoxel({0, 8, 17});  // brick 0 + 2 * (1 + 2 * 2) = 10
  log.commitVoxels();
  const map::ChangeCursor after_first = log.cursor();
  EXPECT_EQ(log.changesSince(start).bricks, (std::vector<int>{1, 10}));
  log.markBricks({4});
  EXPECT_EQ(log.changesSince(start).bricks, (std::vector<int>{1, 4, 10}));
  EXPECT_EQ(log.changesSince(after_first).bricks, (std::vector<int>{4}));
  EXPECT_TRUE(log.changesSince(log.cursor()).bricks.empty());
  // A new epoch (the fine map moved): every earlier cursor must rebuild.
  map::BrickChangeLog moved(g);
  EXPECT_TRUE(moved.changesSince(after_first).all);
  log.reset(g);
  EXPECT_TRUE(log.changesSince(after_first).all);
}

}  // namespace
}  // namespace fvp::host::planner
