// The octomap map engine (OcTree coarse + RoiOcTree fine) on hand-made scans, its files
// (.bt / .ot round trips, read by OctoMap's library and tools) and the RoiOcTree type.
#include <gtest/gtest.h>
#include <octomap/AbstractOcTree.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "fvp/accel/backend.h"
#include "fvp/host/map/octomap_io.h"
#include "fvp/host/map/octomap_map_engine.h"
#include "fvp/host/map/roi_octree.h"
#include "synthetic_scan.h"

namespace fvp::host::map {
namespace {

namespace fs = std::filesystem;
using Vec3f = Eigen::Vector3f;

MapConfig smallConfig() {
  MapConfig c;
  c.observation_min_m = {-0.25, -0.25, 0.0};
  c.observation_max_m = {0.25, 0.25, 0.5};
  return c;
}

const ClusterRegion kRegion({0.0, 0.0, 0.2}, 0.03);

// Centre of coarse lattice voxel k (world index) along each axis.
Eigen::Vector3d coarseCenter(int x, int y, int z) {
  return {(x + 0.5) * 0.01, (y + 0.5) * 0.01, (z + 0.5) * 0.01};
}
Eigen::Vector3d fineCenter(int x, int y, int z) {
  return {(x + 0.5) * 0.001, (y + 0.5) * 0.001, (z + 0.5) * 0.001};
}

float coarseLogOdds(const OctomapMapEngine& e, const Eigen::Vector3d& p) {
  const octomap::OcTreeNode* n = e.coarseTree().search(p.x(), p.y(), p.z());
  return n == nullptr ? std::numeric_limits<float>::quiet_NaN() : n->getLogOdds();
}
const RoiOcTreeNode* fineNode(const OctomapMapEngine& e, const Eigen::Vector3d& p) {
  return e.fineTree().search(p.x(), p.y(), p.z());
}

bool inRegion(const OctomapMapEngine& e, const Eigen::Vector3d& p) {
  std::array<int, 3> i;
  if (!e.fineGrid().gridIndex(p, i)) return false;
  const fvp_region r = regionInGrid(e.fineGrid(), e.region());
  return fvp_region_contains(&r, i[0], i[1], i[2]) != 0;
}

class TempDir {
 public:
  TempDir() {
    path_ = fs::temp_directory_path() /
            ("fvp_map_test_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// ---- scan semantics ------------------------------------------------------------------

TEST(OctomapEngine, KeysAreLatticeIndicesPlusTreeMaxVal) {
  OctomapMapEngine e(smallConfig(), kRegion);
  EXPECT_EQ(e.coarseTree().coordToKey(0.0), 32768);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.25, 0.25);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng) + 0.25);
    const octomap::OcTreeKey key = e.coarseTree().coordToKey(octomap::point3d(p.x(), p.y(), p.z()));
    const auto lattice = e.coarseGrid().latticeIndex(p);
    std::array<int, 3> index;
    ASSERT_TRUE(e.coarseGrid().gridIndex(p, index));
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(int{key[a]} - 32768, lattice[a]);
      EXPECT_EQ(e.coarseKey(index)[a], key[a]);
    }
  }
}

TEST(OctomapEngine, SingleRayMarksFreeVoxelsThenTheHit) {
  OctomapMapEngine e(smallConfig(), kRegion);
  const Eigen::Vector3d origin(0.0051, 0.0052, 0.0053);
  const ScanStats stats =
      e.integrate(testing::makeClouds(origin, {Vec3f(0.0051f, 0.0052f, 0.2103f)}, {}));
  EXPECT_EQ(stats.points, 1u);
  EXPECT_EQ(stats.skipped_invalid, 0u);
  EXPECT_EQ(stats.truncated, 0u);
  EXPECT_EQ(stats.coarse_voxels_updated, 22u);  // z 0..20 free, 21 hit
  const OccupancyModel& m = e.config().model;

  for (int z = 0; z <= 20; ++z) {
    EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, z)), VoxelClass::kFree) << z;
    EXPECT_EQ(coarseLogOdds(e, coarseCenter(0, 0, z)), m.missLogOdds()) << z;
  }
  EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, 21)), VoxelClass::kOccupied);
  EXPECT_EQ(coarseLogOdds(e, coarseCenter(0, 0, 21)), m.hitLogOdds());
  EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, 22)), VoxelClass::kUnknown);
  EXPECT_EQ(e.coarseClass(coarseCenter(1, 0, 10)), VoxelClass::kUnknown);

  // Fine map: the column x = 5, y = 5 inside the region is free up to the ROI hit at 210.
  std::size_t fine_free = 0;
  for (int z = 150; z < 260; ++z) {
    const Eigen::Vector3d p = fineCenter(5, 5, z);
    const VoxelState s = e.fineState(p);
    if (!inRegion(e, p) || z > 210) {
      EXPECT_EQ(s, VoxelState{}) << z;
    } else if (z < 210) {
      EXPECT_EQ(s, (VoxelState{VoxelClass::kFree, false})) << z;
      EXPECT_EQ(fineNode(e, p)->getRoiLogOdds(), 0.0f);
      ++fine_free;
    } else {
      EXPECT_EQ(s, (VoxelState{VoxelClass::kOccupied, true}));
      EXPECT_EQ(fineNode(e, p)->getLogOdds(), m.hitLogOdds());
      EXPECT_EQ(fineNode(e, p)->getRoiLogOdds(), m.hitLogOdds());
    }
  }
  EXPECT_GT(fine_free, 30u);
  EXPECT_EQ(stats.fine_voxels_updated, fine_free + 1);
  EXPECT_EQ(e.fineState(fineCenter(6, 5, 200)), VoxelState{});
}

TEST(OctomapEngine, TwoPointsInOneVoxelUpdateItOnce) {
  OctomapMapEngine e(smallConfig(), kRegion);
  const Eigen::Vector3d origin(0.0051, 0.0052, 0.0053);
  const ScanStats stats = e.integrate(testing::makeClouds(
      origin, {Vec3f(0.0051f, 0.0052f, 0.2103f), Vec3f(0.0053f, 0.0054f, 0.2106f)}, {}));
  EXPECT_EQ(stats.coarse_voxels_updated, 22u);
  const OccupancyModel& m = e.config().model;
  EXPECT_EQ(coarseLogOdds(e, coarseCenter(0, 0, 21)), m.hitLogOdds());
  EXPECT_EQ(coarseLogOdds(e, coarseCenter(0, 0, 10)), m.missLogOdds());
  const RoiOcTreeNode* end = fineNode(e, fineCenter(5, 5, 210));
  ASSERT_NE(end, nullptr);
  EXPECT_EQ(end->getLogOdds(), m.hitLogOdds());
  EXPECT_EQ(end->getRoiLogOdds(), m.hitLogOdds());
  EXPECT_EQ(fineNode(e, fineCenter(5, 5, 200))->getLogOdds(), m.missLogOdds());
}

