// BM_TsdfIntegrate/fvp/<backend>: projective TSDF integration (0.5 mm, 2 mm truncation) of
// one capture's ROI depth: the start view of world 1, rendered, SGBM disparity -> depth,
// fruitlet mask from the HSV segmentation. Each iteration integrates the view into a fresh
// volume over the Cluster Region's cube (built outside the timed region, as a trial builds it
// once; the band's bricks are allocated inside it, as in a trial's first view). Every run is
// checked against the cpu backend: the same bricks, distances within 1e-6 m on >= 99.99 % of
// voxels. items_per_second counts the ROI depth pixels integrated; voxels_per_second the voxel
// slots updated.
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
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>
#include <cmath>

#include "bench_common.h"
#include "fvp/host/perception/perception_pipeline.h"
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
  return true;
}();

}  // namespace
}  // namespace fvp::bench
