// The exact DDA of kernels/fvp_dda.h against brute force (the same walk started at the
// origin, without the skip to the grid entry), against OctoMap's computeRayKeys, and on
// hand-made boundary cases.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <vector>

#include "fvp/accel/kernel_types.h"
#include "fvp/accel/ray_workload.h"

namespace fvp::accel {
namespace {

using Key = std::array<int, 3>;

struct Walk {
  unsigned status = 0;
  std::vector<Key> voxels;
};

// The walk as the kernels do it, recording every voxel (no occupancy, no field).
Walk walkSkipping(const GridParams& g, const Ray& ray) {
  Walk w;
  fvp_dda d;
  w.status = fvp_dda_init(&d, &g, ray.origin_m, ray.end_m);
  if (w.status != 0) return w;
  const int dim[3] = {g.dim_x, g.dim_y, g.dim_z};
  for (;;) {
    w.voxels.push_back({d.key[0], d.key[1], d.key[2]});
    const int axis = fvp_dda_next_axis(&d);
    if (axis < 0) return w;
    fvp_dda_advance(&d, axis);
    if (d.key[axis] < 0 || d.key[axis] >= dim[axis]) {
      w.status = FVP_RAY_LEFT_GRID;
      return w;
    }
  }
}

// Brute force: walk every voxel from the origin's, outside the grid too, and keep the
// in-grid ones up to the first exit. Slow for far origins; that is what the skip avoids.
Walk walkFromOrigin(const GridParams& g, const Ray& ray) {
  Walk w;
  fvp_dda d;
  w.status = fvp_dda_init_ex(&d, &g, ray.origin_m, ray.end_m, /*skip_outside=*/0);
  if (w.status != 0) return w;
  const int dim[3] = {g.dim_x, g.dim_y, g.dim_z};
  auto inside = [&] {
    return d.key[0] >= 0 && d.key[0] < dim[0] && d.key[1] >= 0 && d.key[1] < dim[1] &&
           d.key[2] >= 0 && d.key[2] < dim[2];
  };
  bool entered = false;
  for (;;) {
    if (inside()) {
      entered = true;
      w.voxels.push_back({d.key[0], d.key[1], d.key[2]});
    } else if (entered) {
      w.status = FVP_RAY_LEFT_GRID;
      return w;
    }
    const int axis = fvp_dda_next_axis(&d);
    if (axis < 0) break;
    fvp_dda_advance(&d, axis);
  }
  if (!entered) w.status = FVP_RAY_LEFT_GRID;
  return w;
}

GridParams testGrid(int side = 48, float voxel = 0.01f, float origin = -0.24f) {
  return makeGridParams({side, side + 3, side - 5}, {origin, origin, origin}, voxel);
}

Key voxelOf(const GridParams& g, std::array<float, 3> p) {
  return {static_cast<int>(std::floor((p[0] - g.origin_x_m) / g.voxel_size_m)),
          static_cast<int>(std::floor((p[1] - g.origin_y_m) / g.voxel_size_m)),
          static_cast<int>(std::floor((p[2] - g.origin_z_m) / g.voxel_size_m))};
}

TEST(Dda, WalkIsAFaceConnectedPathFromOriginVoxelToEndVoxel) {
  const GridParams g = testGrid();
  const auto rays = makeRandomRays(g, {2000, 0.0f}, 11);
  for (const Ray& ray : rays) {
    const Walk w = walkSkipping(g, ray);
    ASSERT_EQ(w.status, FVP_RAY_REACHED_END);
    ASSERT_FALSE(w.voxels.empty());
    EXPECT_EQ(w.voxels.front(), voxelOf(g, {ray.origin_m[0], ray.origin_m[1], ray.origin_m[2]}));
    EXPECT_EQ(w.voxels.back(), voxelOf(g, {ray.end_m[0], ray.end_m[1], ray.end_m[2]}));
    for (std::size_t i = 1; i < w.voxels.size(); ++i) {
      int manhattan = 0;
      for (int a = 0; a < 3; ++a) manhattan += std::abs(w.voxels[i][a] - w.voxels[i - 1][a]);
      ASSERT_EQ(manhattan, 1) << "consecutive voxels must share a face";
    }
  }
}

TEST(Dda, SkipToGridEntryMatchesBruteForceWalkFromOrigin) {
  const GridParams g = testGrid();
  // Half the rays start outside; also rays leaving the grid: swap origin and end.
  auto rays = makeRandomRays(g, {4000, 0.6f}, 12);
  const std::size_t n = rays.size();
  for (std::size_t i = 0; i < n; ++i) {
    Ray r = rays[i];
    std::swap(r.origin_m, r.end_m);
    rays.push_back(r);
  }
  std::size_t outside = 0;
  for (const Ray& ray : rays) {
    const Walk fast = walkSkipping(g, ray);
    const Walk slow = walkFromOrigin(g, ray);
    ASSERT_EQ(fast.status, slow.status);
    ASSERT_EQ(fast.voxels, slow.voxels);
    outside += (fast.status == FVP_RAY_LEFT_GRID);
  }
  EXPECT_GT(outside, rays.size() / 10) << "the workload must exercise rays that leave the grid";
}

TEST(Dda, RaysMissingTheGridVisitNothing) {
  const GridParams g = testGrid();
  // Parallel to the grid, beside it.
  const Ray beside = makeRay({-0.5f, 0.4f, 0.0f}, {0.5f, 0.4f, 0.0f});
  EXPECT_EQ(walkSkipping(g, beside).status, FVP_RAY_LEFT_GRID);
  EXPECT_TRUE(walkSkipping(g, beside).voxels.empty());
  // Pointing away from it.
  const Ray away = makeRay({-0.3f, 0.0f, 0.0f}, {-0.6f, 0.0f, 0.0f});
  EXPECT_EQ(walkSkipping(g, away).status, FVP_RAY_LEFT_GRID);
  // Ending before it.
  const Ray short_ray = makeRay({-0.6f, 0.0f, 0.0f}, {-0.3f, 0.0f, 0.0f});
  EXPECT_EQ(walkSkipping(g, short_ray).status, FVP_RAY_LEFT_GRID);
  // Passing the corner region: enters x and y slabs at different times, never all three.
  const Ray corner = makeRay({-0.5f, 0.5f, 0.0f}, {0.5f, 1.2f, 0.0f});
  EXPECT_EQ(walkSkipping(g, corner).status, walkFromOrigin(g, corner).status);
}

TEST(Dda, UnusableEndPointsAreInvalid) {
  const GridParams g = testGrid();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(walkSkipping(g, makeRay({nan, 0, 0}, {0, 0, 0})).status, FVP_RAY_INVALID);
  EXPECT_EQ(walkSkipping(g, makeRay({0, 0, 0}, {0, inf, 0})).status, FVP_RAY_INVALID);
  // 8192 voxels of 1 cm is 81.92 m: beyond the fixed-point range.
  EXPECT_EQ(walkSkipping(g, makeRay({0, 0, 0}, {0, 0, 100.0f})).status, FVP_RAY_INVALID);
  EXPECT_EQ(walkSkipping(g, makeRay({0, 0, 0}, {0, 0, 50.0f})).status, FVP_RAY_LEFT_GRID);
}

TEST(Dda, ZeroLengthRayVisitsItsVoxelOnce) {
  const GridParams g = testGrid();
  const Walk w = walkSkipping(g, makeRay({0.013f, -0.02f, 0.05f}, {0.013f, -0.02f, 0.05f}));
  ASSERT_EQ(w.status, FVP_RAY_REACHED_END);
  ASSERT_EQ(w.voxels.size(), 1u);
  EXPECT_EQ(w.voxels[0], voxelOf(g, {0.013f, -0.02f, 0.05f}));
}

TEST(Dda, AxisAlignedRaysWalkOneAxis) {
  const GridParams g = testGrid(40, 0.01f, 0.0f);  // voxel k spans [k cm, k+1 cm)
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {1, -1}) {
      std::array<float, 3> o{0.155f, 0.155f, 0.155f}, e = o;
      e[axis] += sign * 0.1f;  // 10 voxels
      const Walk w = walkSkipping(g, makeRay(o, e));
      ASSERT_EQ(w.status, FVP_RAY_REACHED_END);
      ASSERT_EQ(w.voxels.size(), 11u) << "axis " << axis << " sign " << sign;
      for (std::size_t i = 0; i < w.voxels.size(); ++i) {
        Key expected{15, 15, 15};
        expected[axis] += sign * static_cast<int>(i);
        EXPECT_EQ(w.voxels[i], expected);
      }
    }
  }
}

