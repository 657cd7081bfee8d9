#include "fvp/accel/ray_workload.h"

#include "fvp/accel/kernels.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace fvp::accel {
namespace {

struct Vec3 {
  float x, y, z;
};

std::size_t linearIndex(const GridParams& g, int x, int y, int z) {
  return static_cast<std::size_t>(x) +
         static_cast<std::size_t>(g.dim_x) *
             (static_cast<std::size_t>(y) + static_cast<std::size_t>(g.dim_y) * z);
}

// Marks as occupied every voxel whose centre satisfies `inside`, within a box of voxels.
template <typename Inside>
void rasterize(DenseGrid& grid, Vec3 lo, Vec3 hi, Inside&& inside) {
  const GridParams& g = grid.params;
  auto toVoxel = [&](float v, float origin) {
    return static_cast<int>(std::floor((v - origin) / g.voxel_size_m));
  };
  const int x0 = std::max(0, toVoxel(lo.x, g.origin_x_m)),
            x1 = std::min(g.dim_x - 1, toVoxel(hi.x, g.origin_x_m));
  const int y0 = std::max(0, toVoxel(lo.y, g.origin_y_m)),
            y1 = std::min(g.dim_y - 1, toVoxel(hi.y, g.origin_y_m));
  const int z0 = std::max(0, toVoxel(lo.z, g.origin_z_m)),
            z1 = std::min(g.dim_z - 1, toVoxel(hi.z, g.origin_z_m));
  for (int z = z0; z <= z1; ++z)
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const Vec3 c{g.origin_x_m + (x + 0.5f) * g.voxel_size_m,
                     g.origin_y_m + (y + 0.5f) * g.voxel_size_m,
                     g.origin_z_m + (z + 0.5f) * g.voxel_size_m};
        const std::size_t i = linearIndex(g, x, y, z);
        if (grid.occupancy[i] != 0.0f && inside(c)) grid.occupancy[i] = kHitLogOdds;
      }
}

}  // namespace

DenseGrid makeCanopyGrid(int side_voxels, float voxel_size_m, std::uint64_t seed) {
  const float half = 0.5f * side_voxels * voxel_size_m;
  DenseGrid grid;
  grid.params =
      makeGridParams({side_voxels, side_voxels, side_voxels}, {-half, -half, -half}, voxel_size_m);
  const GridParams& g = grid.params;
  const auto n = static_cast<std::size_t>(voxelCount(g));
  grid.occupancy.assign(n, 0.0f);
  grid.field.assign(n, 0.0f);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);

  // Known free space: a ball of radius 0.45 side around the centre.
  const float known_r = 0.45f * side_voxels * voxel_size_m;
  for (int z = 0; z < g.dim_z; ++z)
    for (int y = 0; y < g.dim_y; ++y)
      for (int x = 0; x < g.dim_x; ++x) {
        const float cx = g.origin_x_m + (x + 0.5f) * voxel_size_m;
        const float cy = g.origin_y_m + (y + 0.5f) * voxel_size_m;
        const float cz = g.origin_z_m + (z + 0.5f) * voxel_size_m;
        const std::size_t i = linearIndex(g, x, y, z);
        if (cx * cx + cy * cy + cz * cz < known_r * known_r) grid.occupancy[i] = kMissLogOdds;
        grid.field[i] = 0.5f + 0.5f * unit(rng);
      }

  // Fruitlet shells: spheres of radius 3-8 voxels, one voxel thick, near the centre.
  const float cluster_r = 0.2f * side_voxels * voxel_size_m;
  for (int k = 0; k < 6; ++k) {
    const Vec3 c{(2 * unit(rng) - 1) * cluster_r, (2 * unit(rng) - 1) * cluster_r,
                 (2 * unit(rng) - 1) * cluster_r};
    const float r = (3.0f + 5.0f * unit(rng)) * voxel_size_m;
    const float shell = voxel_size_m;
    rasterize(grid, {c.x - r - shell, c.y - r - shell, c.z - r - shell},
              {c.x + r + shell, c.y + r + shell, c.z + r + shell}, [&](Vec3 p) {
                const float d = std::sqrt((p.x - c.x) * (p.x - c.x) + (p.y - c.y) * (p.y - c.y) +
                                          (p.z - c.z) * (p.z - c.z));
                return std::abs(d - r) < shell;
              });
  }
  // Leaf plates: thin discs of radius 6-12 % of the side, random normal.
  for (int k = 0; k < 4; ++k) {
    const Vec3 c{(2 * unit(rng) - 1) * known_r * 0.6f, (2 * unit(rng) - 1) * known_r * 0.6f,
                 (2 * unit(rng) - 1) * known_r * 0.6f};
    Vec3 nrm{unit(rng) - 0.5f, unit(rng) - 0.5f, unit(rng) - 0.5f};
    const float len = std::sqrt(nrm.x * nrm.x + nrm.y * nrm.y + nrm.z * nrm.z) + 1e-6f;
    nrm = {nrm.x / len, nrm.y / len, nrm.z / len};
    const float r = (0.06f + 0.06f * unit(rng)) * side_voxels * voxel_size_m;
    const float thickness = 0.75f * voxel_size_m;
    rasterize(grid, {c.x - r, c.y - r, c.z - r}, {c.x + r, c.y + r, c.z + r}, [&](Vec3 p) {
      const Vec3 d{p.x - c.x, p.y - c.y, p.z - c.z};
      const float along = d.x * nrm.x + d.y * nrm.y + d.z * nrm.z;
      const float dist2 = d.x * d.x + d.y * d.y + d.z * d.z;
      return std::abs(along) < thickness && dist2 - along * along < r * r;
    });
  }
  return grid;
}

