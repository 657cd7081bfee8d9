// The grid map engine: scan-integration semantics on hand-made scans, every backend
// identical to the cpu reference, the ROI distance field against brute force and the
// frontier definitions on hand-made grids.
#include <gtest/gtest.h>

#include "backend_fixture.h"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "fvp/accel/backend.h"
#include "fvp/host/map/grid_map_engine.h"
#include "synthetic_scan.h"

namespace fvp::host::map {
namespace {

using accel::BackendKind;

MapConfig smallConfig() {
  MapConfig c;
  c.observation_min_m = {-0.3, -0.3, -0.3};
  c.observation_max_m = {0.3, 0.3, 0.5};
  c.coarse_voxel_size_m = 0.01;
  c.fine_voxel_size_m = 0.001;
  c.sensor_max_range_m = 0.6;
  return c;
}

const ClusterRegion kRegion(Eigen::Vector3d(0.01, -0.02, 0.3), 0.04);

// A view of a fixed synthetic cluster from a random direction on the sensor's side (-z),
// 0.25-0.35 m away; side x side rays.
testing::SyntheticScan viewOfCluster(std::uint64_t seed, int side) {
  static const testing::SyntheticWorld world = testing::makeWorld(1234, kRegion.center_m());
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d dir(gauss(rng), gauss(rng), -std::abs(gauss(rng)) - 1.0);
  const Eigen::Vector3d origin = kRegion.center_m() + dir.normalized() * (0.25 + 0.1 * unit(rng));
  return testing::renderScan(world, origin, side, side, 0.7, seed);
}

class GridEngineSemantics : public ::testing::Test {
 protected:
  std::unique_ptr<accel::Backend> cpu_ = accel::createBackend(BackendKind::kCpu);
};

TEST_F(GridEngineSemantics, OneRayFreesItsPathAndHitsItsEnd) {
  GridMapEngine map(smallConfig(), kRegion, *cpu_);
  const Eigen::Vector3d sensor(0.0, 0.0, 0.0);
  const Eigen::Vector3f end(0.0105f, -0.0195f, 0.3005f);  // inside the region
  const ScanStats stats = map.integrate(testing::makeClouds(sensor, {end}, {}));
  EXPECT_EQ(stats.points, 1u);
  EXPECT_GT(stats.coarse_voxels_updated, 20u);
  EXPECT_GT(stats.fine_voxels_updated, 20u);
  EXPECT_EQ(map.fineState(end.cast<double>()).occupancy, VoxelClass::kOccupied);
  EXPECT_TRUE(map.fineState(end.cast<double>()).roi);
  EXPECT_EQ(map.coarseClass(end.cast<double>()), VoxelClass::kOccupied);
  // Half way to the end inside the region: free, not ROI.
  const Eigen::Vector3d inside = sensor + (end.cast<double>() - sensor) * 0.93;
  ASSERT_TRUE(kRegion.contains(inside));
  EXPECT_EQ(map.fineState(inside).occupancy, VoxelClass::kFree);
  EXPECT_FALSE(map.fineState(inside).roi);
  EXPECT_EQ(map.coarseClass(sensor + (end.cast<double>() - sensor) * 0.5), VoxelClass::kFree);
  // Off the ray: unknown.
  EXPECT_EQ(map.fineState(kRegion.center_m() + Eigen::Vector3d(0.02, 0.0, 0.0)).occupancy,
            VoxelClass::kUnknown);
  // Outside the Cluster Region the fine map is never updated.
  EXPECT_EQ(map.fineState(sensor + (end.cast<double>() - sensor) * 0.5).occupancy,
            VoxelClass::kUnknown);
}

TEST_F(GridEngineSemantics, EachVoxelIsUpdatedOncePerScan) {
  GridMapEngine map(smallConfig(), kRegion, *cpu_);
  const Eigen::Vector3d sensor(0.0, 0.0, 0.0);
  // Two points in the same fine voxel, one ROI and one not: one hit, and the ROI wins.
  const Eigen::Vector3f a(0.0102f, -0.0198f, 0.3002f), b(0.0107f, -0.0193f, 0.3008f);
  map.integrate(testing::makeClouds(sensor, {a}, {b}));
  std::array<int, 3> index;
  ASSERT_TRUE(map.fine().geometry().gridIndex(a.cast<double>(), index));
  const OccupancyModel& m = map.config().model;
  EXPECT_FLOAT_EQ(map.fine().occupancyAt(index), m.hitLogOdds());
  EXPECT_FLOAT_EQ(map.fine().roiAt(index), m.hitLogOdds());
  // A non-ROI end point alone: ROI miss.
  map.integrate(testing::makeClouds(sensor, {}, {b}));
  EXPECT_FLOAT_EQ(map.fine().occupancyAt(index), 2 * m.hitLogOdds());
  EXPECT_FLOAT_EQ(map.fine().roiAt(index), m.hitLogOdds() + m.missLogOdds());
}

TEST_F(GridEngineSemantics, EndPointVoxelsAreHitsEvenWhereOtherRaysPass) {
  GridMapEngine map(smallConfig(), kRegion, *cpu_);
  const Eigen::Vector3d sensor(0.0, 0.0, 0.0);
  const Eigen::Vector3f near_end(0.0100f, -0.0190f, 0.2800f);
  const Eigen::Vector3f far_end =
      (near_end.cast<double>() * (0.31 / 0.28)).cast<float>();  // same line, behind
  map.integrate(testing::makeClouds(sensor, {}, {near_end, far_end}));
  EXPECT_EQ(map.fineState(near_end.cast<double>()).occupancy, VoxelClass::kOccupied);
  EXPECT_EQ(map.fineState(far_end.cast<double>()).occupancy, VoxelClass::kOccupied);
}

TEST_F(GridEngineSemantics, BadAndFarPointsAreCountedNotWritten) {
  GridMapEngine map(smallConfig(), kRegion, *cpu_);
  const Eigen::Vector3d sensor(0.0, 0.0, 0.0);
  const float nan = std::nanf(""), inf = INFINITY;
  const Eigen::Vector3f far(0.0f, 0.0f, 0.9f);  // beyond the 0.6 m max range
  const ScanStats stats = map.integrate(testing::makeClouds(sensor, {Eigen::Vector3f(nan, 0, 0.3f)},
                                                            {Eigen::Vector3f(0, inf, 0.3f), far}));
  EXPECT_EQ(stats.points, 3u);
  EXPECT_EQ(stats.skipped_invalid, 2u);
  EXPECT_EQ(stats.truncated, 1u);
  // Free up to the cut, the cut voxel itself untouched, nothing occupied.
  EXPECT_EQ(map.coarseClass({0.0, 0.0, 0.3}), VoxelClass::kFree);
  EXPECT_EQ(map.coarseClass({0.0, 0.0, 0.6049}), VoxelClass::kUnknown);
  EXPECT_EQ(map.coarseClass(far.cast<double>()), VoxelClass::kUnknown);
}

TEST_F(GridEngineSemantics, LogOddsClampAfterManyScans) {
  GridMapEngine map(smallConfig(), kRegion, *cpu_);
  const Eigen::Vector3f end(0.0105f, -0.0195f, 0.3005f);
  for (int i = 0; i < 12; ++i) map.integrate(testing::makeClouds({0, 0, 0}, {}, {end}));
  std::array<int, 3> index;
  ASSERT_TRUE(map.fine().geometry().gridIndex(end.cast<double>(), index));
  EXPECT_FLOAT_EQ(map.fine().occupancyAt(index), map.config().model.clampMaxLogOdds());
  EXPECT_FLOAT_EQ(map.fine().roiAt(index), map.config().model.clampMinLogOdds());
}

TEST_F(GridEngineSemantics, FineVoxelsOutsideTheRegionAreNeverMapped) {
  GridMapEngine map(smallConfig(), kRegion, *cpu_);
  const auto scan = viewOfCluster(3, 150);
  map.integrate(scan.clouds());
  std::size_t known = 0;
  map.fine().forEachVoxel([&](const std::array<int, 3>& index, float occupancy, float) {
    if (std::isnan(occupancy)) return;
    ++known;
    EXPECT_TRUE(kRegion.contains(map.fine().geometry().voxelCenter_m(index)) ||
                (map.fine().geometry().voxelCenter_m(index) - kRegion.center_m()).norm() <
                    kRegion.radius_m() + 1e-6);
  });
  EXPECT_GT(known, 1000u);
}

TEST_F(GridEngineSemantics, ASensorTooFarForTheExactWalkIsAnErrorNotADroppedScan) {
  GridMapEngine map(smallConfig(), kRegion, *cpu_);
  try {
    map.integrate(testing::makeClouds({9.0, 0.0, 0.3}, {}, {Eigen::Vector3f(8.5f, 0.0f, 0.3f)}));
    FAIL() << "a sensor 9 m from a 1 mm grid must be rejected";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("voxels from a map's corner"), std::string::npos)
        << e.what();
  }
}

TEST_F(GridEngineSemantics, CoarseOcTreeFollowsTheScansBrickByBrick) {
  // coarseOcTree() is updated from changed bricks only; it must equal a tree built from
  // every known coarse voxel after each scan.
  GridMapEngine map(smallConfig(), kRegion, *cpu_);
  for (int view = 0; view < 3; ++view) {
    const auto scan = viewOfCluster(40 + view, 100);
    map.integrate(scan.clouds());
    const octomap::OcTree& tree = map.coarseOcTree();
    std::size_t known = 0;
    map.coarse().forEachVoxel([&](const std::array<int, 3>& index, float occupancy, float) {
      if (std::isnan(occupancy)) return;
      ++known;
      const Eigen::Vector3d c = map.coarse().geometry().voxelCenter_m(index);
      const octomap::OcTreeNode* node = tree.search(c.x(), c.y(), c.z());
      ASSERT_NE(node, nullptr);
      EXPECT_FLOAT_EQ(node->getLogOdds(), occupancy);
    });
    EXPECT_EQ(tree.getNumLeafNodes(), known);
  }
}

TEST(GridEngine, RequiresABackendAndAKnownEngineName) {
  EXPECT_THROW(createMapEngine("grid", smallConfig(), kRegion, nullptr), std::invalid_argument);
  EXPECT_THROW(createMapEngine("voxblox", smallConfig(), kRegion, nullptr), std::invalid_argument);
  MapConfig bad = smallConfig();
  bad.model.prob_hit = 0.3;
  auto cpu = accel::createBackend(BackendKind::kCpu);
  try {
    createMapEngine("grid", bad, kRegion, cpu.get());
    FAIL() << "a bad model must be rejected";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("prob_hit"), std::string::npos);
  }
}

