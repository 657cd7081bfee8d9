// BM_TsdfIntegrate/fvp/<backend>: projective TSDF integration (0.5 mm, 2 mm truncation) of
// one capture's ROI depth: the start view of world 1, rendered, SGBM disparity -> depth,
// fruitlet mask from the HSV segmentation. Each iteration integrates the view into a fresh
// volume over the Cluster Region's cube (built outside the timed region, as a trial builds it
// once; the band's bricks are allocated inside it, as in a trial's first view). Every run is
// checked against the cpu backend: the same bricks, distances within 1e-6 m on >= 99.99 % of
// voxels. items_per_second counts the ROI depth pixels integrated; voxels_per_second the voxel
// slots updated.
//
// BM_SurfaceExtract/<fvp|open3d>/<points|mesh>, BM_OutlierRemoval/<fvp|open3d>/cpu and
// BM_Dbscan/<fvp|open3d>/cpu: the rest of the sizing front end against Open3D on the same
// frame (see each below).
//
// BM_TsdfIntegrate/open3d/cpu: the peer, Open3D's ScalableTSDFVolume (0.5 mm voxels, 2 mm
// truncation, 8^3-voxel units like our bricks, its default depth sampling stride of 4 for
// finding units) on the same masked depth image, in the same program. Its surface must lie
// within 0.25 mm of ours (mean nearest-neighbour distance both ways, reported as
// chamfer_mm); Open3D weights every observation 1 where we weight 1 / z^2, so surfaces
// agree closely but not exactly.
#include <benchmark/benchmark.h>

#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>
#include <cmath>
#include <map>

#include "bench_common.h"
#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/sizing/fruitlet_sizer.h"
#include "fvp/host/sizing/point_filters.h"
#include "fvp/host/tsdf/tsdf_volume.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"