TEST(OctomapEngine, HitWinsOverFreeWithinOneScan) {
  OctomapMapEngine e(smallConfig(), kRegion);
  const Eigen::Vector3d origin(0.0051, 0.0052, 0.0053);
  // The second ray passes through the first one's end voxel and ends farther on.
  e.integrate(testing::makeClouds(origin, {Vec3f(0.0051f, 0.0052f, 0.1003f)},
                                  {Vec3f(0.0051f, 0.0052f, 0.2003f)}));
  EXPECT_EQ(coarseLogOdds(e, coarseCenter(0, 0, 10)), e.config().model.hitLogOdds());
  EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, 10)), VoxelClass::kOccupied);
  EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, 15)), VoxelClass::kFree);
  EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, 20)), VoxelClass::kOccupied);
}

TEST(OctomapEngine, RoiEndPointMakesTheVoxelAnRoiHit) {
  OctomapMapEngine e(smallConfig(), kRegion);
  const Eigen::Vector3d origin(0.0051, 0.0052, 0.0053);
  const OccupancyModel& m = e.config().model;
  // Voxel (5,5,210): one ROI and one other end point. Voxel (8,5,205): other points only.
  e.integrate(
      testing::makeClouds(origin, {Vec3f(0.0051f, 0.0052f, 0.2103f)},
                          {Vec3f(0.0055f, 0.0056f, 0.2107f), Vec3f(0.0085f, 0.0052f, 0.2053f),
                           Vec3f(0.0082f, 0.0058f, 0.2051f)}));
  const RoiOcTreeNode* mixed = fineNode(e, fineCenter(5, 5, 210));
  ASSERT_NE(mixed, nullptr);
  EXPECT_EQ(mixed->getRoiLogOdds(), m.hitLogOdds());
  EXPECT_EQ(e.fineState(fineCenter(5, 5, 210)), (VoxelState{VoxelClass::kOccupied, true}));
  const RoiOcTreeNode* other = fineNode(e, fineCenter(8, 5, 205));
  ASSERT_NE(other, nullptr);
  EXPECT_EQ(other->getLogOdds(), m.hitLogOdds());
  EXPECT_EQ(other->getRoiLogOdds(), m.missLogOdds());
  EXPECT_EQ(e.fineState(fineCenter(8, 5, 205)), (VoxelState{VoxelClass::kOccupied, false}));
}

TEST(OctomapEngine, MaxRangeCutsTheRayWithoutAHit) {
  MapConfig c = smallConfig();
  c.sensor_max_range_m = 0.1;
  OctomapMapEngine e(c, kRegion);
  const Eigen::Vector3d origin(0.0051, 0.0052, 0.0053);
  const ScanStats stats =
      e.integrate(testing::makeClouds(origin, {Vec3f(0.0051f, 0.0052f, 0.3053f)}, {}));
  EXPECT_EQ(stats.truncated, 1u);
  EXPECT_EQ(stats.points, 1u);
  // The cut lies at z = 0.1053 (voxel 10): free before it, the cut voxel itself untouched
  // (computeRayKeys excludes the end voxel), nothing beyond, no hit anywhere.
  for (int z = 0; z <= 9; ++z) EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, z)), VoxelClass::kFree);
  EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, 10)), VoxelClass::kUnknown);
  EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, 30)), VoxelClass::kUnknown);
  EXPECT_EQ(stats.coarse_voxels_updated, 10u);
  EXPECT_EQ(stats.fine_voxels_updated, 0u);  // the region starts at z = 0.17

  // A point just within max range is a measurement (OctoMap: norm <= maxrange).
  OctomapMapEngine e2(c, kRegion);
  const ScanStats s2 = e2.integrate(testing::makeClouds(Eigen::Vector3d(0.0051, 0.0052, 0.0),
                                                        {Vec3f(0.0051f, 0.0052f, 0.0995f)}, {}));
  EXPECT_EQ(s2.truncated, 0u);
  EXPECT_EQ(e2.coarseClass(coarseCenter(0, 0, 9)), VoxelClass::kOccupied);
}

TEST(OctomapEngine, NonFinitePointsAreSkippedAndCounted) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const Eigen::Vector3d origin(0.0051, 0.0052, 0.0053);
  const Vec3f good(0.0051f, 0.0052f, 0.2103f);
  OctomapMapEngine e(smallConfig(), kRegion);
  const ScanStats stats = e.integrate(testing::makeClouds(
      origin, {Vec3f(nan, 0.0f, 0.2f), good}, {Vec3f(0.0f, inf, 0.2f), Vec3f(0.0f, 0.0f, -inf)}));
  EXPECT_EQ(stats.points, 4u);
  EXPECT_EQ(stats.skipped_invalid, 3u);
  OctomapMapEngine reference(smallConfig(), kRegion);
  const ScanStats ref_stats = reference.integrate(testing::makeClouds(origin, {good}, {}));
  EXPECT_EQ(stats.coarse_voxels_updated, ref_stats.coarse_voxels_updated);
  EXPECT_EQ(stats.fine_voxels_updated, ref_stats.fine_voxels_updated);
  EXPECT_EQ(e.coarseTree().getNumLeafNodes(), reference.coarseTree().getNumLeafNodes());
  EXPECT_EQ(e.fineTree().getNumLeafNodes(), reference.fineTree().getNumLeafNodes());
  EXPECT_THROW(e.integrate(testing::makeClouds(Eigen::Vector3d(nan, 0, 0), {good}, {})),
               std::invalid_argument);
}