// ---------------------------------------------------------------------------------------
// Every backend against the cpu reference.

class GridEngineBackends : public fvp::testing::BackendFixture {
 protected:
  static void expectSameVoxels(const OccupancyLayer& got, const OccupancyLayer& want) {
    ASSERT_EQ(got.bricks().allocatedBricks(), want.bricks().allocatedBricks());
    std::size_t compared = 0;
    want.forEachVoxel([&](const std::array<int, 3>& index, float occupancy, float roi) {
      const float o = got.occupancyAt(index), r = got.roiAt(index);
      // Bit-exact: the same updates in the same order on every backend.
      ASSERT_TRUE((std::isnan(o) && std::isnan(occupancy)) || o == occupancy)
          << "occupancy at " << index[0] << "," << index[1] << "," << index[2];
      if (want.hasRoi()) {
        ASSERT_TRUE((std::isnan(r) && std::isnan(roi)) || r == roi);
      }
      ++compared;
    });
    EXPECT_GT(compared, 0u);
  }
};

TEST_P(GridEngineBackends, ScanIntegrationMatchesCpuExactly) {
  const std::uint64_t seed = fvp::testing::freshSeed();
  SCOPED_TRACE(fvp::testing::replayHint(seed));
  GridMapEngine got(smallConfig(), kRegion, *backend_), want(smallConfig(), kRegion, *cpu_);
  for (int view = 0; view < 3; ++view) {
    const auto scan = viewOfCluster(seed + view, 170);
    const ScanStats a = got.integrate(scan.clouds());
    const ScanStats b = want.integrate(scan.clouds());
    EXPECT_EQ(a.coarse_voxels_updated, b.coarse_voxels_updated);
    EXPECT_EQ(a.fine_voxels_updated, b.fine_voxels_updated);
  }
  expectSameVoxels(got.coarse(), want.coarse());
  expectSameVoxels(got.fine(), want.fine());
}

