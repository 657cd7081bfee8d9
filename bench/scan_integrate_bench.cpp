// BM_ScanIntegrate: one simulated frame (the start view of world seed 1, rendered and run
// through the perception chain: its ROI + non-ROI clouds) into a fresh coarse (1 cm) +
// fine (1 mm, Cluster Region) map pair: the grid engine on every backend and the octomap
// engine, same data, same run. items_per_second = points.
// BM_ScanIntegrateFineBox: RVP's case, one 1 mm map over the whole observation box, for
// the grid engine (bricks allocated as rays reach them), OctoMap's OcTree, and the octomap
// engine as RVP's trials run it (fine_map_extent observation_box).
#include <benchmark/benchmark.h>
#include <octomap/OcTree.h>

#include <memory>
#include <string>

#include "bench_common.h"
#include "fvp/accel/backend.h"
#include "fvp/host/map/grid_map_engine.h"
#include "fvp/host/map/octomap_map_engine.h"
#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"

namespace fvp::bench {
namespace {

using accel::BackendKind;
using host::map::GridMapEngine;
using host::map::MapConfig;
using host::map::OctomapMapEngine;

constexpr std::uint64_t kWorldSeed = 1;
constexpr double kObservationHalfExtentM = 0.6;  // around the cluster: camera and canopy

struct Frame {
  host::LabeledClouds clouds;
  host::ClusterRegion region;
  MapConfig config;
  std::size_t points() const { return clouds.roi_points_m.size() + clouds.other_points_m.size(); }
};

const Frame& frame() {
  static const Frame f = [] {
    const auto world = robot::sim::World::generate(robot::sim::WorldConfig{}, kWorldSeed);
    const robot::sim::StereoRenderer renderer(world);
    const host::StereoFrame stereo = renderer.render(world.startCameraPose());
    const host::PerceptionResult perceived = host::PerceptionPipeline().process(stereo);
    if (!perceived.region)
      throw std::runtime_error("benchmark frame: no Cluster Region (tag not seen)");
    Frame out;
    out.clouds = perceived.clouds;
    out.region = *perceived.region;
    const Eigen::Vector3d c = world.clusterCenter_m();
    out.config.observation_min_m = c.array() - kObservationHalfExtentM;
    out.config.observation_max_m = c.array() + kObservationHalfExtentM;
    return out;
  }();
  return f;
}

// Reference result (cpu grid engine) to check every run against.
const host::map::ScanStats& reference() {
  static const host::map::ScanStats stats = [] {
    auto cpu = accel::createBackend(BackendKind::kCpu);
    GridMapEngine map(frame().config, frame().region, *cpu);
    return map.integrate(frame().clouds);
  }();
  return stats;
}

void BM_ScanIntegrateGrid(benchmark::State& state, BackendKind kind) {
  auto backend = backendOrSkip(state, kind);
  if (!backend) return;
  const Frame& f = frame();
  host::map::ScanStats stats;
  std::size_t map_bytes = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto map = std::make_unique<GridMapEngine>(f.config, f.region, *backend);
    state.ResumeTiming();
    stats = map->integrate(f.clouds);
    state.PauseTiming();
    map_bytes = map->coarse().bricks().deviceBytes() + map->fine().bricks().deviceBytes();
    map.reset();
    state.ResumeTiming();
  }
  if (stats.coarse_voxels_updated != reference().coarse_voxels_updated ||
      stats.fine_voxels_updated != reference().fine_voxels_updated) {
    state.SkipWithError("voxel updates differ from the cpu reference");
    return;
  }
  state.SetItemsProcessed(static_cast<int64_t>(f.points()) * state.iterations());
  state.counters["points"] = static_cast<double>(f.points());
  state.counters["voxel_updates"] =
      static_cast<double>(stats.coarse_voxels_updated + stats.fine_voxels_updated);
  state.counters["map_MB"] = map_bytes / 1e6;
  state.SetLabel(backend->deviceName());
}

void BM_ScanIntegrateOctomap(benchmark::State& state) {
  const Frame& f = frame();
  host::map::ScanStats stats;
  std::size_t map_bytes = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto map = std::make_unique<OctomapMapEngine>(f.config, f.region);
    state.ResumeTiming();
    stats = map->integrate(f.clouds);
    state.PauseTiming();
    map_bytes = map->coarseTree().memoryUsage() + map->fineTree().memoryUsage();
    map.reset();
    state.ResumeTiming();
  }
  // Same semantics: the voxel updates agree with the grid engine's to within near-ties.
  const double want =
      static_cast<double>(reference().fine_voxels_updated + reference().coarse_voxels_updated);
  const double got = static_cast<double>(stats.fine_voxels_updated + stats.coarse_voxels_updated);
  if (std::abs(got - want) > 1e-3 * want) {
    state.SkipWithError("octomap engine's voxel updates differ from the grid engine's by > 0.1 %");
    return;
  }
  state.SetItemsProcessed(static_cast<int64_t>(f.points()) * state.iterations());
  state.counters["points"] = static_cast<double>(f.points());
  state.counters["voxel_updates"] = got;
  state.counters["map_MB"] = map_bytes / 1e6;
  state.SetLabel("OcTree 1 cm + RoiOcTree 1 mm, key sets built on all cores (OpenMP)");
}