TEST(OctomapEngine, LogOddsClampAfterManyScans) {
  OctomapMapEngine e(smallConfig(), kRegion);
  const Eigen::Vector3d origin(0.0051, 0.0052, 0.0053);
  const OccupancyModel& m = e.config().model;
  for (int i = 0; i < 30; ++i) {
    e.integrate(testing::makeClouds(origin, {Vec3f(0.0051f, 0.0052f, 0.2103f)},
                                    {Vec3f(0.0085f, 0.0052f, 0.2053f)}));
  }
  EXPECT_EQ(coarseLogOdds(e, coarseCenter(0, 0, 21)), m.clampMaxLogOdds());
  EXPECT_EQ(coarseLogOdds(e, coarseCenter(0, 0, 5)), m.clampMinLogOdds());
  const RoiOcTreeNode* roi = fineNode(e, fineCenter(5, 5, 210));
  EXPECT_EQ(roi->getLogOdds(), m.clampMaxLogOdds());
  EXPECT_EQ(roi->getRoiLogOdds(), m.clampMaxLogOdds());
  const RoiOcTreeNode* other = fineNode(e, fineCenter(8, 5, 205));
  EXPECT_EQ(other->getLogOdds(), m.clampMaxLogOdds());
  EXPECT_EQ(other->getRoiLogOdds(), m.clampMinLogOdds());
  EXPECT_EQ(fineNode(e, fineCenter(5, 5, 190))->getLogOdds(), m.clampMinLogOdds());
  EXPECT_EQ(e.fineState(fineCenter(5, 5, 190)), (VoxelState{VoxelClass::kFree, false}));
}

TEST(OctomapEngine, FineMapOnlyInsideTheClusterRegion) {
  OctomapMapEngine e(smallConfig(), kRegion);
  // Inside the fine grid's cube but outside the sphere (distance 0.035 > 0.03 from the axis).
  const ScanStats stats = e.integrate(testing::makeClouds(Eigen::Vector3d(0.0251, 0.0252, 0.0053),
                                                          {Vec3f(0.0251f, 0.0252f, 0.2003f)}, {}));
  EXPECT_EQ(stats.fine_voxels_updated, 0u);
  EXPECT_EQ(e.fineTree().getRoot(), nullptr);
  EXPECT_EQ(e.fineState(Eigen::Vector3d(0.0251, 0.0252, 0.2003)), VoxelState{});
  EXPECT_EQ(e.coarseClass(Eigen::Vector3d(0.0251, 0.0252, 0.2003)), VoxelClass::kOccupied);

  // A ray crossing the sphere: every fine voxel it made known lies inside the region.
  e.integrate(
      testing::makeClouds(Eigen::Vector3d(0.2, 0.1, 0.05), {Vec3f(-0.01f, 0.005f, 0.21f)}, {}));
  std::size_t leaves = 0;
  for (auto it = e.fineTree().begin_leafs(), end = e.fineTree().end_leafs(); it != end; ++it) {
    ASSERT_EQ(it.getDepth(), e.fineTree().getTreeDepth());
    const auto c = it.getCoordinate();
    EXPECT_TRUE(inRegion(e, Eigen::Vector3d(c.x(), c.y(), c.z())));
    ++leaves;
  }
  EXPECT_GT(leaves, 40u);
  EXPECT_EQ(e.fineState(Eigen::Vector3d(0.5, 0.5, 0.5)), VoxelState{});
}

TEST(OctomapEngine, CoarseMapOnlyInsideTheObservationBox) {
  OctomapMapEngine e(smallConfig(), kRegion);
  // From below the box to above it: free inside the box only, the end outside is no hit.
  const ScanStats stats = e.integrate(testing::makeClouds(Eigen::Vector3d(0.0051, 0.0052, -0.2053),
                                                          {}, {Vec3f(0.0051f, 0.0052f, 0.7053f)}));
  const GridGeometry& g = e.coarseGrid();
  for (auto it = e.coarseTree().begin_leafs(), end = e.coarseTree().end_leafs(); it != end; ++it) {
    const auto c = it.getCoordinate();
    std::array<int, 3> index;
    EXPECT_TRUE(g.gridIndex(Eigen::Vector3d(c.x(), c.y(), c.z()), index));
    EXPECT_FALSE(e.coarseTree().isNodeOccupied(*it));
  }
  EXPECT_EQ(stats.coarse_voxels_updated, static_cast<std::size_t>(g.dims[2]));
  EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, -3)), VoxelClass::kUnknown);
  EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, 0)), VoxelClass::kFree);
  EXPECT_EQ(e.coarseClass(coarseCenter(0, 0, g.dims[2] - 1 + static_cast<int>(g.first_voxel[2]))),
            VoxelClass::kFree);
}

TEST(OctomapEngine, RejectsGridsOutsideTheKeyRange) {
  MapConfig c = smallConfig();
  c.observation_min_m = {400.0, 0.0, 0.0};
  c.observation_max_m = {400.5, 0.5, 0.5};
  EXPECT_THROW(OctomapMapEngine(c, kRegion), std::invalid_argument);
}

// ---- RoiOcTree -----------------------------------------------------------------------

TEST(RoiOcTree, PruningKeepsTheRoiOfEachVoxel) {
  RoiOcTree tree(0.001);
  const octomap::OcTreeKey base = tree.coordToKey(0.0101, 0.0201, 0.0301);
  std::vector<octomap::OcTreeKey> siblings;
  for (int i = 0; i < 8; ++i) {
    octomap::OcTreeKey k(static_cast<octomap::key_type>((base[0] & ~1) | (i & 1)),
                         static_cast<octomap::key_type>((base[1] & ~1) | ((i >> 1) & 1)),
                         static_cast<octomap::key_type>((base[2] & ~1) | ((i >> 2) & 1)));
    siblings.push_back(k);
  }
  for (const auto& k : siblings) tree.updateNodeAndRoi(k, true, RoiOcTree::RoiUpdate::kHit);
  EXPECT_EQ(tree.getNumLeafNodes(), 1u);  // the eight equal leaves were pruned into one
  // A different ROI update of one voxel must expand the parent and change only that voxel.
  tree.updateNodeAndRoi(siblings[3], true, RoiOcTree::RoiUpdate::kMiss);
  const float hit = tree.getProbHitLog(), miss = tree.getProbMissLog();
  for (int i = 0; i < 8; ++i) {
    const RoiOcTreeNode* n = tree.search(siblings[i]);
    ASSERT_NE(n, nullptr);
    EXPECT_EQ(n->getLogOdds(), i == 3 ? hit + hit : hit) << i;
    EXPECT_EQ(n->getRoiLogOdds(), i == 3 ? hit + miss : hit) << i;
  }
  EXPECT_EQ(tree.getNumLeafNodes(), 8u);
}