TEST_P(GridEngineBackends, OnTouchBrickAllocationMatchesCpu) {
  // A grid too large to allocate up front: bricks appear as rays reach them.
  GridGeometry g;
  g.voxel_size_m = 0.001;
  g.first_voxel = {-400, -400, -100};
  g.dims = {800, 800, 800};
  OccupancyLayer got(*backend_, g, true, std::nullopt, BrickAllocation::kOnTouch);
  OccupancyLayer want(*cpu_, g, true, std::nullopt, BrickAllocation::kOnTouch);
  ScanIntegrator got_integrator(got), want_integrator(want);
  const auto scan = viewOfCluster(17, 70);
  ScanStats stats;
  const auto points = prepareScanPoints(scan.clouds(), 0.6, stats);
  auto on_backend = backend_->createBufferFrom(points);
  auto on_cpu = cpu_->createBufferFrom(points);
  const OccupancyModel model;
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(
        got_integrator.integrate(*on_backend, points.size(), scan.origin_m.cast<float>(), model),
        want_integrator.integrate(*on_cpu, points.size(), scan.origin_m.cast<float>(), model));
  }
  EXPECT_GT(want.bricks().allocatedBricks(), 100u);
  EXPECT_LT(want.bricks().allocatedBricks(),
            100u * 100u * 100u / 4);  // far fewer than the 10^6 of the box
  expectSameVoxels(got, want);
}

