// BM_SnapshotRefresh/grid/<backend>/<updated|full>/r<radius_mm>: the information-gain
// snapshot after one more view of simulated world 1, updated from the bricks the view changed
// (InfoGainEvaluator::refresh on the same evaluator) or built whole (a fresh evaluator), with
// its upload to the backend's device. Each iteration first integrates the next of three orbit
// views (90 degree arc) and updates the map's ROI distance field, untimed: the time is the
// snapshot's alone (manual timing), the distance field is reported beside it (distance_ms).
// The Cluster Region's radius sets the fine map's size (40, 65 = the world's own, 100 mm),
// so the two modes show how the cost scales with the changed bricks against the map. Every
// run checks the updated snapshot, host and device copies, against a fresh build byte for
// byte. bytes_per_second: snapshot bytes rewritten (2 per fine, 1 per coarse voxel of the
// rewritten bricks) per second.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "bench_common.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/planner/info_gain_evaluator.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"

namespace fvp::bench {
namespace {

using host::planner::InfoGainEvaluator;

struct Views {
  std::vector<host::LabeledClouds> clouds;  ///< three perceived orbit views
  host::ClusterRegion region;               ///< from the first view that saw the tag
  host::map::MapConfig config;
};

const Views& views() {
  static const Views v = [] {
    const auto world = robot::sim::World::generate(robot::sim::WorldConfig{}, 1);
    const robot::sim::StereoRenderer renderer(world);
    host::PerceptionPipeline perception;
    Views out;
    std::optional<host::ClusterRegion> region;
    for (const Eigen::Isometry3d& pose : robot::sim::orbitViews(world, 3, 90.0)) {
      const host::PerceptionResult perceived = perception.process(renderer.render(pose));
      if (!region && perceived.region) region = perceived.region;
      out.clouds.push_back(perceived.clouds);
    }
    if (!region) throw std::runtime_error("BM_SnapshotRefresh: no Cluster Region");
    out.region = *region;
    const Eigen::Vector3d c = world.clusterCenter_m();
    out.config.observation_min_m = c.array() - 0.6;
    out.config.observation_max_m = c.array() + 0.6;
    return out;
  }();
  return v;
}

bool sameSnapshot(const InfoGainEvaluator& a, const InfoGainEvaluator& fresh) {
  const auto eq = [](auto x, auto y) { return std::equal(x.begin(), x.end(), y.begin(), y.end()); };
  bool same = eq(a.fineWords(), fresh.fineWords()) && eq(a.coarseWords(), fresh.coarseWords());
  if (std::string(a.walkDevice()) != "host")
    same = same && eq(a.deviceFineWords(), fresh.fineWords()) &&
           eq(a.deviceCoarseWords(), fresh.coarseWords());
  return same;
}

void BM_SnapshotRefresh(benchmark::State& state, accel::BackendKind kind, bool updated,
                        double radius_m) {
  auto backend = backendOrSkip(state, kind);
  if (!backend) return;
  const Views& v = views();
  const host::ClusterRegion region(v.region.center_m(), radius_m);
  auto map = host::map::createMapEngine("grid", v.config, region, backend.get());
  const host::planner::InfoGainConfig config;
  InfoGainEvaluator evaluator(config, backend.get());
  map->integrate(v.clouds[0]);
  evaluator.refresh(*map);
  std::size_t view = 1;
  double fine_bricks = 0, coarse_bricks = 0, upload_bytes = 0, distance_s = 0, rewritten = 0;
  for (auto _ : state) {
    map->integrate(v.clouds[view++ % v.clouds.size()]);
    const auto t0 = std::chrono::steady_clock::now();
    map->updateRoiDistance(config.max_d_m);
    distance_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    InfoGainEvaluator fresh(config, backend.get());
    InfoGainEvaluator& refreshed = updated ? evaluator : fresh;
    refreshed.refresh(*map);
    const host::planner::SnapshotRefreshStats& r = refreshed.lastRefresh();
    state.SetIterationTime(r.snapshot_s);
    fine_bricks += double(r.fine_bricks);
    coarse_bricks += double(r.coarse_bricks);
    upload_bytes += double(r.upload_bytes);
    rewritten += 512.0 * (2.0 * double(r.fine_bricks) + double(r.coarse_bricks));
  }
  InfoGainEvaluator check(config);
  check.refresh(*map);
  if (updated && !sameSnapshot(evaluator, check)) {
    state.SkipWithError("the updated snapshot differs from a fresh build");
    return;
  }
  const double n = double(state.iterations());
  state.SetBytesProcessed(static_cast<int64_t>(rewritten));
  state.counters["fine_bricks"] = fine_bricks / n;
  state.counters["coarse_bricks"] = coarse_bricks / n;
  state.counters["upload_MB"] = upload_bytes / n / 1e6;
  state.counters["snapshot_MB"] = double(evaluator.snapshotBytes()) / 1e6;
  state.counters["distance_ms"] = 1e3 * distance_s / n;
}

void registerAll() {
  for (accel::BackendKind kind :
       {accel::BackendKind::kCpu, accel::BackendKind::kOpenCl, accel::BackendKind::kVulkan})
    for (bool updated : {true, false})
      for (int radius_mm : {40, 65, 100}) {
        const std::string name = "BM_SnapshotRefresh/grid/" + std::string(accel::toString(kind)) +
                                 (updated ? "/updated" : "/full") + "/r" +
                                 std::to_string(radius_mm);
        benchmark::RegisterBenchmark(name.c_str(), BM_SnapshotRefresh, kind, updated,
                                     radius_mm / 1000.0)
            ->Iterations(6)
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond);
      }
}

const bool kRegistered = (registerAll(), true);

}  // namespace
}  // namespace fvp::bench