TEST(Dda, EndPointOnABoundaryBelongsToTheUpperVoxel) {
  // Voxel k covers [k, k+1) voxel units, so an end exactly on the boundary x = 20 lies in
  // voxel 20 whichever way the ray travels; with 1/64 m voxels every value is exact.
  const float v = 1.0f / 64.0f;
  const GridParams g = makeGridParams({40, 40, 40}, {0, 0, 0}, v);
  const Walk up =
      walkSkipping(g, makeRay({17.5f * v, 5.5f * v, 5.5f * v}, {20.0f * v, 5.5f * v, 5.5f * v}));
  ASSERT_EQ(up.voxels.size(), 4u);  // 17, 18, 19, 20
  EXPECT_EQ(up.voxels.back(), (Key{20, 5, 5}));
  const Walk down =
      walkSkipping(g, makeRay({22.5f * v, 5.5f * v, 5.5f * v}, {20.0f * v, 5.5f * v, 5.5f * v}));
  ASSERT_EQ(down.voxels.size(), 3u);  // 22, 21, 20
  EXPECT_EQ(down.voxels.back(), (Key{20, 5, 5}));
}

TEST(Dda, SimultaneousCrossingsStepZThenYThenX) {
  // A diagonal through voxel corners crosses x, y and z boundaries at the same parameter;
  // OctoMap's order is z first, then y, then x.
  const float v = 1.0f / 64.0f;
  const GridParams g = makeGridParams({16, 16, 16}, {0, 0, 0}, v);
  const Walk w =
      walkSkipping(g, makeRay({2.5f * v, 2.5f * v, 2.5f * v}, {4.5f * v, 4.5f * v, 4.5f * v}));
  const std::vector<Key> expected{{2, 2, 2}, {2, 2, 3}, {2, 3, 3}, {3, 3, 3},
                                  {3, 3, 4}, {3, 4, 4}, {4, 4, 4}};
  EXPECT_EQ(w.voxels, expected);
  // x-y tie only: y before x.
  const Walk xy =
      walkSkipping(g, makeRay({2.5f * v, 2.5f * v, 2.25f * v}, {3.5f * v, 3.5f * v, 2.25f * v}));
  EXPECT_EQ(xy.voxels, (std::vector<Key>{{2, 2, 2}, {2, 3, 2}, {3, 3, 2}}));
}