GridGeometry millimetreGrid(std::array<int, 3> dims) {
  GridGeometry g;
  g.voxel_size_m = 0.001;
  g.first_voxel = {0, 0, 0};
  g.dims = dims;
  return g;
}

// Random ROI voxels (and known non-ROI ones, which must not count) in the box [lo, hi) of
// the grid; returns the dense ROI channel and the ROI voxels.
std::vector<float> randomRoi(const GridGeometry& g, std::array<int, 3> lo, std::array<int, 3> hi,
                             int count, std::mt19937_64& rng,
                             std::vector<std::array<int, 3>>* roi_voxels) {
  std::vector<float> roi(static_cast<std::size_t>(g.voxelCount()), std::nanf(""));
  const auto pick = [&] {
    std::array<int, 3> v;
    for (int a = 0; a < 3; ++a) v[a] = std::uniform_int_distribution<int>(lo[a], hi[a] - 1)(rng);
    return v;
  };
  const auto at = [&](const std::array<int, 3>& v) {
    return v[0] + std::size_t(g.dims[0]) * (v[1] + std::size_t(g.dims[1]) * v[2]);
  };
  for (int k = 0; k < count; ++k) {
    const auto v = pick();
    roi[at(v)] = 0.85f;
    roi_voxels->push_back(v);
  }
  // Never over an ROI voxel, which the brute force counts.
  for (int k = 0; k < 3 * count; ++k) {
    const auto v = pick();
    if (!(roi[at(v)] > 0.0f)) roi[at(v)] = -0.4f;
  }
  return roi;
}

void expectDistancesEqualBruteForce(const RoiDistanceField& field, const GridGeometry& g,
                                    const std::vector<std::array<int, 3>>& roi_voxels, int radius) {
  const std::vector<float> d = field.dense();
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = 0; x < g.dims[0]; ++x) {
        double best = radius;
        for (const auto& r : roi_voxels)
          best = std::min(best, std::sqrt(double((x - r[0]) * (x - r[0]) + (y - r[1]) * (y - r[1]) +
                                                 (z - r[2]) * (z - r[2]))));
        ASSERT_NEAR(d[x + g.dims[0] * (y + g.dims[1] * z)], best, 1e-5)
            << "voxel " << x << "," << y << "," << z;
      }
}

TEST_P(GridEngineBackends, RoiDistanceFieldEqualsBruteForce) {
  const std::uint64_t seed = fvp::testing::freshSeed();
  SCOPED_TRACE(fvp::testing::replayHint(seed));
  std::mt19937_64 rng(seed);
  const GridGeometry g = millimetreGrid({24, 16, 32});
  std::vector<std::array<int, 3>> roi_voxels;
  const std::vector<float> roi = randomRoi(g, {0, 0, 0}, g.dims, 12, rng, &roi_voxels);
  OccupancyLayer grid(*backend_, g, true, std::nullopt, BrickAllocation::kUpFront);
  grid.assignDense(std::vector<float>(roi.size(), -0.4f), roi);
  RoiDistanceField field(grid);
  // Windows reaching one, two and three bricks each way.
  for (const int radius : {1, 9, 20}) {
    SCOPED_TRACE("radius " + std::to_string(radius));
    field.compute(radius);
    expectDistancesEqualBruteForce(field, g, roi_voxels, radius);
  }
}