namespace fvp::bench {
namespace {

struct TsdfFrame {
  cv::Mat depth_m, mask;
  host::StereoIntrinsics intrinsics;
  Eigen::Isometry3d T_world_camera;
  Eigen::AlignedBox3d bounds_m;
};

const TsdfFrame& tsdfFrame() {
  static const TsdfFrame f = [] {
    const auto world = robot::sim::World::generate(robot::sim::WorldConfig{}, 1);
    const robot::sim::StereoRenderer renderer(world);
    const host::StereoFrame stereo = renderer.render(world.startCameraPose());
    const host::PerceptionResult perceived = host::PerceptionPipeline().process(stereo);
    if (!perceived.region) throw std::runtime_error("BM_TsdfIntegrate: tag not seen");
    TsdfFrame out;
    out.depth_m =
        host::tsdf::depthFromDisparity(perceived.disparity.disparity_px, stereo.intrinsics);
    out.mask = perceived.fruitlet_mask;
    out.intrinsics = stereo.intrinsics;
    out.T_world_camera = stereo.T_world_camera;
    const Eigen::Vector3d half = Eigen::Vector3d::Constant(perceived.region->radius_m());
    out.bounds_m = {perceived.region->center_m() - half, perceived.region->center_m() + half};
    return out;
  }();
  return f;
}

void BM_TsdfIntegrate(benchmark::State& state, accel::BackendKind kind) {
  const TsdfFrame& f = tsdfFrame();
  auto backend = backendOrSkip(state, kind);
  if (!backend) return;
  host::tsdf::TsdfVolume reference({}, f.bounds_m, nullptr);
  reference.integrate(f.depth_m, f.mask, f.intrinsics, f.T_world_camera);
  host::tsdf::TsdfIntegrateStats stats;
  std::size_t bytes = 0, blocks = 0;
  std::vector<float> distance;
  for (auto _ : state) {
    state.PauseTiming();  // a trial builds its volume once
    host::tsdf::TsdfVolume volume({}, f.bounds_m, backend.get());
    state.ResumeTiming();
    stats = volume.integrate(f.depth_m, f.mask, f.intrinsics, f.T_world_camera);
    state.PauseTiming();
    bytes = volume.memoryBytes();
    blocks = volume.blockCount();
    distance = volume.distances();  // download: not part of integration
    state.ResumeTiming();
  }
  const auto& want = reference.distances();
  if (distance.size() != want.size()) {
    state.SkipWithError("the bricks differ from the cpu reference");
    return;
  }
  std::size_t differ = 0;
  for (std::size_t i = 0; i < want.size(); ++i) differ += std::abs(distance[i] - want[i]) > 1e-6f;
  if (differ > want.size() / 10000) {
    state.SkipWithError("distances differ from the cpu reference");
    return;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(stats.roi_pixels) * state.iterations());
  state.counters["voxels_per_second"] = benchmark::Counter(
      double(stats.voxels_updated) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["roi_pixels"] = double(stats.roi_pixels);
  state.counters["blocks"] = double(blocks);
  state.counters["MB"] = bytes / 1e6;
  state.counters["bytes_per_block"] = blocks ? double(bytes) / blocks : 0.0;
}

// The frame as Open3D takes it: masked float depth, a colour image it ignores (NoColor).
std::shared_ptr<open3d::geometry::RGBDImage> open3dImage(const TsdfFrame& f) {
  open3d::geometry::Image depth, colour;
  depth.Prepare(f.depth_m.cols, f.depth_m.rows, 1, 4);
  colour.Prepare(f.depth_m.cols, f.depth_m.rows, 1, 1);
  for (int v = 0; v < f.depth_m.rows; ++v)
    for (int u = 0; u < f.depth_m.cols; ++u) {
      const float z = f.depth_m.at<float>(v, u);
      *depth.PointerAt<float>(u, v) = f.mask.at<std::uint8_t>(v, u) && z > 0.0f ? z : 0.0f;
    }
  return open3d::geometry::RGBDImage::CreateFromColorAndDepth(colour, depth, 1.0, 10.0, false);
}

void BM_TsdfIntegrateOpen3d(benchmark::State& state) {
  const TsdfFrame& f = tsdfFrame();
  const auto image = open3dImage(f);
  const open3d::camera::PinholeCameraIntrinsic intrinsic(f.depth_m.cols, f.depth_m.rows,
                                                         f.intrinsics.fx_px, f.intrinsics.fy_px,
                                                         f.intrinsics.cx_px, f.intrinsics.cy_px);
  const Eigen::Matrix4d extrinsic = f.T_world_camera.inverse().matrix();
  const host::tsdf::TsdfConfig config;
  std::shared_ptr<open3d::geometry::PointCloud> surface;
  for (auto _ : state) {
    state.PauseTiming();
    open3d::pipelines::integration::ScalableTSDFVolume volume(
        config.voxel_size_m, config.truncation_m,
        open3d::pipelines::integration::TSDFVolumeColorType::NoColor, 8);
    state.ResumeTiming();
    volume.Integrate(*image, intrinsic, extrinsic);
    state.PauseTiming();
    surface = volume.ExtractPointCloud();
    state.ResumeTiming();
  }
  host::tsdf::TsdfVolume ours(config, f.bounds_m, nullptr);
  const auto stats = ours.integrate(f.depth_m, f.mask, f.intrinsics, f.T_world_camera);
  const std::vector<Eigen::Vector3f> a = ours.extractSurfacePoints();
  std::vector<Eigen::Vector3f> b;
  for (const auto& p : surface->points_)
    if (f.bounds_m.contains(p)) b.push_back(p.cast<float>());
  if (a.empty() || b.empty()) {
    state.SkipWithError("an empty surface");
    return;
  }
  const double chamfer_mm = 1e3 * host::sizing::chamferDistance_m(a, b);
  if (!(chamfer_mm < 0.25)) {
    state.SkipWithError("Open3D's surface is more than 0.25 mm from ours");
    return;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(stats.roi_pixels) * state.iterations());
  state.counters["roi_pixels"] = double(stats.roi_pixels);
  state.counters["chamfer_mm"] = chamfer_mm;
  state.counters["surface_points"] = double(b.size());
  state.counters["our_surface_points"] = double(a.size());
}

// Surface extraction from the integrated frame: our zero-crossing points and marching-cubes
// mesh against Open3D's ExtractPointCloud and ExtractTriangleMesh of its own volume over the
// same frame. Checked: each pair of surfaces within 0.25 mm (chamfer).
struct IntegratedFrame {
  std::unique_ptr<host::tsdf::TsdfVolume> ours;
  std::unique_ptr<open3d::pipelines::integration::ScalableTSDFVolume> theirs;
};

const IntegratedFrame& integratedFrame() {
  static const IntegratedFrame f = [] {
    const TsdfFrame& frame = tsdfFrame();
    IntegratedFrame out;
    const host::tsdf::TsdfConfig config;
    out.ours = std::make_unique<host::tsdf::TsdfVolume>(config, frame.bounds_m, nullptr);
    out.ours->integrate(frame.depth_m, frame.mask, frame.intrinsics, frame.T_world_camera);
    out.theirs = std::make_unique<open3d::pipelines::integration::ScalableTSDFVolume>(
        config.voxel_size_m, config.truncation_m,
        open3d::pipelines::integration::TSDFVolumeColorType::NoColor, 8);
    const open3d::camera::PinholeCameraIntrinsic intrinsic(
        frame.depth_m.cols, frame.depth_m.rows, frame.intrinsics.fx_px, frame.intrinsics.fy_px,
        frame.intrinsics.cx_px, frame.intrinsics.cy_px);
    out.theirs->Integrate(*open3dImage(frame), intrinsic, frame.T_world_camera.inverse().matrix());
    return out;
  }();
  return f;
}

std::vector<Eigen::Vector3f> insideBounds(const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3f> out;
  for (const auto& p : points)
    if (tsdfFrame().bounds_m.contains(p)) out.push_back(p.cast<float>());
  return out;
}

void BM_SurfaceExtract(benchmark::State& state, bool open3d, bool mesh) {
  const IntegratedFrame& f = integratedFrame();
  std::vector<Eigen::Vector3f> points;
  std::size_t triangles = 0;
  for (auto _ : state) {
    if (!open3d && !mesh) {
      points = f.ours->extractSurfacePoints();
    } else if (!open3d) {
      const host::tsdf::TriangleMesh m = f.ours->extractMesh();
      points = m.vertices_m;
      triangles = m.triangles.size();
    } else if (!mesh) {
      points = insideBounds(f.theirs->ExtractPointCloud()->points_);
    } else {
      const auto m = f.theirs->ExtractTriangleMesh();
      points = insideBounds(m->vertices_);
      triangles = m->triangles_.size();
    }
  }
  // Check against the other library's surface of the same kind.
  std::vector<Eigen::Vector3f> other;
  if (open3d)
    other = mesh ? f.ours->extractMesh().vertices_m : f.ours->extractSurfacePoints();
  else
    other = insideBounds(mesh ? f.theirs->ExtractTriangleMesh()->vertices_
                              : f.theirs->ExtractPointCloud()->points_);
  if (points.empty() || other.empty()) {
    state.SkipWithError("an empty surface");
    return;
  }
  const double chamfer_mm = 1e3 * host::sizing::chamferDistance_m(points, other);
  if (!(chamfer_mm < 0.25)) {
    state.SkipWithError("the two libraries' surfaces are more than 0.25 mm apart");
    return;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(points.size()) * state.iterations());
  state.counters["points"] = double(points.size());
  state.counters["triangles"] = double(triangles);
  state.counters["chamfer_mm"] = chamfer_mm;
}

// Outlier removal and DBSCAN with the sizing chain's defaults on the frame's surface points,
// ours (nanoflann) against Open3D's. Checked: the same survivors; the same clusters up to
// label permutation.
const std::vector<Eigen::Vector3f>& surfacePoints() {
  static const std::vector<Eigen::Vector3f> points = integratedFrame().ours->extractSurfacePoints();
  return points;
}

open3d::geometry::PointCloud toOpen3d(const std::vector<Eigen::Vector3f>& points) {
  open3d::geometry::PointCloud cloud;
  for (const auto& p : points) cloud.points_.push_back(p.cast<double>());
  return cloud;
}

void BM_OutlierRemoval(benchmark::State& state, bool open3d) {
  const auto& points = surfacePoints();
  const host::sizing::SizingConfig c;
  const open3d::geometry::PointCloud cloud = toOpen3d(points);
  std::vector<std::size_t> kept;
  for (auto _ : state) {
    if (open3d) {
      const auto [inliers, index] =
          cloud.RemoveStatisticalOutliers(c.outlier_neighbours, c.outlier_std_ratio);
      kept.assign(index.begin(), index.end());
    } else {
      kept = host::sizing::statisticalOutlierInliers(points, c.outlier_neighbours,
                                                     c.outlier_std_ratio);
    }
  }
  const auto [unused, theirs] =
      cloud.RemoveStatisticalOutliers(c.outlier_neighbours, c.outlier_std_ratio);
  const auto ours =
      host::sizing::statisticalOutlierInliers(points, c.outlier_neighbours, c.outlier_std_ratio);
  if (ours != std::vector<std::size_t>(theirs.begin(), theirs.end())) {
    state.SkipWithError("the survivors differ from Open3D's");
    return;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(points.size()) * state.iterations());
  state.counters["points"] = double(points.size());
  state.counters["removed"] = double(points.size() - kept.size());
}

void BM_Dbscan(benchmark::State& state, bool open3d) {
  const auto& points = surfacePoints();
  const host::sizing::SizingConfig c;
  const open3d::geometry::PointCloud cloud = toOpen3d(points);
  std::vector<int> labels;
  for (auto _ : state) {
    labels = open3d ? cloud.ClusterDBSCAN(c.dbscan_eps_m, c.dbscan_min_samples, false)
                    : host::sizing::dbscan(points, c.dbscan_eps_m, c.dbscan_min_samples);
  }
  const auto ours = host::sizing::dbscan(points, c.dbscan_eps_m, c.dbscan_min_samples);
  const auto theirs = cloud.ClusterDBSCAN(c.dbscan_eps_m, c.dbscan_min_samples, false);
  std::map<int, int> forward, backward;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const int a = ours[i] == host::sizing::kDbscanNoise ? -1 : ours[i];
    const int b = theirs[i] < 0 ? -1 : theirs[i];
    if (forward.emplace(a, b).first->second != b || backward.emplace(b, a).first->second != a) {
      state.SkipWithError("the clusters differ from Open3D's");
      return;
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(points.size()) * state.iterations());
  state.counters["points"] = double(points.size());
  state.counters["clusters"] = double(forward.size() - forward.count(-1));
}

const bool kRegistered = [] {
  for (accel::BackendKind kind :
       {accel::BackendKind::kCpu, accel::BackendKind::kOpenCl, accel::BackendKind::kVulkan})
    benchmark::RegisterBenchmark(
        ("BM_TsdfIntegrate/fvp/" + std::string(accel::toString(kind))).c_str(), BM_TsdfIntegrate,
        kind)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  benchmark::RegisterBenchmark("BM_TsdfIntegrate/open3d/cpu", BM_TsdfIntegrateOpen3d)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  for (const bool open3d : {false, true}) {
    const std::string who = open3d ? "open3d" : "fvp";
    for (const bool mesh : {false, true})
      benchmark::RegisterBenchmark(
          ("BM_SurfaceExtract/" + who + (mesh ? "/mesh" : "/points")).c_str(), BM_SurfaceExtract,
          open3d, mesh)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    benchmark::RegisterBenchmark(("BM_OutlierRemoval/" + who + "/cpu").c_str(), BM_OutlierRemoval,
                                 open3d)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("BM_Dbscan/" + who + "/cpu").c_str(), BM_Dbscan, open3d)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  return true;
}();

}  // namespace
}  // namespace fvp::bench
