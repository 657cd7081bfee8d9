// BM_RayTraverse: batched voxel ray traversal on a 1 mm canopy grid (the fine map's
// case), ours on every backend and OctoMap (computeRayKeys + search on an OcTree holding
// the same occupancy) on the same rays, in the same run. items_per_second = voxel steps.
#include <benchmark/benchmark.h>
#include <octomap/OcTree.h>
#include <omp.h>

#include <map>
#include <memory>
#include <string>

#include "bench_common.h"
#include "fvp/accel/backend.h"
#include "fvp/accel/kernels.h"
#include "fvp/accel/ray_workload.h"

namespace fvp::bench {
namespace {

using accel::Backend;
using accel::BackendKind;
using accel::DenseGrid;
using accel::Ray;
using accel::RayResult;

constexpr int kSideVoxels = 160;  // 16 cm cube at 1 mm: a Cluster Region
constexpr float kVoxelSizeM = 0.001f;
constexpr std::uint64_t kWorkloadSeed = 7;

struct Workload {
  DenseGrid grid;
  std::map<std::size_t, std::vector<Ray>> rays;             // by count
  std::map<std::size_t, std::vector<RayResult>> reference;  // cpu results by count

  const std::vector<Ray>& raysFor(std::size_t n) {
    auto it = rays.find(n);
    if (it == rays.end())
      it = rays.emplace(n, accel::makeRandomRays(grid.params, {n, 0.0f}, kWorkloadSeed + n)).first;
    return it->second;
  }
  const std::vector<RayResult>& referenceFor(std::size_t n) {
    auto it = reference.find(n);
    if (it == reference.end()) {
      auto cpu = accel::createBackend(BackendKind::kCpu);
      it = reference.emplace(n, accel::traverseOnBackend(*cpu, grid, raysFor(n))).first;
    }
    return it->second;
  }
};

Workload& workload() {
  static Workload w{accel::makeCanopyGrid(kSideVoxels, kVoxelSizeM, kWorkloadSeed), {}, {}};
  return w;
}

// The same occupancy in an OcTree at the same resolution: every known voxel of the grid
// is set with its log-odds. The grid's origin lies on OctoMap's key lattice.
octomap::OcTree& octree() {
  static std::unique_ptr<octomap::OcTree> tree = [] {
    const DenseGrid& grid = workload().grid;
    const auto& g = grid.params;
    auto t = std::make_unique<octomap::OcTree>(g.voxel_size_m);
    t->setOccupancyThres(octomap::probability(accel::kDefaultOccupiedThreshold));
    for (int z = 0; z < g.dim_z; ++z)
      for (int y = 0; y < g.dim_y; ++y)
        for (int x = 0; x < g.dim_x; ++x) {
          const float v = grid.occupancy[x + g.dim_x * (y + static_cast<std::size_t>(g.dim_y) * z)];
          if (v == 0.0f) continue;  // unknown: not in the tree
          const octomap::point3d c(g.origin_x_m + (x + 0.5f) * g.voxel_size_m,
                                   g.origin_y_m + (y + 0.5f) * g.voxel_size_m,
                                   g.origin_z_m + (z + 0.5f) * g.voxel_size_m);
          t->setNodeValue(t->coordToKey(c), v, /*lazy_eval=*/true);
        }
    t->updateInnerOccupancy();
    return t;
  }();
  return *tree;
}

// The peer's walk: OctoMap's ray keys plus the end key (ours includes the end voxel),
// each looked up until the first occupied node. Returns voxel steps.
std::uint64_t octomapTraverse(octomap::OcTree& tree, const Ray& ray, octomap::KeyRay& keys) {
  const octomap::point3d o(ray.origin_m[0], ray.origin_m[1], ray.origin_m[2]);
  const octomap::point3d e(ray.end_m[0], ray.end_m[1], ray.end_m[2]);
  tree.computeRayKeys(o, e, keys);
  std::uint64_t steps = 0;
  for (const auto& key : keys) {
    ++steps;
    const octomap::OcTreeNode* node = tree.search(key);
    if (node && tree.isNodeOccupied(node)) return steps;
  }
  ++steps;
  return steps;
}

void BM_RayTraverseGrid(benchmark::State& state, BackendKind kind, int threads) {
  const auto n = static_cast<std::size_t>(state.range(0));
  auto backend = backendOrSkip(state, kind);
  if (!backend) return;
  OmpThreadsScope omp_threads(threads);
  Workload& w = workload();
  const auto& rays = w.raysFor(n);
  const auto& reference = w.referenceFor(n);
  // Upload once: the maps live on the device between planning queries.
  auto occupancy = backend->createBufferFrom(w.grid.occupancy);
  auto field = backend->createBufferFrom(w.grid.field);
  auto ray_buffer = backend->createBufferFrom(rays);
  auto results = backend->createBuffer(n * sizeof(RayResult));
  accel::TraverseParams params{w.grid.params, accel::kDefaultOccupiedThreshold,
                               static_cast<unsigned>(n)};
  std::vector<RayResult> out(n);
  for (auto _ : state) {
    backend->run(accel::kernels::rayTraverse(), params,
                 {ray_buffer.get(), occupancy.get(), field.get(), results.get()});
    backend->download(*results, out.data(), n * sizeof(RayResult));
    benchmark::DoNotOptimize(out.data());
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (out[i].steps != reference[i].steps || out[i].stop_voxel != reference[i].stop_voxel) {
      state.SkipWithError("result differs from the cpu reference");
      return;
    }
  }
  const auto steps = accel::totalSteps(out);
  setThroughput(state, steps, n);
  state.counters["map_MB"] = 2.0 * sizeof(float) * accel::voxelCount(w.grid.params) / 1e6;
  state.SetLabel(backend->deviceName());
}

void BM_RayTraverseOctomap(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Workload& w = workload();
  const auto& rays = w.raysFor(n);
  const auto& reference = w.referenceFor(n);
  octomap::OcTree& tree = octree();
  octomap::KeyRay keys;
  std::uint64_t steps = 0;
  std::size_t agree = 0;
  for (auto _ : state) {
    steps = 0;
    agree = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint64_t s = octomapTraverse(tree, rays[i], keys);
      steps += s;
      agree += (s == reference[i].steps);
    }
    benchmark::DoNotOptimize(steps);
  }
  // Same walk, same stop: allow the rare end point that float and double quantise apart.
  if (agree < n - n / 1000) {
    state.SkipWithError("OctoMap's walk disagrees with ours on more than 0.1 % of rays");
    return;
  }
  setThroughput(state, steps, n);
  state.counters["map_MB"] = tree.memoryUsage() / 1e6;
  state.counters["agree_pct"] = 100.0 * agree / n;
  state.SetLabel("octomap::OcTree computeRayKeys + search, 1 thread");
}

void registerAll() {
  for (int64_t rays : {10000, 100000}) {
    for (BackendKind kind : {BackendKind::kCpu, BackendKind::kOpenCl, BackendKind::kVulkan}) {
      const std::string name = "BM_RayTraverse/grid/" + std::string(accel::toString(kind));
      benchmark::RegisterBenchmark(name.c_str(), BM_RayTraverseGrid, kind, 0)
          ->Arg(rays)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    }
    benchmark::RegisterBenchmark("BM_RayTraverse/grid/cpu-1thread", BM_RayTraverseGrid,
                                 BackendKind::kCpu, 1)
        ->Arg(rays)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark("BM_RayTraverse/octomap/cpu-1thread", BM_RayTraverseOctomap)
        ->Arg(rays)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
}

const bool registered = (registerAll(), true);

}  // namespace
}  // namespace fvp::bench