// The passes run only over bricks within the radius of ROI bricks; the rest must read the
// cap, also where ROI was before and is no more.
TEST_P(GridEngineBackends, RoiDistanceFieldFarFromRoiIsTheCapAfterRoiMoves) {
  const std::uint64_t seed = fvp::testing::freshSeed();
  SCOPED_TRACE(fvp::testing::replayHint(seed));
  std::mt19937_64 rng(seed);
  const GridGeometry g = millimetreGrid({56, 48, 40});  // 7 x 6 x 5 bricks
  const int radius = 11;  // two bricks around ROI bricks, less their far corners
  OccupancyLayer grid(*backend_, g, true, std::nullopt, BrickAllocation::kUpFront);
  RoiDistanceField field(grid);
  const std::vector<float> occupancy(static_cast<std::size_t>(g.voxelCount()), -0.4f);
  // ROI in one corner, then only in the opposite one.
  std::vector<std::array<int, 3>> first, second;
  grid.assignDense(occupancy, randomRoi(g, {0, 0, 0}, {12, 10, 9}, 5, rng, &first));
  field.compute(radius);
  expectDistancesEqualBruteForce(field, g, first, radius);
  grid.assignDense(occupancy, randomRoi(g, {44, 36, 30}, g.dims, 5, rng, &second));
  field.compute(radius);
  expectDistancesEqualBruteForce(field, g, second, radius);
  // No ROI at all: the cap everywhere.
  grid.assignDense(occupancy, std::vector<float>(occupancy.size(), -0.4f));
  field.compute(radius);
  expectDistancesEqualBruteForce(field, g, {}, radius);
}

TEST_P(GridEngineBackends, FrontiersFollowTheirDefinitions) {
  // A hand-made 16^3 grid: known free slab z < 8 with an ROI voxel on the slab's top
  // face, a known occupied voxel inside the slab, unknown above.
  GridGeometry g;
  g.voxel_size_m = 0.001;
  g.first_voxel = {0, 0, 0};
  g.dims = {16, 16, 16};
  const auto n = static_cast<std::size_t>(g.voxelCount());
  auto at = [&](int x, int y, int z) { return x + 16 * (y + 16 * z); };
  std::vector<float> occupancy(n, std::nanf("")), roi(n, std::nanf(""));
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) occupancy[at(x, y, z)] = -0.4f;
  occupancy[at(5, 5, 7)] = 0.85f;
  roi[at(5, 5, 7)] = 0.85f;  // ROI at the top face: next to unknown
  occupancy[at(9, 9, 3)] = 0.85f;
  roi[at(9, 9, 3)] = 0.85f;  // ROI buried in known space: not a frontier
  OccupancyLayer grid(*backend_, g, true, std::nullopt, BrickAllocation::kUpFront);
  grid.assignDense(occupancy, roi);
  const auto frontiers = FrontierExtractor(grid).extract(0.0f);
  std::size_t roi_count = 0, explore = 0;
  for (const auto& f : frontiers) {
    if (f.roi_frontier) {
      ++roi_count;
      EXPECT_EQ(f.index, (std::array<int, 3>{5, 5, 7}));
    }
    if (f.exploration_frontier) {
      ++explore;
      EXPECT_EQ(f.index[2], 7) << "only the top layer of the free slab touches unknown space";
      EXPECT_LT(f.normal.z(), -0.5) << "normals point away from the unknown (down)";
      const bool interior = f.index[0] > 0 && f.index[0] < 15 && f.index[1] > 0 && f.index[1] < 15;
      if (interior) {
        EXPECT_EQ(f.normal, Eigen::Vector3d(0, 0, -1));
      }
    }
  }
  EXPECT_EQ(roi_count, 1u);
  EXPECT_EQ(explore, 16u * 16u - 1u);  // the top layer minus the occupied ROI voxel
  // Sorted by index and identical to the cpu reference.
  OccupancyLayer reference(*cpu_, g, true, std::nullopt, BrickAllocation::kUpFront);
  reference.assignDense(occupancy, roi);
  const auto want = FrontierExtractor(reference).extract(0.0f);
  ASSERT_EQ(frontiers.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(frontiers[i].index, want[i].index);
    EXPECT_EQ(frontiers[i].normal, want[i].normal);
  }
}

