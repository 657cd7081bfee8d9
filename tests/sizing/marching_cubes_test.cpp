// Marching cubes: the derived case table against its definition, and meshes of analytic
// signed distances that must be closed, consistently wound, of the right topology, on the
// surface and enclosing the right volume; then the mesh of a TSDF fused from views.
#include "fvp/host/tsdf/marching_cubes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <set>

#include "fvp/host/core/look_at.h"
#include "fvp/host/tsdf/tsdf_volume.h"
#include "sphere_views.h"

namespace fvp::host::tsdf {
namespace {

TEST(MarchingCubes, EveryCrossingEdgeIsInExactlyOneCycle) {
  for (int config = 0; config < 256; ++config) {
    std::multiset<int> seen;
    for (const auto& cycle : MarchingCubes::cycles(config)) {
      EXPECT_GE(cycle.size(), 3u) << "configuration " << config;
      seen.insert(cycle.begin(), cycle.end());
    }
    std::multiset<int> crossing;
    for (int edge = 0; edge < MarchingCubes::kEdges; ++edge) {
      const auto [a, b] = MarchingCubes::edgeCorners(edge);
      ASSERT_EQ(__builtin_popcount(a ^ b), 1) << "edge " << edge;
      if (((config >> a) & 1) != ((config >> b) & 1)) crossing.insert(edge);
    }
    EXPECT_EQ(seen, crossing) << "configuration " << config;
  }
  EXPECT_TRUE(MarchingCubes::cycles(0).empty());
  EXPECT_TRUE(MarchingCubes::cycles(255).empty());
  EXPECT_EQ(MarchingCubes::cycles(1).size(), 1u);              // one corner: a triangle
  EXPECT_EQ(MarchingCubes::cycles(1 | 128).size(), 2u);        // opposite corners: two
  EXPECT_EQ(MarchingCubes::cycles(1 | 2).front().size(), 4u);  // an edge: a quad
  EXPECT_THROW(MarchingCubes::cycles(256), std::invalid_argument);
}

struct MeshStats {
  bool closed_and_oriented = true;  ///< every directed edge once, its reverse once
  long euler = 0;                   ///< V - E + F
  double volume = 0.0;              ///< divergence theorem; positive when wound outward
};

MeshStats analyse(const TriangleMesh& mesh) {
  MeshStats stats;
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
    const Eigen::Vector3d a = mesh.vertices_m[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices_m[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices_m[t[2]].cast<double>();
    stats.volume += a.dot(b.cross(c)) / 6.0;
  }
  for (const auto& [edge, count] : directed) {
    const auto reverse = directed.find({edge.second, edge.first});
    if (count != 1 || reverse == directed.end() || reverse->second != 1)
      stats.closed_and_oriented = false;
  }
  stats.euler =
      long(mesh.vertices_m.size()) - long(directed.size() / 2) + long(mesh.triangles.size());
  return stats;
}

// A dense grid over [0, n)^3 of an analytic signed distance.
template <class Sdf>
TriangleMesh meshOf(int n, double voxel_m, const Sdf& sdf) {
  std::vector<std::array<int, 3>> cubes;
  for (int x = 0; x + 1 < n; ++x)
    for (int y = 0; y + 1 < n; ++y)
      for (int z = 0; z + 1 < n; ++z) cubes.push_back({x, y, z});
  const auto sample = [&](const std::array<int, 3>& g, float& d) {
    d = static_cast<float>(sdf(voxel_m * Eigen::Vector3d(g[0], g[1], g[2])));
    return true;
  };
  return MarchingCubes::extract(cubes, sample, Eigen::Vector3d::Zero(), voxel_m);
}

TEST(MarchingCubes, SphereIsClosedOnTheSurfaceAndEnclosesItsVolume) {
  constexpr double kVoxelM = 0.0005, kRadiusM = 0.005;
  const Eigen::Vector3d centre(0.01013, 0.00987, 0.01021);  // off the grid's symmetry
  const TriangleMesh mesh =
      meshOf(41, kVoxelM, [&](const Eigen::Vector3d& p) { return (p - centre).norm() - kRadiusM; });
  ASSERT_GT(mesh.triangles.size(), 1000u);
  const MeshStats stats = analyse(mesh);
  EXPECT_TRUE(stats.closed_and_oriented);
  EXPECT_EQ(stats.euler, 2);
  double worst_m = 0.0;
  for (const auto& v : mesh.vertices_m)
    worst_m = std::max(worst_m, std::abs((v.cast<double>() - centre).norm() - kRadiusM));
  // Linear interpolation of the exact distance along an edge: off by ~h^2 / (8 r) at most.
  EXPECT_LT(worst_m, 2e-5);
  const double exact = 4.0 / 3.0 * std::numbers::pi * std::pow(kRadiusM, 3);
  EXPECT_NEAR(stats.volume, exact, 0.01 * exact);  // positive: normals point out
}

TEST(MarchingCubes, TorusAndTouchingSpheresResolveAmbiguousFacesWithoutCracks) {
  constexpr double kVoxelM = 0.0005;
  const Eigen::Vector3d c(0.01, 0.0101, 0.0099);
  // A thin torus (genus 1: Euler characteristic 0) exercises ambiguous faces along its tube.
  const TriangleMesh torus = meshOf(41, kVoxelM, [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d q = p - c;
    const double ring = std::hypot(q.x(), q.y()) - 0.006;
    return std::hypot(ring, q.z()) - 0.0012;
  });
  const MeshStats t = analyse(torus);
  EXPECT_TRUE(t.closed_and_oriented);
  EXPECT_EQ(t.euler, 0);
  EXPECT_GT(t.volume, 0.0);
  // Two spheres a fraction of a voxel apart: two closed components (Euler characteristic 4).
  const TriangleMesh pair = meshOf(41, kVoxelM, [&](const Eigen::Vector3d& p) {
    const double a = (p - (c - Eigen::Vector3d(0.0042, 0, 0))).norm() - 0.004;
    const double b = (p - (c + Eigen::Vector3d(0.0042, 0, 0))).norm() - 0.004;
    return std::min(a, b);
  });
  const MeshStats s = analyse(pair);
  EXPECT_TRUE(s.closed_and_oriented);
  EXPECT_EQ(s.euler, 4);
}

TEST(MarchingCubes, UnobservedVoxelsLeaveHolesNotGarbage) {
  const Eigen::Vector3d centre(0.0051, 0.0049, 0.0052);
  std::vector<std::array<int, 3>> cubes;
  for (int x = 0; x < 20; ++x)
    for (int y = 0; y < 20; ++y)
      for (int z = 0; z < 20; ++z) cubes.push_back({x, y, z});
  const auto sample = [&](const std::array<int, 3>& g, float& d) {
    if (g[2] > 12) return false;  // the top was never seen
    d = static_cast<float>((0.0005 * Eigen::Vector3d(g[0], g[1], g[2]) - centre).norm() - 0.003);
    return true;
  };
  const TriangleMesh mesh = MarchingCubes::extract(cubes, sample, Eigen::Vector3d::Zero(), 0.0005);
  ASSERT_FALSE(mesh.triangles.empty());
  for (const auto& v : mesh.vertices_m) EXPECT_LE(v.z(), 0.0005f * 12 + 1e-6f);
  EXPECT_FALSE(analyse(mesh).closed_and_oriented);  // an open cap
}

TEST(MarchingCubes, TsdfMeshOfViewedSphereLiesOnIt) {
  const Eigen::Vector3d centre(0.02, -0.01, 0.3);
  constexpr double kRadiusM = 0.006;
  const std::vector<Eigen::Vector4d> spheres = {{centre.x(), centre.y(), centre.z(), kRadiusM}};
  TsdfVolume volume({}, Eigen::AlignedBox3d(centre.array() - 0.02, centre.array() + 0.02));
  for (const double angle : {-0.6, 0.0, 0.6}) {
    const Eigen::Vector3d eye =
        centre + 0.25 * Eigen::Vector3d(std::sin(angle), 0.0, -std::cos(angle));
    const testing::SphereView v = testing::renderSpheres(spheres, lookAtPose(eye, centre));
    volume.integrate(v.depth, v.mask, v.in, v.T_world_camera);
  }
  const TriangleMesh mesh = volume.extractMesh();
  ASSERT_GT(mesh.triangles.size(), 500u);
  double sum_m = 0.0;
  for (const auto& p : mesh.vertices_m)
    sum_m += std::abs((p.cast<double>() - centre).norm() - kRadiusM);
  const double mean_m = sum_m / mesh.vertices_m.size();
  std::cout << mesh.vertices_m.size() << " vertices, " << mesh.triangles.size()
            << " triangles, mean distance to the sphere " << mean_m * 1e3 << " mm\n";
  EXPECT_LT(mean_m, 1e-4);  // a fifth of a voxel
}

}  // namespace
}  // namespace fvp::host::tsdf