TEST(Dda, EntryThroughAnEdgeMatchesTheWalkFromOutside) {
  // The ray enters exactly through a grid edge (x and y slabs at the same parameter).
  const float v = 1.0f / 64.0f;
  const GridParams g = makeGridParams({16, 16, 16}, {0, 0, 0}, v);
  for (const Ray& ray :
       {makeRay({-2.0f * v, -2.0f * v, 3.5f * v}, {5.0f * v, 5.0f * v, 3.5f * v}),
        makeRay({-2.0f * v, -2.0f * v, -2.0f * v}, {5.0f * v, 5.0f * v, 5.0f * v}),
        makeRay({18.0f * v, -2.0f * v, 3.5f * v}, {11.0f * v, 5.0f * v, 3.5f * v})}) {
    const Walk fast = walkSkipping(g, ray);
    const Walk slow = walkFromOrigin(g, ray);
    EXPECT_EQ(fast.status, slow.status);
    EXPECT_EQ(fast.voxels, slow.voxels);
    EXPECT_FALSE(fast.voxels.empty());
  }
}

// Gap, in voxels along the ray, between the two boundary crossings that two walks took in
// opposite order at their first difference (computed from the float end points in long
// double, independent of either walk's arithmetic).
long double crossingGapVoxels(const std::vector<Key>& a, const std::vector<Key>& b,
                              const std::array<long double, 3>& o,
                              const std::array<long double, 3>& e) {
  std::size_t k = 1;
  while (k < a.size() && k < b.size() && a[k] == b[k]) ++k;
  if (k >= a.size() || k >= b.size()) return 1e9L;
  auto axisOf = [](const Key& from, const Key& to) {
    for (int i = 0; i < 3; ++i)
      if (from[i] != to[i]) return i;
    return -1;
  };
  const int axis_a = axisOf(a[k - 1], a[k]), axis_b = axisOf(b[k - 1], b[k]);
  if (axis_a < 0 || axis_b < 0 || axis_a == axis_b) return 1e9L;
  auto crossing = [&](int axis, const Key& from, const Key& to) {
    const long double boundary = std::max(from[axis], to[axis]);  // voxel units
    return (boundary - o[axis]) / (e[axis] - o[axis]);
  };
  const long double length =
      std::sqrt((e[0] - o[0]) * (e[0] - o[0]) + (e[1] - o[1]) * (e[1] - o[1]) +
                (e[2] - o[2]) * (e[2] - o[2]));
  return std::abs(crossing(axis_a, a[k - 1], a[k]) - crossing(axis_b, b[k - 1], b[k])) * length;
}