TEST_P(GridEngineBackends, FrontiersFromChangedBricksEqualAFullExtractionAfterEveryScan) {
  // The engine's extractor classifies again only the bricks a scan changed and their
  // neighbours; a fresh extractor on the same layer classifies every brick.
  const std::uint64_t seed = fvp::testing::freshSeed();
  SCOPED_TRACE(fvp::testing::replayHint(seed));
  GridMapEngine map(smallConfig(), kRegion, *backend_);
  const float occupied = map.config().model.occupiedLogOdds();
  std::size_t partial = 0;
  for (int view = 0; view < 6; ++view) {
    map.integrate(viewOfCluster(seed + view, 120).clouds());
    const std::vector<FrontierVoxel> got = map.frontiers();
    FrontierExtractor fresh(map.fine());
    const std::vector<FrontierVoxel> want = fresh.extract(occupied);
    ASSERT_TRUE(fresh.lastStats().full);
    ASSERT_EQ(got.size(), want.size()) << "view " << view;
    for (std::size_t i = 0; i < want.size(); ++i) {
      ASSERT_EQ(got[i].index, want[i].index) << "view " << view << ", frontier " << i;
      ASSERT_EQ(got[i].normal, want[i].normal) << "view " << view << ", frontier " << i;
      ASSERT_EQ(got[i].roi_frontier, want[i].roi_frontier);
      ASSERT_EQ(got[i].exploration_frontier, want[i].exploration_frontier);
    }
    EXPECT_FALSE(want.empty());
    partial += map.frontierStats().classified_bricks < map.frontierStats().allocated_bricks;
  }
  EXPECT_GE(partial, 4u) << "later views change part of the map: not every brick again";
  // No scan since: nothing to classify, the same list.
  const std::size_t before = map.frontiers().size();
  EXPECT_EQ(map.frontierStats().classified_bricks, 0u);
  EXPECT_FALSE(map.frontierStats().full);
  EXPECT_EQ(map.frontiers().size(), before);
}

TEST_P(GridEngineBackends, FrontiersFromChangedBricksReachEveryNeighbourBrick) {
  // 4^3 bricks of known free space with unknown voxels at two corners and on one edge of
  // brick (1, 1, 1), each with a frontier voxel diagonally across in another brick whose
  // normal it enters (that voxel stays a frontier through an unknown face neighbour of its
  // own). Making such a voxel known changes frontiers in the bricks across its faces and the
  // normal in the brick across its corner or edge: one changed brick, its face, edge and
  // corner neighbours.
  GridGeometry g;
  g.voxel_size_m = 0.001;
  g.first_voxel = {0, 0, 0};
  g.dims = {32, 32, 32};
  const auto at = [](int x, int y, int z) { return std::size_t(x + 32 * (y + 32 * z)); };
  const float unknown = std::nanf("");
  std::vector<float> occupancy(std::size_t(g.voxelCount()), -0.4f);
  occupancy[at(8, 8, 8)] = occupancy[at(6, 7, 7)] = unknown;        // the low corner
  occupancy[at(15, 15, 15)] = occupancy[at(17, 16, 16)] = unknown;  // the high corner
  occupancy[at(8, 8, 12)] = occupancy[at(6, 7, 12)] = unknown;      // an edge: (0, 0, 1) across
  OccupancyLayer grid(*backend_, g, true, std::nullopt, BrickAllocation::kUpFront);
  grid.assignDense(occupancy, std::vector<float>(occupancy.size(), unknown));
  FrontierExtractor extractor(grid);
  extractor.extract(0.0f);
  BrickLayer& bricks = grid.bricks();
  for (const std::array<int, 3> corner :
       {std::array{8, 8, 8}, std::array{15, 15, 15}, std::array{8, 8, 12}}) {
    SCOPED_TRACE("voxel " + std::to_string(corner[0]) + "," + std::to_string(corner[1]) + "," +
                 std::to_string(corner[2]));
    // Known now: written as a scan writes it, its brick marked changed.
    std::vector<float> slots(bricks.slotCount());
    backend_->download(grid.occupancy(), slots.data(), slots.size() * sizeof(float));
    slots[std::size_t(bricks.slotOf(corner))] = -0.4f;
    backend_->upload(grid.occupancy(), slots.data(), slots.size() * sizeof(float));
    const int entry = bricks.table()[std::size_t(bricks.brickIndex(1, 1, 1))];
    bricks.markChanged({std::uint32_t(entry & FVP_BRICK_INDEX_MASK)});
    const std::vector<FrontierVoxel> got = extractor.extract(0.0f);
    EXPECT_FALSE(extractor.lastStats().full);
    EXPECT_EQ(extractor.lastStats().classified_bricks, 27u);
    const std::vector<FrontierVoxel> want = FrontierExtractor(grid).extract(0.0f);
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      EXPECT_EQ(got[i].index, want[i].index) << i;
      EXPECT_EQ(got[i].normal, want[i].normal) << i;
    }
  }
}

