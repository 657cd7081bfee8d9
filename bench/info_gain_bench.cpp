// BM_InfoGain/<engine or peer>/<backend>/<mode>/<candidates>: paper Eq. 1-2 for a batch of
// viewpoint candidates on the map of a real simulated sequence (world 1, three views over a
// 90 degree arc), our snapshot walk (the info_gain kernel on cpu, opencl or vulkan) against
// the paper's way: OctoMap's computeRayKeys and OcTree::search per voxel on the coarse tree
// and a 1 mm fine tree, with d_i from the engine's distance field. Both run in the same
// program on the same candidates. Every grid run must equal the host walk exactly; the peer
// must agree with it on >= 95 % of candidates (the two walks differ at voxel-boundary
// near-ties and OctoMap's key ray leaves out its end voxel).
#include <benchmark/benchmark.h>
#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>

#include "bench_common.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/planner/info_gain_evaluator.h"
#include "fvp/host/planner/viewpoint_sampler.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/simulated_mapping.h"

namespace fvp::bench {
namespace {

using host::planner::GainMode;
using host::planner::ViewQuery;

struct Scene {
  std::unique_ptr<accel::Backend> backend;
  std::unique_ptr<host::map::MapEngine> map;
  std::vector<ViewQuery> queries;         ///< 100 000, the FVP samplers' candidates
  std::unique_ptr<octomap::OcTree> fine;  ///< the peer's 1 mm tree (occupied / free)
};

Scene& scene() {
  static Scene s = [] {
    Scene out;
    const auto world = robot::sim::World::generate(robot::sim::WorldConfig{}, 1);
    out.backend = accel::createBackend("cpu");
    robot::sim::SimulatedMappingOptions options;
    auto mapped = robot::sim::mapSimulatedViews(world, robot::sim::orbitViews(world, 3, 90.0),
                                                options, out.backend.get());
    if (!mapped.map) throw std::runtime_error("BM_InfoGain: no Cluster Region");
    out.map = std::move(mapped.map);
    const auto frontiers = out.map->frontiers();
    host::planner::ViewpointSampler sampler(host::planner::PlannerConfig{}, 7);
    for (const auto* set : {&frontiers}) {
      const auto roi = sampler.sampleRoi(*set, 50000, nullptr);
      const auto exploration = sampler.sampleExploration(*set, 50000, nullptr);
      for (const auto* list : {&roi, &exploration})
        for (const auto& c : *list) out.queries.push_back({c.T_world_camera, c.target_m});
    }
    // The peer's fine tree: every known voxel of the region with its occupancy.
    const auto& g = out.map->gridGeometry(host::map::MapLevel::kFine);
    out.fine = std::make_unique<octomap::OcTree>(g.voxel_size_m);
    for (int z = 0; z < g.dims[2]; ++z)
      for (int y = 0; y < g.dims[1]; ++y)
        for (int x = 0; x < g.dims[0]; ++x) {
          const Eigen::Vector3d c = g.voxelCenter_m({x, y, z});
          if (!out.map->region().contains(c)) continue;
          const auto st = out.map->fineState(c);
          if (st.occupancy == host::map::VoxelClass::kUnknown) continue;
          out.fine->updateNode(octomap::point3d(c.x(), c.y(), c.z()),
                               st.occupancy == host::map::VoxelClass::kOccupied);
        }
    return out;
  }();
  return s;
}

/// The paper's way: key rays and tree searches, coarse outside the region, fine inside.
host::planner::GainResult octomapGain(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                                      const octomap::OcTree& coarse, const octomap::OcTree& fine,
                                      const host::map::MapEngine& map, double max_d) {
  host::planner::GainResult r;
  const Eigen::Vector3d c = map.region().center_m();
  const double radius = map.region().radius_m();
  const Eigen::Vector3d d = target - eye, f = eye - c;
  const double a = d.squaredNorm(), b = 2 * f.dot(d), cc = f.squaredNorm() - radius * radius;
  const double disc = b * b - 4 * a * cc;
  if (disc < 0) return r;
  const double t = (-b - std::sqrt(disc)) / (2 * a);
  if (t < 0 || t > 1) return r;
  const Eigen::Vector3d entry = eye + t * d;
  const auto pt = [](const Eigen::Vector3d& v) { return octomap::point3d(v.x(), v.y(), v.z()); };
  octomap::KeyRay keys;
  if (coarse.computeRayKeys(pt(eye), pt(entry), keys))
    for (const auto& k : keys) {
      ++r.voxel_steps;
      const octomap::OcTreeNode* n = coarse.search(k);
      if (n && coarse.isNodeOccupied(n)) {
        r.blocked = true;
        return r;
      }
    }
  if (!fine.computeRayKeys(pt(entry), pt(target), keys)) return r;
  const auto& g = map.gridGeometry(host::map::MapLevel::kFine);
  double sum = 0;
  for (const auto& k : keys) {
    ++r.voxel_steps;
    const octomap::point3d p = fine.keyToCoord(k);
    const Eigen::Vector3d pc(p.x(), p.y(), p.z());
    if (!map.region().contains(pc)) continue;
    ++r.region_voxels;
    const octomap::OcTreeNode* n = fine.search(k);
    if (n && fine.isNodeOccupied(n)) break;
    if (!n) {
      std::array<int, 3> index;
      g.gridIndex(pc, index);
      sum += host::planner::roiProximityWeight(map.roiDistance_m(index), max_d);
    }
  }
  if (r.region_voxels) r.ig = sum / r.region_voxels;
  return r;
}

void BM_InfoGain(benchmark::State& state, const std::string& engine, accel::BackendKind kind,
                 GainMode mode, bool embree_cull) {
  Scene& s = scene();
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const std::span<const ViewQuery> queries(s.queries.data(), n);
  host::planner::InfoGainConfig config;
  config.mode = mode;
  // The reference: the same C walk on the host, without a backend.
  host::planner::InfoGainEvaluator reference(config);
  reference.refresh(*s.map);
  const std::vector<host::planner::GainResult> want = reference.evaluate(queries);
  std::unique_ptr<accel::Backend> backend;
  if (engine == "grid" && !(backend = backendOrSkip(state, kind))) return;
  host::planner::InfoGainConfig ours_config = config;
  ours_config.embree_cull = embree_cull;
  host::planner::InfoGainEvaluator ours(ours_config, backend.get());
  // Snapshot build (and upload to the backend's device) is part of each planning iteration.
  const double snapshot_s = ours.refresh(*s.map);
  std::uint64_t steps = 0;
  std::vector<host::planner::GainResult> got;
  host::planner::EvaluateStats stats;
  for (auto _ : state) {
    if (engine == "grid") {
      got = ours.evaluate(queries, &stats);
    } else {
      got.assign(n, {});
      const octomap::OcTree& coarse = s.map->coarseOcTree();
      for (std::size_t i = 0; i < n; ++i)
        got[i] = octomapGain(queries[i].T_world_camera.translation(), queries[i].target_m, coarse,
                             *s.fine, *s.map, config.max_d_m);
    }
    benchmark::DoNotOptimize(got.data());
  }
  steps = 0;
  std::size_t agree = 0, identical = 0;
  for (std::size_t i = 0; i < n; ++i) {
    steps += got[i].voxel_steps;
    agree += std::abs(got[i].ig - want[i].ig) < 0.02;
    // Culled rays are not walked: their steps are not comparable, their gains are.
    identical +=
        got[i].ig == want[i].ig && (embree_cull || got[i].voxel_steps == want[i].voxel_steps);
  }
  // Embree tests faces, the walk voxels: they may disagree on rays grazing a voxel edge.
  if (engine == "grid" && identical < (embree_cull ? 0.99 * n : double(n))) {
    state.SkipWithError("the backend's gains differ from the host walk");
    return;
  }
  if (embree_cull) {
    state.counters["culled_percent"] = 100.0 * stats.culled / std::max<std::size_t>(1, stats.rays);
    state.counters["cull_ms"] = 1e3 * stats.cull_s;
    state.counters["walk_ms"] = 1e3 * stats.walk_s;
    state.counters["identical_percent"] = 100.0 * identical / n;
  }
  if (agree < 0.95 * n) {
    state.SkipWithError("gains disagree with the snapshot walk on more than 5 % of candidates");
    return;
  }
  state.SetItemsProcessed(static_cast<int64_t>(n) * state.iterations());  // viewpoints/s
  state.counters["voxel_steps_per_second"] =
      benchmark::Counter(double(steps) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["agree_percent"] = 100.0 * agree / n;
  state.counters["snapshot_MB"] = ours.snapshotBytes() / 1e6;
  state.counters["snapshot_s"] = snapshot_s;
}

void registerAll() {
  using accel::BackendKind;
  for (GainMode mode : {GainMode::kSingleRay, GainMode::kFrustum}) {
    const std::string m = mode == GainMode::kSingleRay ? "single" : "frustum";
    for (int n : {100, 1000, 10000, 100000})
      for (BackendKind kind : {BackendKind::kCpu, BackendKind::kOpenCl, BackendKind::kVulkan}) {
        const std::string name = "BM_InfoGain/grid/" + std::string(accel::toString(kind)) + "/" +
                                 m + "/" + std::to_string(n);
        benchmark::RegisterBenchmark(name.c_str(), BM_InfoGain, "grid", kind, mode, false)
            ->Arg(n)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
    // The same walk after Embree culls the rays blocked in the coarse map (embree_cull).
    for (int n : {1000, 10000, 100000})
      benchmark::RegisterBenchmark(
          ("BM_InfoGain/grid-embree-cull/cpu/" + m + "/" + std::to_string(n)).c_str(), BM_InfoGain,
          "grid", BackendKind::kCpu, mode, true)
          ->Arg(n)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    if (mode == GainMode::kSingleRay)
      for (int n : {100, 1000, 10000}) {
        benchmark::RegisterBenchmark(
            ("BM_InfoGain/octomap/cpu/" + m + "/" + std::to_string(n)).c_str(), BM_InfoGain,
            "octomap", BackendKind::kCpu, mode, false)
            ->Arg(n)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
  }
}

const bool kRegistered = (registerAll(), true);

}  // namespace
}  // namespace fvp::bench