// OctoMap's computeRayKeys on a grid whose voxels coincide with OctoMap's keys. Boundary
// conventions that differ, by design: our walk also holds the end voxel (OctoMap's
// excludes it) and visits one voxel for a ray inside a single voxel (OctoMap's is empty).
// Where two crossings lie closer than float32 end points can resolve (~1e-4 voxel for
// rays of 100+ voxels), our 1/65536-voxel fixed point and OctoMap's float direction may
// order them differently: both are valid walks of the float input. Such near-ties must
// be the only differences, and rare.
TEST(Dda, VoxelSequenceEqualsOctomapComputeRayKeys) {
  const double res = 0.001;
  const int side = 128;
  const GridParams g = makeGridParams({side, side, side}, {0, 0, 0}, static_cast<float>(res));
  octomap::OcTree tree(res);
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<float> coord(0.0f, static_cast<float>(side * res));
  // Keep end points away from voxel boundaries, where float (ours) and double (OctoMap)
  // quantisation may legitimately round to different voxels.
  auto awayFromBoundary = [&](float c) {
    const double f = c / res - std::floor(c / res);
    return f > 1e-3 && f < 1.0 - 1e-3;
  };
  auto randomPoint = [&] {
    for (;;) {
      octomap::point3d p(coord(rng), coord(rng), coord(rng));
      if (awayFromBoundary(p.x()) && awayFromBoundary(p.y()) && awayFromBoundary(p.z())) return p;
    }
  };
  constexpr int kRays = 5000;
  int compared = 0, near_ties = 0;
  octomap::KeyRay keys;
  for (int i = 0; i < kRays; ++i) {
    const octomap::point3d o = randomPoint(), e = randomPoint();
    ASSERT_TRUE(tree.computeRayKeys(o, e, keys));
    std::vector<Key> expected;
    for (const auto& k : keys)
      expected.push_back({k[0] - 32768, k[1] - 32768, k[2] - 32768});  // key 32768 is [0, res)
    const octomap::OcTreeKey end_key = tree.coordToKey(e);
    expected.push_back({end_key[0] - 32768, end_key[1] - 32768, end_key[2] - 32768});
    const Walk w = walkSkipping(g, makeRay({o.x(), o.y(), o.z()}, {e.x(), e.y(), e.z()}));
    ASSERT_EQ(w.status, FVP_RAY_REACHED_END);
    compared += static_cast<int>(expected.size());
    if (w.voxels == expected) continue;
    ++near_ties;
    ASSERT_EQ(w.voxels.size(), expected.size()) << "ray " << i;
    ASSERT_EQ(w.voxels.back(), expected.back()) << "ray " << i;
    const std::array<long double, 3> o_vox{o.x() / res, o.y() / res, o.z() / res};
    const std::array<long double, 3> e_vox{e.x() / res, e.y() / res, e.z() / res};
    EXPECT_LT(crossingGapVoxels(w.voxels, expected, o_vox, e_vox), 1e-3L)
        << "ray " << i << " from " << o << " to " << e << " differs by more than a near-tie";
  }
  EXPECT_LE(near_ties, kRays / 500) << "near-tie differences must stay below 0.2 % of rays";
  EXPECT_GT(compared, kRays * 50);
  std::cout << "identical walks: " << kRays - near_ties << " of " << kRays << " rays (" << compared
            << " voxels); near-tie order differences: " << near_ties << "\n";
}