// RVP's case: one 1 mm occupancy + ROI map over the whole observation box.
host::map::GridGeometry fineBoxGeometry() {
  MapConfig box = frame().config;
  box.coarse_voxel_size_m = 0.001;
  return host::map::coarseGridGeometry(box);
}

void BM_ScanIntegrateFineBoxGrid(benchmark::State& state, BackendKind kind) {
  auto backend = backendOrSkip(state, kind);
  if (!backend) return;
  const Frame& f = frame();
  host::map::ScanStats prep;
  const auto points = host::map::prepareScanPoints(f.clouds, f.config.sensor_max_range_m, prep);
  auto buffer = backend->createBufferFrom(points);
  const host::map::OccupancyModel model;
  std::size_t updated = 0, bricks = 0, bytes = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto grid = std::make_unique<host::map::OccupancyLayer>(
        *backend, fineBoxGeometry(), true, std::nullopt, host::map::BrickAllocation::kOnTouch);
    host::map::ScanIntegrator integrator(*grid);
    state.ResumeTiming();
    updated = integrator.integrate(*buffer, static_cast<std::uint32_t>(points.size()),
                                   f.clouds.sensor_origin_m.cast<float>(), model);
    state.PauseTiming();
    bricks = grid->bricks().allocatedBricks();
    bytes = grid->bricks().deviceBytes();
    grid.reset();
    state.ResumeTiming();
  }
  state.SetItemsProcessed(static_cast<int64_t>(points.size()) * state.iterations());
  state.counters["voxel_updates"] = static_cast<double>(updated);
  state.counters["bricks"] = static_cast<double>(bricks);
  state.counters["map_MB"] = bytes / 1e6;
  state.SetLabel(backend->deviceName());
}

void BM_ScanIntegrateFineBoxOctomap(benchmark::State& state) {
  const Frame& f = frame();
  octomap::Pointcloud cloud;
  for (const auto* c : {&f.clouds.roi_points_m, &f.clouds.other_points_m})
    for (const auto& p : *c) cloud.push_back(p.x(), p.y(), p.z());
  const octomap::point3d origin(f.clouds.sensor_origin_m.x(), f.clouds.sensor_origin_m.y(),
                                f.clouds.sensor_origin_m.z());
  std::size_t leaves = 0, bytes = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto tree = std::make_unique<octomap::OcTree>(0.001);
    state.ResumeTiming();
    tree->insertPointCloud(cloud, origin, f.config.sensor_max_range_m);
    state.PauseTiming();
    leaves = tree->getNumLeafNodes();
    bytes = tree->memoryUsage();
    tree.reset();
    state.ResumeTiming();
  }
  state.SetItemsProcessed(static_cast<int64_t>(cloud.size()) * state.iterations());
  state.counters["leaves"] = static_cast<double>(leaves);
  state.counters["map_MB"] = bytes / 1e6;
  state.SetLabel("octomap::OcTree 1 mm insertPointCloud (no ROI), 1 thread");
}