// The octomap engine applies a scan's updates lazily, in its own order, then restores inner
// nodes and pruning once (updateInnerOccupancy + prune): the tree must be the one eager
// per-key updates give. Scans over a 16^3 block with every kind of update; whole-block free
// scans clamp it so it prunes, and later scans must expand it again.
TEST(RoiOcTree, LazyScanThenInnerAndPruneEqualsEagerUpdates) {
  RoiOcTree eager(0.001), lazy(0.001);
  const octomap::OcTreeKey base = eager.coordToKey(0.0, 0.0, 0.0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::size_t fewest_leaves = std::numeric_limits<std::size_t>::max();
  for (int scan = 0; scan < 24; ++scan) {
    const bool whole_block_free = scan < 6 || scan % 6 == 0;  // clamps after 5 misses
    std::vector<std::pair<octomap::OcTreeKey, int>> updates;  // 0 free, 1 hit, 2 ROI hit
    for (int i = 0; i < 16 * 16 * 16; ++i) {
      if (!whole_block_free && u(rng) < 0.4) continue;
      const octomap::OcTreeKey key(static_cast<octomap::key_type>(base[0] + i % 16),
                                   static_cast<octomap::key_type>(base[1] + i / 16 % 16),
                                   static_cast<octomap::key_type>(base[2] + i / 256));
      const double r = u(rng);
      updates.emplace_back(key, whole_block_free || r < 0.7 ? 0 : r < 0.85 ? 1 : 2);
    }
    const auto apply = [](RoiOcTree& tree, const std::pair<octomap::OcTreeKey, int>& up,
                          bool lazy_eval) {
      tree.updateNodeAndRoi(up.first, up.second != 0,
                            up.second == 2   ? RoiOcTree::RoiUpdate::kHit
                            : up.second == 1 ? RoiOcTree::RoiUpdate::kMiss
                                             : RoiOcTree::RoiUpdate::kNone,
                            lazy_eval);
    };
    for (const auto& up : updates) apply(eager, up, false);
    std::shuffle(updates.begin(), updates.end(), rng);
    for (const auto& up : updates) apply(lazy, up, true);
    lazy.updateInnerOccupancy();
    lazy.prune();

    ASSERT_EQ(lazy.getNumLeafNodes(), eager.getNumLeafNodes()) << "scan " << scan;
    ASSERT_EQ(lazy.size(), eager.size()) << "scan " << scan;
    auto e = eager.begin_tree(), l = lazy.begin_tree();
    for (; e != eager.end_tree() && l != lazy.end_tree(); ++e, ++l) {
      ASSERT_EQ(e.getKey(), l.getKey()) << "scan " << scan;
      ASSERT_EQ(e.getDepth(), l.getDepth()) << "scan " << scan;
      ASSERT_EQ(e->getLogOdds(), l->getLogOdds()) << "scan " << scan;
      ASSERT_EQ(e->getRoiLogOdds(), l->getRoiLogOdds()) << "scan " << scan;
    }
    EXPECT_TRUE(e == eager.end_tree() && l == lazy.end_tree()) << "scan " << scan;
    fewest_leaves = std::min(fewest_leaves, eager.getNumLeafNodes());
  }
  // The block clamped free and pruned (the case the test is for), then split again.
  EXPECT_EQ(fewest_leaves, 1u);
  EXPECT_GT(eager.getNumLeafNodes(), 64u);
}

TEST(RoiOcTree, NativeOtRoundTripThroughOctomapsTypeRegistry) {
  RoiOcTree tree(0.001);
  tree.updateNodeAndRoi(tree.coordToKey(0.01, 0.02, 0.03), true, RoiOcTree::RoiUpdate::kHit);
  tree.updateNodeAndRoi(tree.coordToKey(0.011, 0.02, 0.03), true, RoiOcTree::RoiUpdate::kMiss);
  tree.updateNodeAndRoi(tree.coordToKey(0.012, 0.02, 0.03), false, RoiOcTree::RoiUpdate::kNone);
  std::stringstream s;
  ASSERT_TRUE(tree.write(s));
  std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(s));
  ASSERT_NE(read, nullptr);
  EXPECT_EQ(read->getTreeType(), "RoiOcTree");
  auto* roi = dynamic_cast<RoiOcTree*>(read.get());
  ASSERT_NE(roi, nullptr);
  EXPECT_EQ(roi->getNumLeafNodes(), tree.getNumLeafNodes());
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const RoiOcTreeNode* n = roi->search(it.getKey());
    ASSERT_NE(n, nullptr);
    EXPECT_EQ(n->getLogOdds(), it->getLogOdds());
    EXPECT_EQ(n->getRoiLogOdds(), it->getRoiLogOdds());
  }
}

TEST(RoiColor, EncodingKeepsTheRoiClassAndTheValueWithinHalfAStep) {
  for (float v = -8.0f; v <= 7.99f; v += 0.00731f) {
    const float back = decodeRoiColor(encodeRoiColor(v));
    EXPECT_NEAR(back, v, 0.5f / kRoiColorScale + 1e-6f) << v;
    EXPECT_EQ(back > 0.0f, v > 0.0f) << v;
    EXPECT_EQ(encodeRoiColor(v).r, v > 0.0f ? kRoiRed : kNonRoiRed);
  }
  for (float v : {1e-7f, -1e-7f, 0.0f, 1e-30f}) {
    EXPECT_EQ(decodeRoiColor(encodeRoiColor(v)) > 0.0f, v > 0.0f) << v;
  }
}

// ---- files ---------------------------------------------------------------------------

// An engine after a few synthetic views of fruitlets in the region.
std::unique_ptr<OctomapMapEngine> mappedEngine(int views = 3,
                                               FineMapExtent extent = FineMapExtent::kClusterRegion,
                                               int width_px = 160, int height_px = 120) {
  MapConfig c = smallConfig();
  c.fine_map_extent = extent;
  const ClusterRegion region({0.0, 0.0, 0.3}, 0.04);
  auto e = std::make_unique<OctomapMapEngine>(c, region);
  const testing::SyntheticWorld world = testing::makeWorld(11, region.center_m());
  const Eigen::Vector3d origins[] = {
      {0.2, 0.05, 0.1}, {-0.15, 0.2, 0.15}, {0.0, -0.2, 0.05}, {0.1, 0.1, 0.45}};
  for (int v = 0; v < views; ++v) {
    const auto scan = testing::renderScan(world, origins[v % 4], width_px, height_px, 0.5, 100 + v);
    e->integrate(scan.clouds());
  }
  return e;
}