TEST(Dda, TraverseStopsAtFirstOccupiedVoxelAndSumsTheField) {
  const GridParams g = makeGridParams({10, 1, 1}, {0, 0, 0}, 1.0f);
  std::vector<float> occupancy(10, kMissLogOdds), field(10);
  for (int i = 0; i < 10; ++i) field[i] = static_cast<float>(i);
  occupancy[6] = kHitLogOdds;
  const Ray ray = makeRay({0.5f, 0.5f, 0.5f}, {9.5f, 0.5f, 0.5f});
  fvp_ray_result r = fvp_traverse_ray(&g, kDefaultOccupiedThreshold, ray.origin_m, ray.end_m,
                                      occupancy.data(), field.data());
  EXPECT_EQ(r.status, FVP_RAY_HIT_OCCUPIED);
  EXPECT_EQ(r.steps, 7u);
  EXPECT_EQ(r.stop_voxel, 6);
  EXPECT_FLOAT_EQ(r.field_sum, 0 + 1 + 2 + 3 + 4 + 5 + 6);
  occupancy[6] = 0.0f;  // unknown does not stop the ray
  r = fvp_traverse_ray(&g, kDefaultOccupiedThreshold, ray.origin_m, ray.end_m, occupancy.data(),
                       field.data());
  EXPECT_EQ(r.status, FVP_RAY_REACHED_END);
  EXPECT_EQ(r.steps, 10u);
  EXPECT_EQ(r.stop_voxel, 9);
  // A ray from inside that leaves the grid: no stopping voxel.
  const Ray leaving = makeRay({7.5f, 0.5f, 0.5f}, {14.5f, 0.5f, 0.5f});
  r = fvp_traverse_ray(&g, kDefaultOccupiedThreshold, leaving.origin_m, leaving.end_m,
                       occupancy.data(), field.data());
  EXPECT_EQ(r.status, FVP_RAY_LEFT_GRID);
  EXPECT_EQ(r.steps, 3u);
  EXPECT_EQ(r.stop_voxel, -1);
}

TEST(GridParams, RejectsBadGeometry) {
  EXPECT_THROW(makeGridParams({0, 4, 4}, {0, 0, 0}, 0.01f), std::invalid_argument);
  EXPECT_THROW(makeGridParams({4, 4, 4}, {0, 0, 0}, 0.0f), std::invalid_argument);
  EXPECT_THROW(makeGridParams({4, 4, 4}, {0, 0, 0}, std::nanf("")), std::invalid_argument);
  EXPECT_THROW(makeGridParams({20000, 4, 4}, {0, 0, 0}, 0.01f), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::accel