// RVP's map as the trials run it: the octomap engine with fine_map_extent observation_box
// (1 cm coarse tree + one 1 mm RoiOcTree over the whole box), same frame. Checked: its fine
// voxel updates within 0.1 % of the grid engine's walk over the same 1 mm box (the coarse
// grid's, a little larger than BM_ScanIntegrateFineBox's), same rays and cut.
void BM_ScanIntegrateFineBoxOctomapEngine(benchmark::State& state) {
  const Frame& f = frame();
  MapConfig config = f.config;
  config.fine_map_extent = host::map::FineMapExtent::kObservationBox;
  host::map::ScanStats stats;
  std::size_t bytes = 0, leaves = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto map = std::make_unique<OctomapMapEngine>(config, f.region);
    state.ResumeTiming();
    stats = map->integrate(f.clouds);
    state.PauseTiming();
    bytes = map->coarseTree().memoryUsage() + map->fineTree().memoryUsage();
    leaves = map->fineTree().getNumLeafNodes();
    map.reset();
    state.ResumeTiming();
  }
  // The grid engine's whole-box walk on the same points is the reference count.
  static const std::size_t want = [] {
    auto cpu = accel::createBackend(BackendKind::kCpu);
    host::map::ScanStats prep;
    const auto points =
        host::map::prepareScanPoints(frame().clouds, frame().config.sensor_max_range_m, prep);
    auto buffer = cpu->createBufferFrom(points);
    // The engine's box: the coarse grid's (snapped to whole coarse bricks) at 1 mm.
    host::map::GridGeometry box = host::map::coarseGridGeometry(frame().config);
    const int ratio = static_cast<int>(
        std::lround(frame().config.coarse_voxel_size_m / frame().config.fine_voxel_size_m));
    box.voxel_size_m = frame().config.fine_voxel_size_m;
    for (int a = 0; a < 3; ++a) {
      box.first_voxel[a] *= ratio;
      box.dims[a] *= ratio;
    }
    host::map::OccupancyLayer grid(*cpu, box, true, std::nullopt,
                                   host::map::BrickAllocation::kOnTouch);
    return host::map::ScanIntegrator(grid).integrate(
        *buffer, static_cast<std::uint32_t>(points.size()),
        frame().clouds.sensor_origin_m.cast<float>(), host::map::OccupancyModel{});
  }();
  const double got = static_cast<double>(stats.fine_voxels_updated);
  if (std::abs(got - double(want)) > 1e-3 * double(want)) {
    state.SkipWithError("fine voxel updates differ from the grid engine's 1 mm box by > 0.1 %");
    return;
  }
  state.SetItemsProcessed(static_cast<int64_t>(f.points()) * state.iterations());
  state.counters["voxel_updates"] = got;
  state.counters["leaves"] = static_cast<double>(leaves);
  state.counters["map_MB"] = bytes / 1e6;
  state.SetLabel(
      "octomap engine, fine_map_extent observation_box (RVP's map), flat key sets, Morton-ordered "
      "lazy updates");
}

// One planning iteration's map work after a view (docs/design.md section 5): integrate the view,
// recompute the ROI distance field (paper Eq. 1, max_d 2 cm), extract the frontiers and
// bring both Embree scenes up to date. Steady state: the map already holds the start view
// (set up untimed), and the step integrates it again, as a robot holding still would.
constexpr double kMapStepMaxDM = 0.02;

struct MapStepResult {
  host::map::ScanStats scan;
  std::size_t frontiers = 0, coarse_occupied = 0, fine_occupied = 0;
};

MapStepResult mapStep(host::map::MapEngine& map, const Frame& f) {
  MapStepResult r;
  r.scan = map.integrate(f.clouds);
  map.updateRoiDistance(kMapStepMaxDM);
  r.frontiers = map.frontiers().size();
  r.coarse_occupied = map.occupiedScene(host::map::MapLevel::kCoarse).occupiedCount();
  r.fine_occupied = map.occupiedScene(host::map::MapLevel::kFine).occupiedCount();
  return r;
}