TEST_P(GridEngineBackends, ChangedBricksAreExactlyTheBricksWhoseVoxelsChanged) {
  // Readers (host mirror, Embree scenes, the coarse OcTree) refresh only the bricks a scan
  // reports changed: compare the report with a full before/after comparison.
  GridMapEngine map(smallConfig(), kRegion, *backend_);
  const auto first = viewOfCluster(5, 120);
  map.integrate(first.clouds());
  for (OccupancyLayer* layer : {&map.coarse(), &map.fine()}) {
    std::vector<float> before_occ, before_roi;
    layer->forEachVoxel([&](const std::array<int, 3>&, float o, float r) {
      before_occ.push_back(o);
      before_roi.push_back(r);
    });
    const std::uint64_t count_before = layer->bricks().changeCount();
    const auto scan = viewOfCluster(6, 120);
    map.integrate(scan.clouds());
    // Compare against a mirror read from scratch: download every slot.
    const std::size_t slots = layer->bricks().slotCount();
    std::vector<float> occ(slots), roi(slots, std::nanf(""));
    backend_->download(layer->occupancy(), occ.data(), slots * sizeof(float));
    if (layer->hasRoi()) backend_->download(layer->roi(), roi.data(), slots * sizeof(float));
    const auto same = [](float a, float b) { return (std::isnan(a) && std::isnan(b)) || a == b; };
    std::size_t changed = 0;
    for (std::size_t b = 0; b < layer->bricks().allocatedBricks(); ++b) {
      bool differs = false;
      for (int v = 0; v < accel::kBrickVoxels; ++v) {
        const std::size_t slot = b * accel::kBrickVoxels + v;
        const float o0 = slot < before_occ.size() ? before_occ[slot] : std::nanf("");
        const float r0 = slot < before_roi.size() ? before_roi[slot] : std::nanf("");
        differs = differs || !same(o0, occ[slot]) || (layer->hasRoi() && !same(r0, roi[slot]));
      }
      EXPECT_EQ(layer->bricks().brickChangeStamps()[b] > count_before, differs) << "brick " << b;
      changed += differs;
    }
    EXPECT_GT(changed, 0u);
    // The incrementally refreshed mirror equals the full download.
    std::size_t slot = 0;
    layer->forEachVoxel([&](const std::array<int, 3>&, float o, float r) {
      EXPECT_TRUE(same(o, occ[slot]));
      if (layer->hasRoi()) {
        EXPECT_TRUE(same(r, roi[slot]));
      }
      ++slot;
    });
  }
}

FVP_INSTANTIATE_FOR_ALL_BACKENDS(GridEngineBackends);