void expectCoarseMatches(const OctomapMapEngine& e, const octomap::OcTree& read) {
  const GridGeometry& g = e.coarseGrid();
  std::size_t known = 0;
  for (int z = 0; z < g.dims[2]; ++z) {
    for (int y = 0; y < g.dims[1]; ++y) {
      for (int x = 0; x < g.dims[0]; ++x) {
        const octomap::OcTreeNode* n = read.search(e.coarseKey({x, y, z}));
        const VoxelClass from_file = n == nullptr             ? VoxelClass::kUnknown
                                     : read.isNodeOccupied(n) ? VoxelClass::kOccupied
                                                              : VoxelClass::kFree;
        ASSERT_EQ(from_file, e.coarseClassAt({x, y, z})) << x << " " << y << " " << z;
        known += from_file != VoxelClass::kUnknown;
      }
    }
  }
  EXPECT_GT(known, 1000u);
}

void expectFineMatches(const OctomapMapEngine& e, const RoiOcTree& read) {
  const GridGeometry& g = e.fineGrid();
  std::size_t known = 0, roi = 0;
  for (int z = 0; z < g.dims[2]; ++z) {
    for (int y = 0; y < g.dims[1]; ++y) {
      for (int x = 0; x < g.dims[0]; ++x) {
        const RoiOcTreeNode* mine = e.fineTree().search(e.fineKey({x, y, z}));
        const RoiOcTreeNode* theirs = read.search(e.fineKey({x, y, z}));
        ASSERT_EQ(mine == nullptr, theirs == nullptr);
        if (mine == nullptr) continue;
        ASSERT_EQ(mine->getLogOdds(), theirs->getLogOdds());  // exact
        ASSERT_EQ(mine->isRoi(), theirs->isRoi());
        ASSERT_NEAR(mine->getRoiLogOdds(), theirs->getRoiLogOdds(), 0.5f / kRoiColorScale);
        ++known;
        roi += mine->isRoi();
      }
    }
  }
  EXPECT_GT(known, 10000u);
  EXPECT_GT(roi, 100u);
}

TEST(OctomapEngineFiles, ExportedMapsRoundTrip) {
  const auto e = mappedEngine();
  TempDir dir;
  e->exportCoarse(dir.path() / "coarse.bt");
  e->exportFine(dir.path() / "fine.ot");
  expectCoarseMatches(*e, *readCoarseBt(dir.path() / "coarse.bt"));
  expectFineMatches(*e, *readFineOt(dir.path() / "fine.ot"));
  // Only the two files: no temporary left behind; rewriting replaces them.
  e->exportFine(dir.path() / "fine.ot");
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 2u);
}

TEST(OctomapEngineFiles, OctomapLibraryReadsTheFiles) {
  const auto e = mappedEngine(2);
  TempDir dir;
  e->exportCoarse(dir.path() / "coarse.bt");
  e->exportFine(dir.path() / "fine.ot");
  octomap::OcTree bt(0.5);
  ASSERT_TRUE(bt.readBinary((dir.path() / "coarse.bt").string()));
  EXPECT_DOUBLE_EQ(bt.getResolution(), 0.01);
  EXPECT_GT(bt.getNumLeafNodes(), 0u);
  std::unique_ptr<octomap::AbstractOcTree> ot(
      octomap::AbstractOcTree::read((dir.path() / "fine.ot").string()));
  ASSERT_NE(ot, nullptr);
  EXPECT_EQ(ot->getTreeType(), "ColorOcTree");
  auto* color = dynamic_cast<octomap::ColorOcTree*>(ot.get());
  ASSERT_NE(color, nullptr);
  EXPECT_DOUBLE_EQ(color->getResolution(), 0.001);
  std::size_t red = 0;
  for (auto it = color->begin_leafs(), end = color->end_leafs(); it != end; ++it) {
    const RoiOcTreeNode* n = e->fineTree().search(it.getKey(), it.getDepth());
    ASSERT_NE(n, nullptr);
    EXPECT_EQ(it->getLogOdds(), n->getLogOdds());
    EXPECT_EQ(it->getColor().r == kRoiRed, n->isRoi());
    red += it->getColor().r == kRoiRed;
  }
  EXPECT_GT(red, 0u);
}

int runTool(const std::string& command, const fs::path& log) {
  const int rc = std::system((command + " > '" + log.string() + "' 2>&1").c_str());
  return rc == -1 ? -1 : WEXITSTATUS(rc);
}

TEST(OctomapEngineFiles, OctomapToolsReadTheFiles) {
  const std::string convert = FVP_CONVERT_OCTREE, compare = FVP_COMPARE_OCTREES;
  if (convert.find("NOTFOUND") != std::string::npos ||
      compare.find("NOTFOUND") != std::string::npos) {
    GTEST_SKIP() << "octomap-tools (convert_octree, compare_octrees) not installed";
  }
  const auto e = mappedEngine(2);
  TempDir dir;
  const fs::path bt = dir.path() / "coarse.bt", ot = dir.path() / "fine.ot";
  e->exportCoarse(bt);
  e->exportFine(ot);
  const fs::path log = dir.path() / "tool.log";
  auto slurp = [&] {
    std::ifstream in(log);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };

  // convert_octree reads the ColorOcTree .ot through OctoMap's registry and writes it back.
  const fs::path ot_copy = dir.path() / "fine_copy.ot";
  ASSERT_EQ(runTool(convert + " '" + ot.string() + "' '" + ot_copy.string() + "'", log), 0)
      << slurp();
  expectFineMatches(*e, *readFineOt(ot_copy));

  // convert_octree reads the .bt; compare_octrees reads the resulting OcTree .ot files.
  const fs::path bt_as_ot = dir.path() / "coarse.ot";
  ASSERT_EQ(runTool(convert + " '" + bt.string() + "' '" + bt_as_ot.string() + "'", log), 0)
      << slurp();
  ASSERT_EQ(runTool(compare + " '" + bt_as_ot.string() + "' '" + bt_as_ot.string() + "'", log), 0)
      << slurp();
  EXPECT_NE(slurp().find("KLD: 0"), std::string::npos) << slurp();
}

TEST(OctomapEngineFiles, FailuresNameTheFile) {
  const auto e = mappedEngine(1);
  try {
    e->exportCoarse("/nonexistent-dir/coarse.bt");
    FAIL() << "no exception";
  } catch (const std::runtime_error& err) {
    EXPECT_NE(std::string(err.what()).find("/nonexistent-dir/coarse.bt"), std::string::npos);
  }
  EXPECT_THROW(readCoarseBt("/nonexistent-dir/coarse.bt"), std::runtime_error);
  EXPECT_THROW(readFineOt("/nonexistent-dir/fine.ot"), std::runtime_error);
  TempDir dir;
  e->exportCoarse(dir.path() / "coarse.bt");
  EXPECT_THROW(readFineOt(dir.path() / "coarse.bt"), std::runtime_error);  // a .bt is no .ot
}