const MapStepResult& mapStepReference() {
  static const MapStepResult r = [] {
    auto cpu = accel::createBackend(BackendKind::kCpu);
    GridMapEngine map(frame().config, frame().region, *cpu);
    mapStep(map, frame());
    return mapStep(map, frame());
  }();
  return r;
}

void BM_MapStep(benchmark::State& state, const std::string& engine, BackendKind kind) {
  std::unique_ptr<accel::Backend> backend;
  if (engine == "grid") {
    backend = backendOrSkip(state, kind);
    if (!backend) return;
  }
  const Frame& f = frame();
  MapStepResult result;
  accel::TransferCounters moved{};
  std::uint64_t waits = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto map = host::map::createMapEngine(engine, f.config, f.region, backend.get());
    mapStep(*map, f);
    if (backend) backend->resetTransfers();
    const std::uint64_t waits_before = backend ? backend->deviceWaits() : 0;
    state.ResumeTiming();
    result = mapStep(*map, f);
    state.PauseTiming();
    if (backend) moved = backend->transfers();
    if (backend) waits = backend->deviceWaits() - waits_before;
    map.reset();
    state.ResumeTiming();
  }
  const MapStepResult& want = mapStepReference();
  // The grid engine matches the cpu reference exactly; the octomap engine within near-ties.
  const auto close = [&](std::size_t got, std::size_t ref) {
    const double tolerance = engine == "grid" ? 0.0 : 1e-3 * static_cast<double>(ref);
    return std::abs(static_cast<double>(got) - static_cast<double>(ref)) <= tolerance;
  };
  if (!close(result.scan.fine_voxels_updated, want.scan.fine_voxels_updated) ||
      !close(result.frontiers, want.frontiers) ||
      !close(result.fine_occupied, want.fine_occupied) ||
      !close(result.coarse_occupied, want.coarse_occupied)) {
    state.SkipWithError("map step differs from the cpu grid engine's");
    return;
  }
  state.SetItemsProcessed(static_cast<int64_t>(f.points()) * state.iterations());
  state.counters["frontiers"] = static_cast<double>(result.frontiers);
  state.counters["upload_MB"] = moved.upload_bytes / 1e6;
  state.counters["download_MB"] = moved.download_bytes / 1e6;
  state.counters["transfers"] = static_cast<double>(moved.uploads + moved.downloads);
  state.counters["device_waits"] = static_cast<double>(waits);
  state.SetLabel(backend ? backend->deviceName() : "OcTree + RoiOcTree + DynamicEDTOctomap");
}

void registerAll() {
  for (BackendKind kind : {BackendKind::kCpu, BackendKind::kOpenCl, BackendKind::kVulkan}) {
    const std::string b(accel::toString(kind));
    benchmark::RegisterBenchmark(("BM_ScanIntegrate/grid/" + b).c_str(), BM_ScanIntegrateGrid, kind)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  benchmark::RegisterBenchmark("BM_ScanIntegrate/octomap/cpu", BM_ScanIntegrateOctomap)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(2);
  for (BackendKind kind : {BackendKind::kCpu, BackendKind::kOpenCl, BackendKind::kVulkan}) {
    const std::string b(accel::toString(kind));
    benchmark::RegisterBenchmark(("BM_ScanIntegrateFineBox/grid/" + b).c_str(),
                                 BM_ScanIntegrateFineBoxGrid, kind)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  benchmark::RegisterBenchmark("BM_ScanIntegrateFineBox/octomap/cpu",
                               BM_ScanIntegrateFineBoxOctomap)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(1);
  benchmark::RegisterBenchmark("BM_ScanIntegrateFineBox/octomap-engine/cpu",
                               BM_ScanIntegrateFineBoxOctomapEngine)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(1);
  for (BackendKind kind : {BackendKind::kCpu, BackendKind::kOpenCl, BackendKind::kVulkan}) {
    const std::string b(accel::toString(kind));
    benchmark::RegisterBenchmark(("BM_MapStep/grid/" + b).c_str(), BM_MapStep, "grid", kind)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  benchmark::RegisterBenchmark("BM_MapStep/octomap/cpu", BM_MapStep, "octomap", BackendKind::kCpu)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(2);
}

const bool registered = (registerAll(), true);

}  // namespace
}  // namespace fvp::bench