TEST(MapConfigYaml, TheDefaultsFileHoldsTheDefaults) {
  const MapConfig read = MapConfig::fromYamlFile(FVP_SOURCE_DIR "/host/config/map_default.yaml");
  const MapConfig defaults;
  EXPECT_EQ(read.coarse_voxel_size_m, defaults.coarse_voxel_size_m);
  EXPECT_EQ(read.fine_voxel_size_m, defaults.fine_voxel_size_m);
  EXPECT_EQ(read.fine_map_extent, defaults.fine_map_extent);
  EXPECT_EQ(read.observation_min_m, defaults.observation_min_m);
  EXPECT_EQ(read.observation_max_m, defaults.observation_max_m);
  EXPECT_EQ(read.sensor_max_range_m, defaults.sensor_max_range_m);
  EXPECT_EQ(read.model.prob_hit, defaults.model.prob_hit);
  EXPECT_EQ(read.model.occupied_prob, defaults.model.occupied_prob);
}

TEST(MapConfigYaml, FineMapExtentParsesBothValues) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("fvp_map_extent_" + std::to_string(::getpid()) + ".yaml");
  for (const FineMapExtent extent :
       {FineMapExtent::kObservationBox, FineMapExtent::kClusterRegion}) {
    std::ofstream(path) << "fine_map_extent: " << toString(extent) << "\n";
    EXPECT_EQ(MapConfig::fromYamlFile(path).fine_map_extent, extent) << toString(extent);
  }
  std::filesystem::remove(path);
  EXPECT_EQ(toString(FineMapExtent::kObservationBox), "observation_box");
}

TEST(MapConfigYaml, ErrorsNameTheFileAndTheKey) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("fvp_map_config_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto expectError = [&](const std::string& yaml, const std::string& key,
                         const std::string& expected) {
    const auto path = dir / "map.yaml";
    std::ofstream(path) << yaml;
    try {
      MapConfig::fromYamlFile(path);
      FAIL() << "accepted: " << yaml;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path.string()), std::string::npos) << what;
      EXPECT_NE(what.find(key), std::string::npos) << what;
      EXPECT_NE(what.find(expected), std::string::npos) << what;
    }
  };
  expectError("fine_voxel_size_m: -1\n", "fine_voxel_size_m", "expected a value in");
  expectError("fine_voxel_size: 0.001\n", "fine_voxel_size", "unknown key");
  expectError("observation_min_m: [0, 0]\n", "observation_min_m", "list of 3 numbers");
  expectError("prob_hit: high\n", "prob_hit", "expected a number");
  expectError("observation_min_m: [0, 0, 3]\n", "observation_max_m", "must exceed");
  expectError("sensor_max_range_m: 5.0\n", "sensor_max_range_m", "fewer than 4096 voxels per ray");
  expectError("fine_map_extent: everywhere\n", "fine_map_extent",
              "cluster_region or observation_box");
  std::filesystem::remove_all(dir);
}

// Review finding: with bricks allocated on touch, the separable distance passes lost
// values carried through voxels of unallocated bricks. Here the ROI voxel's brick and a
// diagonal neighbour are the only bricks a ray reached.
TEST(GridEngineDistance, DistancesCrossUnallocatedBricksExactly) {
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  GridGeometry g;
  g.voxel_size_m = 0.001;
  g.first_voxel = {0, 0, 0};
  g.dims = {32, 32, 32};
  OccupancyLayer grid(*cpu, g, true, std::nullopt, BrickAllocation::kOnTouch);
  // One ROI ray ending in voxel (7, 0, 0) from a sensor at voxel (15.5, 15.5, 0.5): it
  // touches bricks (0,0,0), (1,0,0), (0,1,0) or (1,1,0) only.
  const accel::ScanPoint end{0.0075f, 0.0005f, 0.0005f, FVP_POINT_HIT | FVP_POINT_ROI};
  auto points = cpu->createBufferFrom(std::vector<accel::ScanPoint>{end});
  ScanIntegrator(grid).integrate(*points, 1, Eigen::Vector3f(0.0155f, 0.0155f, 0.0005f),
                                 OccupancyModel{});
  ASSERT_LT(grid.bricks().allocatedBricks(), 5u);
  const int radius = 10;
  RoiDistanceField field(grid);
  field.compute(radius);
  const std::vector<float> d = field.dense();
  for (int z = 0; z < 32; ++z)
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        const double exact = std::sqrt(double((x - 7) * (x - 7) + y * y + z * z));
        ASSERT_NEAR(d[x + 32 * (y + 32 * z)], std::min<double>(exact, radius), 1e-5)
            << "voxel " << x << "," << y << "," << z;
      }
}

}  // namespace
}  // namespace fvp::host::map