// ---- planner reads: ROI distance field, frontiers (brute force by their definitions) ---

// The fine map's voxel states over the grid box, read voxel by voxel (x fastest).
std::vector<VoxelState> denseFineStates(const OctomapMapEngine& e) {
  const GridGeometry& g = e.fineGrid();
  std::vector<VoxelState> states(static_cast<std::size_t>(g.voxelCount()));
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = 0; x < g.dims[0]; ++x)
        states[x + g.dims[0] * (y + static_cast<std::size_t>(g.dims[1]) * z)] =
            e.fineStateAt({x, y, z});
  return states;
}

// map_engine.h's d_i: distance between voxel centres to the nearest known ROI voxel, in
// metres, capped at max_d_m; every ROI voxel within the cap's cube is visited.
std::vector<double> bruteForceRoiDistance_m(const OctomapMapEngine& e, double max_d_m) {
  const GridGeometry& g = e.fineGrid();
  const auto states = denseFineStates(e);
  const int window = static_cast<int>(std::ceil(max_d_m / g.voxel_size_m));
  std::vector<double> d(states.size(), max_d_m);
  for (int rz = 0; rz < g.dims[2]; ++rz)
    for (int ry = 0; ry < g.dims[1]; ++ry)
      for (int rx = 0; rx < g.dims[0]; ++rx) {
        if (!states[rx + g.dims[0] * (ry + static_cast<std::size_t>(g.dims[1]) * rz)].roi) continue;
        for (int z = std::max(0, rz - window); z <= std::min(g.dims[2] - 1, rz + window); ++z)
          for (int y = std::max(0, ry - window); y <= std::min(g.dims[1] - 1, ry + window); ++y)
            for (int x = std::max(0, rx - window); x <= std::min(g.dims[0] - 1, rx + window); ++x) {
              const double dist_m =
                  g.voxel_size_m * std::sqrt(double((x - rx) * (x - rx) + (y - ry) * (y - ry) +
                                                    (z - rz) * (z - rz)));
              double& out = d[x + g.dims[0] * (y + static_cast<std::size_t>(g.dims[1]) * z)];
              out = std::min(out, dist_m);
            }
      }
  return d;
}

// frontier_voxel.h's definition, voxel by voxel over the grid box.
std::vector<FrontierVoxel> bruteForceFrontiers(const OctomapMapEngine& e) {
  const GridGeometry& g = e.fineGrid();
  const auto states = denseFineStates(e);
  const fvp_region region = regionInGrid(g, e.region());
  auto inRegion = [&](int x, int y, int z) {
    return x >= 0 && y >= 0 && z >= 0 && x < g.dims[0] && y < g.dims[1] && z < g.dims[2] &&
           fvp_region_contains(&region, x, y, z);
  };
  auto state = [&](int x, int y, int z) {
    return states[x + g.dims[0] * (y + static_cast<std::size_t>(g.dims[1]) * z)];
  };
  std::vector<FrontierVoxel> out;
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = 0; x < g.dims[0]; ++x) {
        const VoxelState s = state(x, y, z);
        if (s.occupancy == VoxelClass::kUnknown) continue;
        const bool is_free = s.occupancy == VoxelClass::kFree;
        if (!s.roi && !is_free) continue;
        bool face_unknown = false;
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              if (dx == 0 && dy == 0 && dz == 0) continue;
              if (!inRegion(x + dx, y + dy, z + dz)) continue;
              if (state(x + dx, y + dy, z + dz).occupancy != VoxelClass::kUnknown) continue;
              face_unknown |= std::abs(dx) + std::abs(dy) + std::abs(dz) == 1;
              sum -= Eigen::Vector3d(dx, dy, dz);
            }
        if (!face_unknown) continue;
        FrontierVoxel f;
        f.index = {x, y, z};
        f.center_m = g.voxelCenter_m(f.index);
        f.roi_frontier = s.roi;
        f.exploration_frontier = is_free;
        if (sum.squaredNorm() > 0) f.normal = sum.normalized();
        out.push_back(f);
      }
  return out;  // z, then y, then x: the engines' order
}

void expectSameFrontiers(const std::vector<FrontierVoxel>& got,
                         const std::vector<FrontierVoxel>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    ASSERT_EQ(got[i].index, want[i].index) << i;
    EXPECT_EQ(got[i].center_m, want[i].center_m) << i;
    EXPECT_EQ(got[i].roi_frontier, want[i].roi_frontier) << i;
    EXPECT_EQ(got[i].exploration_frontier, want[i].exploration_frontier) << i;
    EXPECT_LE((got[i].normal - want[i].normal).norm(), 1e-12) << i;
  }
}

std::array<int, 3> fineIndex(const OctomapMapEngine& e, const Eigen::Vector3d& p) {
  std::array<int, 3> i{};
  EXPECT_TRUE(e.fineGrid().gridIndex(p, i));
  return i;
}