std::vector<Ray> makeRandomRays(const GridParams& g, const RayOptions& options,
                                std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const std::array<float, 3> lo{g.origin_x_m, g.origin_y_m, g.origin_z_m};
  const std::array<float, 3> size{g.dim_x * g.voxel_size_m, g.dim_y * g.voxel_size_m,
                                  g.dim_z * g.voxel_size_m};
  auto inside = [&] {
    return std::array<float, 3>{lo[0] + unit(rng) * size[0], lo[1] + unit(rng) * size[1],
                                lo[2] + unit(rng) * size[2]};
  };
  std::vector<Ray> rays;
  rays.reserve(options.count);
  for (std::size_t i = 0; i < options.count; ++i) {
    std::array<float, 3> origin = inside();
    if (unit(rng) < options.outside_fraction) {
      // A camera 0.5-1.5 grid sides from the centre, in a random direction.
      std::normal_distribution<float> gauss;
      std::array<float, 3> dir{gauss(rng), gauss(rng), gauss(rng)};
      const float len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]) + 1e-6f;
      const float dist = (0.5f + unit(rng)) * std::max({size[0], size[1], size[2]});
      for (int a = 0; a < 3; ++a) origin[a] = lo[a] + 0.5f * size[a] + dir[a] / len * dist;
    }
    rays.push_back(makeRay(origin, inside()));
  }
  return rays;
}

std::vector<RayResult> traverseOnBackend(Backend& backend, const DenseGrid& grid,
                                         const std::vector<Ray>& rays, float occupied_threshold) {
  TraverseParams params{};
  params.grid = grid.params;
  params.occupied_threshold = occupied_threshold;
  params.ray_count = static_cast<unsigned>(rays.size());
  auto occupancy = backend.createBufferFrom(grid.occupancy);
  auto field = backend.createBufferFrom(grid.field);
  auto ray_buffer = backend.createBufferFrom(rays);
  auto results = backend.createBuffer(rays.size() * sizeof(RayResult));
  backend.run(kernels::rayTraverse(), params,
              {ray_buffer.get(), occupancy.get(), field.get(), results.get()});
  return backend.downloadAll<RayResult>(*results);
}

std::uint64_t totalSteps(const std::vector<RayResult>& results) {
  std::uint64_t steps = 0;
  for (const auto& r : results) steps += r.steps;
  return steps;
}

}  // namespace fvp::accel
