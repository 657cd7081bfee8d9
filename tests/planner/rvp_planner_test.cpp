// RVP: ROI-contour targets against their definition, its gains by hand, the set choice and
// the counting of failed moves.
#include <gtest/gtest.h>

#include <set>

#include "fvp/host/map/map_engine.h"
#include "fvp/host/planner/rvp_planner.h"
#include "planner_test_maps.h"

namespace fvp::host::planner {
namespace {

using Vec3f = Eigen::Vector3f;

map::MapConfig smallConfig() {
  return testing::plannerTestConfig();
}
const ClusterRegion& kRegion = testing::kPlannerTestRegion;
std::unique_ptr<map::MapEngine> mappedEngine() {
  return testing::mappedTestEngine();
}

TEST(RvpPlanner, RoiContourTargetsEqualTheirDefinition) {
  auto e = mappedEngine();
  const auto got = RvpPlanner::roiContourTargets(*e);
  const map::GridGeometry& g = e->gridGeometry(map::MapLevel::kFine);
  const auto st = [&](int x, int y, int z) { return e->fineState(g.voxelCenter_m({x, y, z})); };
  const auto inRegion = [&](int x, int y, int z) {
    return kRegion.contains(g.voxelCenter_m({x, y, z}));
  };
  static constexpr int f[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                  {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  std::set<std::array<long, 3>> want;
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = 0; x < g.dims[0]; ++x) {
        if (st(x, y, z).occupancy != map::VoxelClass::kFree) continue;
        bool roi = false, unknown = false;
        for (const auto& d : f) {
          const auto s = st(x + d[0], y + d[1], z + d[2]);
          roi |= s.roi && s.occupancy == map::VoxelClass::kOccupied;
          unknown |=
              inRegion(x + d[0], y + d[1], z + d[2]) && s.occupancy == map::VoxelClass::kUnknown;
        }
        if (roi && unknown) {
          const Eigen::Vector3d c = g.voxelCenter_m({x, y, z});
          want.insert(
              {std::lround(c.x() * 1e5), std::lround(c.y() * 1e5), std::lround(c.z() * 1e5)});
        }
      }
  std::set<std::array<long, 3>> have;
  for (const auto& c : got)
    have.insert({std::lround(c.x() * 1e5), std::lround(c.y() * 1e5), std::lround(c.z() * 1e5)});
  EXPECT_EQ(have, want);
  EXPECT_GT(have.size(), 10u);
}

TEST(RvpPlanner, RoiGainByHand) {
  auto e = map::createMapEngine("octomap", smallConfig(), kRegion, nullptr);
  RvpPlanner rvp(RvpConfig{}, 1);
  rvp.refresh(*e);
  // Nothing known: every region voxel on the ray is unknown.
  EXPECT_DOUBLE_EQ(rvp.roiGain(kRegion.center_m(), {0.0, -0.4, 0.3}), 1.0);
  // A hit 10 cm outside the region on the viewing line: an occupied coarse voxel on the ray
  // drops the candidate.
  e->integrate(
      map::testing::makeClouds({0.0005, -0.45, 0.3005}, {}, {Vec3f(0.0005f, -0.2f, 0.3005f)}));
  rvp.refresh(*e);
  EXPECT_LT(rvp.roiGain({0.0005, 0.0005, 0.3005}, {0.0005, -0.4, 0.3005}), 0.0);  // occluded
  // From the other side the ray meets nothing the scan reached: all unknown.
  const double g = rvp.roiGain({0.0005, 0.0005, 0.3005}, {0.0005, 0.4, 0.3005});
  EXPECT_DOUBLE_EQ(g, 1.0);
}

TEST(RvpPlanner, PlansMovesAndCountsFailures) {
  auto e = mappedEngine();
  RvpPlanner rvp(RvpConfig{}, 3);
  const auto shell = [](const Eigen::Isometry3d& T) {
    const double r = (T.translation() - Eigen::Vector3d(0.0, -0.7, 0.3)).norm();
    return r > 0.2 && r < 0.8;
  };
  int attempts = 0;
  const PlanStep step =
      planAndMove(rvp, *e, Eigen::Isometry3d(Eigen::Translation3d(0, -0.3, 0.35)), shell,
                  [&](const Eigen::Isometry3d&) { return ++attempts == 3; });
  ASSERT_TRUE(step.moved());
  EXPECT_EQ(step.move_attempts, 3u);
  EXPECT_EQ(step.failed_moves, 2u);
  EXPECT_EQ(step.candidates.size(), 200u);
  const Candidate& c = step.candidates[*step.chosen];
  EXPECT_TRUE(c.reachable);
  const double d = (c.position_m() - c.target_m).norm();
  if (c.kind == CandidateKind::kRoi) {
    EXPECT_GE(d, 0.3 - 1e-9);
    EXPECT_LE(d, 0.5 + 1e-9);
  }
  // Every move fails: all finite-utility candidates of the chosen set are tried once.
  std::size_t calls = 0;
  const PlanStep failed =
      planAndMove(rvp, *e, Eigen::Isometry3d(Eigen::Translation3d(0, -0.3, 0.35)), shell,
                  [&](const Eigen::Isometry3d&) { return ++calls, false; });
  EXPECT_FALSE(failed.moved());
  EXPECT_EQ(failed.failed_moves, calls);
  EXPECT_GT(calls, 0u);
}

}  // namespace
}  // namespace fvp::host::planner