TEST(OctomapEnginePlannerReads, RoiDistanceOnAHandMadeMapEqualsBruteForce) {
  OctomapMapEngine e(smallConfig(), kRegion);
  EXPECT_THROW(e.roiDistance_m({0, 0, 0}), std::logic_error);
  EXPECT_THROW(e.updateRoiDistance(0.0), std::invalid_argument);
  const Eigen::Vector3d origin(0.0051, 0.0052, 0.0053);
  // Three ROI voxels (one on the sphere's edge), a known non-ROI voxel, and a voxel whose
  // one ROI hit three later other hits outweigh (ROI log-odds 0.85 - 3 * 0.4 < 0).
  e.integrate(
      testing::makeClouds(origin,
                          {Vec3f(0.0051f, 0.0052f, 0.2103f), Vec3f(-0.0103f, 0.0071f, 0.1952f),
                           Vec3f(0.0152f, -0.0121f, 0.2204f), Vec3f(0.0263f, 0.0025f, 0.2031f),
                           Vec3f(-0.0041f, -0.0182f, 0.1857f)},
                          {Vec3f(0.0085f, 0.0052f, 0.2053f)}));
  for (int i = 0; i < 3; ++i)
    e.integrate(testing::makeClouds(origin, {}, {Vec3f(-0.0041f, -0.0182f, 0.1857f)}));
  std::size_t roi_voxels = 0;
  for (const VoxelState& s : denseFineStates(e)) roi_voxels += s.roi;
  ASSERT_EQ(roi_voxels, 4u);
  ASSERT_FALSE(e.fineState(Eigen::Vector3d(-0.0041, -0.0182, 0.1857)).roi);
  ASSERT_EQ(e.fineState(Eigen::Vector3d(-0.0041, -0.0182, 0.1857)).occupancy,
            VoxelClass::kOccupied);

  const GridGeometry& g = e.fineGrid();
  for (const double cap_m : {0.0125, 0.02}) {  // 12.5 and 20 voxels: a cap between voxels too
    e.updateRoiDistance(cap_m);
    const std::vector<double> want = bruteForceRoiDistance_m(e, cap_m);
    std::size_t below_cap = 0;
    for (int z = 0; z < g.dims[2]; ++z)
      for (int y = 0; y < g.dims[1]; ++y)
        for (int x = 0; x < g.dims[0]; ++x) {
          const double w = want[x + g.dims[0] * (y + static_cast<std::size_t>(g.dims[1]) * z)];
          // float square root (the grid kernel's conversion): within 1e-8 m at 1 mm voxels.
          ASSERT_NEAR(e.roiDistance_m({x, y, z}), w, 1e-8) << x << " " << y << " " << z;
          below_cap += w < cap_m;
        }
    EXPECT_GT(below_cap, 4u * 1000u);
    EXPECT_EQ(e.roiDistance_m({-1, 0, 0}), cap_m);  // outside the fine grid: the cap
    EXPECT_EQ(e.roiDistance_m({0, g.dims[1], 0}), cap_m);
    EXPECT_EQ(e.roiDistance_m(fineIndex(e, Eigen::Vector3d(0.0051, 0.0052, 0.2103))), 0.0);
  }

  // A new scan with a new ROI voxel: the next update recomputes.
  const std::array<int, 3> fresh = fineIndex(e, Eigen::Vector3d(0.0005, 0.0005, 0.2005));
  EXPECT_GT(e.roiDistance_m(fresh), 0.0);
  e.integrate(testing::makeClouds(origin, {Vec3f(0.0005f, 0.0005f, 0.2005f)}, {}));
  e.updateRoiDistance(0.02);
  EXPECT_EQ(e.roiDistance_m(fresh), 0.0);
}

TEST(OctomapEnginePlannerReads, RoiDistanceOnFruitletSurfacesWithinDynamicEdtsDeviation) {
  const auto e = mappedEngine();
  const GridGeometry& g = e->fineGrid();
  const double cap_m = 0.02;
  e->updateRoiDistance(cap_m);
  const std::vector<double> want = bruteForceRoiDistance_m(*e, cap_m);
  std::size_t equal = 0, below_cap = 0;
  double max_error_m = 0.0;
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = 0; x < g.dims[0]; ++x) {
        const double w = want[x + g.dims[0] * (y + static_cast<std::size_t>(g.dims[1]) * z)];
        const double err = e->roiDistance_m({x, y, z}) - w;
        // DynamicEDT may miss the nearest ROI voxel, never finds a nearer one than exists.
        ASSERT_GE(err, -1e-8) << x << " " << y << " " << z;
        equal += err <= 1e-8;
        max_error_m = std::max(max_error_m, err);
        below_cap += w < cap_m;
      }
  std::cout << "DynamicEDT vs brute force: " << equal << " of " << want.size()
            << " fine voxels equal, max excess " << max_error_m * 1e3 << " mm\n";
  EXPECT_GT(below_cap, want.size() / 10);
  EXPECT_GE(double(equal), 0.999 * want.size());
  EXPECT_LE(max_error_m, 0.1 * g.voxel_size_m);  // docs/maps.md: DynamicEDT's deviation
}

TEST(OctomapEnginePlannerReads, FrontiersOfOneRayByHand) {
  OctomapMapEngine e(smallConfig(), kRegion);
  EXPECT_TRUE(e.frontiers().empty());
  const Eigen::Vector3d origin(0.0051, 0.0052, 0.0053);
  // Column x = 5, y = 5 (world lattice): an ROI hit at z = 205, then three scans whose rays
  // pass it to end at z = 215: voxel 205 turns free (0.85 - 3 * 0.4) but stays ROI.
  e.integrate(testing::makeClouds(origin, {Vec3f(0.0051f, 0.0052f, 0.2053f)}, {}));
  for (int i = 0; i < 3; ++i)
    e.integrate(testing::makeClouds(origin, {}, {Vec3f(0.0051f, 0.0052f, 0.2153f)}));
  const auto frontiers = e.frontiers();
  expectSameFrontiers(frontiers, bruteForceFrontiers(e));

  std::size_t known = 0;
  for (const VoxelState& s : denseFineStates(e)) known += s.occupancy != VoxelClass::kUnknown;
  // Every known voxel of the column but the occupied non-ROI end (z = 215) is a frontier:
  // its four side neighbours are unknown.
  EXPECT_EQ(frontiers.size(), known - 1);
  const auto at = [&](int z) {
    const std::array<int, 3> i = fineIndex(e, fineCenter(5, 5, z));
    const auto it = std::find_if(frontiers.begin(), frontiers.end(),
                                 [&](const FrontierVoxel& f) { return f.index == i; });
    return it == frontiers.end() ? nullptr : &*it;
  };
  const FrontierVoxel* both = at(205);
  ASSERT_NE(both, nullptr);
  EXPECT_TRUE(both->roi_frontier);
  EXPECT_TRUE(both->exploration_frontier);
  EXPECT_EQ(both->normal, Eigen::Vector3d::Zero());  // unknown all around the column
  const FrontierVoxel* below_end = at(214);
  ASSERT_NE(below_end, nullptr);
  EXPECT_FALSE(below_end->roi_frontier);
  EXPECT_TRUE(below_end->exploration_frontier);
  EXPECT_EQ(below_end->normal, Eigen::Vector3d::Zero());
  EXPECT_EQ(at(215), nullptr);  // occupied, not ROI
  for (int z = 190; z < 214; ++z) {
    const FrontierVoxel* f = at(z);
    ASSERT_NE(f, nullptr) << z;
    EXPECT_EQ(f->exploration_frontier, true) << z;
    EXPECT_EQ(f->roi_frontier, z == 205) << z;
  }

  // The ROI end voxel alone on top of its column: unknown above and around, so the normal
  // points down the known column: -(9 * (+z) + 8 * (-z)) = -z.
  OctomapMapEngine top(smallConfig(), kRegion);
  top.integrate(testing::makeClouds(origin, {Vec3f(0.0051f, 0.0052f, 0.2103f)}, {}));
  const auto tf = top.frontiers();
  expectSameFrontiers(tf, bruteForceFrontiers(top));
  ASSERT_FALSE(tf.empty());
  const FrontierVoxel& end = tf.back();  // the largest z
  EXPECT_EQ(end.index, fineIndex(top, fineCenter(5, 5, 210)));
  EXPECT_TRUE(end.roi_frontier);
  EXPECT_FALSE(end.exploration_frontier);  // occupied
  EXPECT_EQ(end.normal, Eigen::Vector3d(0, 0, -1));
}

