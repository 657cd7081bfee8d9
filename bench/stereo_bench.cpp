// BM_Stereo: stereo matching of a view, both passes (the half-resolution pass over the whole
// image and the full-resolution pass over the Cluster Region's band), with OpenCV's SGBM as
// the full-resolution pass (BM_Stereo/sgbm, the reference) and with the guided kernels on
// each backend (BM_Stereo/guided/<backend>, docs/stereo.md). Workload: the start views of
// development worlds 1-3 (with leaves), rendered once with their exact depth; each
// iteration matches all three. Checks: the fruitlet pixels' median depth error against the
// exact depth stays under 1 mm over at least 1000 pixels, and every backend's guided
// disparities equal the cpu backend's bit for bit. Counters: fruitlet_px and
// fruitlet_depth_error_mm (median), band_px_per_second (full-resolution band pixels).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_common.h"
#include "fvp/host/core/cluster_region.h"
#include "fvp/host/perception/cluster_region_image.h"
#include "fvp/host/perception/stereo_matcher.h"
#include "fvp/robot/sim/object_ids.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"

namespace fvp::bench {
namespace {

struct StereoView {
  robot::sim::RenderedView view;
  cv::Rect band;
};

const std::vector<StereoView>& stereoViews() {
  static const std::vector<StereoView> views = [] {
    std::vector<StereoView> out;
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const auto world = robot::sim::World::generate(robot::sim::WorldConfig{}, seed);
      const robot::sim::StereoRenderer renderer(world);
      StereoView v{renderer.renderWithGroundTruth(world.startCameraPose()), {}};
      const host::ClusterRegion region(world.clusterCenter_m(), host::kDefaultClusterRadiusM);
      v.band = host::clusterRegionImageBounds(region, v.view.frame.intrinsics,
                                              v.view.frame.T_world_camera);
      out.push_back(std::move(v));
    }
    return out;
  }();
  return views;
}

/// Every view's disparities, in order.
std::vector<cv::Mat> matchAll(const host::StereoMatcher& matcher) {
  std::vector<cv::Mat> out;
  for (const StereoView& v : stereoViews())
    out.push_back(
        matcher.compute(v.view.frame.left_bgr, v.view.frame.right_bgr, v.band).disparity_px);
  return out;
}

/// The fruitlet pixels' depth errors (metres) of one matcher's disparities.
std::vector<double> fruitletErrors(const std::vector<cv::Mat>& disparities) {
  std::vector<double> err_m;
  for (std::size_t i = 0; i < disparities.size(); ++i) {
    const robot::sim::RenderedView& rv = stereoViews()[i].view;
    const host::StereoIntrinsics& K = rv.frame.intrinsics;
    for (int v = 0; v < K.height_px; ++v)
      for (int u = 0; u < K.width_px; ++u) {
        const float d = disparities[i].at<float>(v, u);
        const double z = rv.ground_truth.depth_m.at<float>(v, u);
        if (d > 0.0f && z > 0.0 &&
            robot::sim::isFruitletId(rv.ground_truth.object_id.at<int>(v, u)))
          err_m.push_back(std::abs(K.depthFromDisparity(d) - z));
      }
  }
  return err_m;
}

void BM_Stereo(benchmark::State& state, bool guided, accel::BackendKind kind) {
  std::unique_ptr<accel::Backend> backend;
  if (guided && !(backend = backendOrSkip(state, kind))) return;
  host::StereoMatcherConfig config;
  config.guided_fine = guided;
  const host::StereoMatcher matcher(config, backend.get());
  std::vector<cv::Mat> disparities;
  for (auto _ : state) disparities = matchAll(matcher);
  std::vector<double> err_m = fruitletErrors(disparities);
  if (err_m.size() < 1000) return state.SkipWithError("fewer than 1000 fruitlet pixels matched");
  std::nth_element(err_m.begin(), err_m.begin() + err_m.size() / 2, err_m.end());
  const double median_mm = err_m[err_m.size() / 2] * 1e3;
  if (!(median_mm < 1.0)) return state.SkipWithError("fruitlet median depth error >= 1 mm");
  if (guided && kind != accel::BackendKind::kCpu) {
    const std::vector<cv::Mat> reference = matchAll(host::StereoMatcher(config));  // its own cpu
    for (std::size_t i = 0; i < reference.size(); ++i)
      if (cv::countNonZero(reference[i] != disparities[i]) != 0)
        return state.SkipWithError("the guided disparities differ from the cpu backend's");
  }
  double band_px = 0.0;
  for (const StereoView& v : stereoViews()) band_px += v.band.area();
  state.counters["fruitlet_px"] = double(err_m.size());
  state.counters["fruitlet_depth_error_mm"] = median_mm;
  state.counters["band_px_per_second"] =
      benchmark::Counter(band_px * double(state.iterations()), benchmark::Counter::kIsRate);
}

void registerAll() {
  benchmark::RegisterBenchmark("BM_Stereo/sgbm", BM_Stereo, false, accel::BackendKind::kCpu)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(5);
  for (accel::BackendKind kind :
       {accel::BackendKind::kCpu, accel::BackendKind::kOpenCl, accel::BackendKind::kVulkan})
    benchmark::RegisterBenchmark(("BM_Stereo/guided/" + std::string(accel::toString(kind))).c_str(),
                                 BM_Stereo, true, kind)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(5);
}

const bool kRegistered = (registerAll(), true);

}  // namespace
}  // namespace fvp::bench