TEST(OctomapEnginePlannerReads, FrontiersOfSyntheticViewsEqualBruteForce) {
  const auto e = mappedEngine();
  // Pruned leafs (eight equal voxels merged) must be expanded into their voxels.
  std::size_t pruned = 0;
  for (auto it = e->fineTree().begin_leafs(); it != e->fineTree().end_leafs(); ++it)
    pruned += it.getDepth() < e->fineTree().getTreeDepth();
  EXPECT_GT(pruned, 100u);
  const auto frontiers = e->frontiers();
  std::size_t roi = 0, exploration = 0;
  for (const auto& f : frontiers) {
    roi += f.roi_frontier;
    exploration += f.exploration_frontier;
  }
  EXPECT_GT(roi, 50u);
  EXPECT_GT(exploration, 500u);
  expectSameFrontiers(frontiers, bruteForceFrontiers(*e));
}

// RVP's map in the paper: one 1 mm ROI octree over the whole observation space. The fine
// tree then holds the rays' voxels everywhere in the box, while every read the planners
// make (Cluster Region only) gives what the region-only tree gives.
TEST(OctomapEngine, ObservationBoxExtentUpdatesTheWholeBoxAndReadsTheSameRegion) {
  // A quarter of the usual rays: 1 mm over the whole box is what makes this map slow.
  const auto region_only = mappedEngine(3, FineMapExtent::kClusterRegion, 80, 60);
  const auto whole_box = mappedEngine(3, FineMapExtent::kObservationBox, 80, 60);

  // Every leaf of the whole-box tree lies in the observation box, and far more of them
  // lie outside the region than inside.
  const GridGeometry& coarse = whole_box->coarseGrid();
  std::size_t outside_region = 0, leaves = 0;
  // A leaf in the fine grid's cube but outside the sphere: known to the tree, not to reads.
  Eigen::Vector3d cube_not_sphere = Eigen::Vector3d::Constant(std::nan(""));
  for (auto it = whole_box->fineTree().begin_leafs(); it != whole_box->fineTree().end_leafs();
       ++it) {
    const auto c = it.getCoordinate();
    const Eigen::Vector3d p(c.x(), c.y(), c.z());
    std::array<int, 3> index;
    ASSERT_TRUE(coarse.gridIndex(p, index)) << p.transpose();
    if (!inRegion(*whole_box, p)) {
      ++outside_region;
      if (it.getDepth() == whole_box->fineTree().getTreeDepth() &&
          whole_box->fineGrid().gridIndex(p, index))
        cube_not_sphere = p;
    }
    ++leaves;
  }
  EXPECT_GT(outside_region, leaves / 2);
  EXPECT_GT(whole_box->fineTree().size(), 10 * region_only->fineTree().size());

  // Reads: the same states in the region. The whole-box rays start at the sensor, the
  // region's at the clipped point, so near-tie crossings may differ (the >= 99.9 % of
  // octomap_map_engine.h).
  const GridGeometry& g = whole_box->fineGrid();
  std::size_t known = 0, differ = 0;
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = 0; x < g.dims[0]; ++x) {
        const VoxelState a = region_only->fineStateAt({x, y, z});
        const VoxelState b = whole_box->fineStateAt({x, y, z});
        known += a.occupancy != VoxelClass::kUnknown;
        differ += !(a == b);
      }
  EXPECT_GT(known, 10000u);
  EXPECT_LE(differ, known / 1000) << differ << " of " << known;
  // Outside the region, the whole-box tree knows voxels that fineState still calls unknown.
  ASSERT_TRUE(cube_not_sphere.allFinite());
  ASSERT_NE(
      whole_box->fineTree().search(cube_not_sphere.x(), cube_not_sphere.y(), cube_not_sphere.z()),
      nullptr);
  EXPECT_EQ(whole_box->fineState(cube_not_sphere), VoxelState{});

  // Planner reads over the region's cube: occupied voxels and frontiers agree likewise.
  // Occupied voxels: exactly the region's occupied states, nothing from the cube's corners.
  for (const auto* e : {region_only.get(), whole_box.get()}) {
    std::set<std::array<int, 3>> want;
    for (int z = 0; z < g.dims[2]; ++z)
      for (int y = 0; y < g.dims[1]; ++y)
        for (int x = 0; x < g.dims[0]; ++x)
          if (e->fineStateAt({x, y, z}).occupancy == VoxelClass::kOccupied) want.insert({x, y, z});
    const auto got = e->occupiedVoxels(MapLevel::kFine);
    EXPECT_GT(got.size(), 100u);
    const std::set<std::array<int, 3>> got_set(got.begin(), got.end());
    EXPECT_EQ(got_set, want);
  }
  // ROI comes from end points only, which clipping does not move: the same distance field.
  region_only->updateRoiDistance(0.02);
  whole_box->updateRoiDistance(0.02);
  std::size_t near_roi = 0;
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = 0; x < g.dims[0]; ++x) {
        const double d = region_only->roiDistance_m({x, y, z});
        ASSERT_EQ(whole_box->roiDistance_m({x, y, z}), d) << x << " " << y << " " << z;
        near_roi += d < 0.02;
      }
  EXPECT_GT(near_roi, 1000u);
  const auto frontiers_a = region_only->frontiers();
  const auto frontiers_b = whole_box->frontiers();
  EXPECT_NEAR(double(frontiers_b.size()), double(frontiers_a.size()), 0.01 * frontiers_a.size());
  expectSameFrontiers(frontiers_b, bruteForceFrontiers(*whole_box));
}

TEST(OctomapEngine, GridEngineRejectsTheObservationBoxExtent) {
  MapConfig c = smallConfig();
  c.fine_map_extent = FineMapExtent::kObservationBox;
  try {
    auto cpu = accel::createBackend(accel::BackendKind::kCpu);
    createMapEngine("grid", c, kRegion, cpu.get());
    FAIL() << "the grid engine accepted fine_map_extent observation_box";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("observation_box"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fvp::host::map
