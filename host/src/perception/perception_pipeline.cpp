#include "fvp/host/perception/perception_pipeline.h"

#include <chrono>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "fvp/host/core/input_checks.h"
#include "fvp/host/perception/cluster_region_image.h"

namespace fvp::host {
namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

void PerceptionConfig::validate() const {
  segmentation.validate();
  stereo.validate();
  tag.validate();
  region.validate();
  if (band_margin_px < 0)
    throw std::invalid_argument("perception config: band_margin_px: expected >= 0");
  if (!(window_depth_margin_m >= 0.0))
    throw std::invalid_argument("perception config: window_depth_margin_m: expected >= 0");
  if (!(projection.max_depth_m > projection.min_depth_m))
    throw std::invalid_argument(
        "perception config: projection: expected min_depth_m < max_depth_m");
}

PerceptionPipeline::PerceptionPipeline(PerceptionConfig config, accel::Backend* backend)
    : config_((config.validate(), std::move(config))),
      segmenter_(config_.segmentation),
      matcher_(config_.stereo, backend),
      tag_detector_(config_.tag),
      projector_(config_.projection) {}

void checkStereoFrame(const StereoFrame& frame, const std::string& source) {
  const StereoIntrinsics& K = frame.intrinsics;
  checkIntrinsics(K, source + ": camera model");
  checkPose(frame.T_world_camera, source, "T_world_camera");
  const cv::Size size(K.width_px, K.height_px);
  const auto check = [&](const cv::Mat& image, const char* field, int type, const char* kind,
                         bool required) {
    if (image.empty() ? !required : image.size() == size && image.type() == type) return;
    throw std::invalid_argument(
        source + ": " + field + ": expected a " + kind + " image of " +
        std::to_string(size.height) + " x " + std::to_string(size.width) +
        " pixels (the intrinsics'), got " +
        (image.empty() ? std::string("none")
                       : std::to_string(image.rows) + " x " + std::to_string(image.cols)));
  };
  check(frame.left_bgr, "left", CV_8UC3, "BGR", true);
  check(frame.right_bgr, "right", CV_8UC3, "BGR", false);
  check(frame.fruitlet_mask, "fruitlet_mask",
        frame.fruitlet_mask.type() == CV_16UC1 ? CV_16UC1 : CV_8UC1,
        "CV_8U mask or CV_16U instance", false);
  check(frame.disparity_px, "disparity_px", CV_32FC1, "CV_32F disparity", false);
}

PerceptionResult PerceptionPipeline::process(
    const StereoFrame& frame, const std::optional<ClusterRegion>& known_region,
    const std::optional<Eigen::Isometry3d>& expected_T_world_tag) const {
  checkStereoFrame(frame, "stereo frame");
  const StereoIntrinsics& K = frame.intrinsics;
  PerceptionResult result;
  PerceptionStats timing;

  auto t0 = std::chrono::steady_clock::now();
  if (!frame.fruitlet_mask.empty()) {
    cv::compare(frame.fruitlet_mask, 0, result.fruitlet_mask, cv::CMP_NE);  // as given: 0 / 255
    if (frame.fruitlet_mask.type() == CV_16UC1) result.fruitlet_instances = frame.fruitlet_mask;
  } else
    result.fruitlet_mask = segmenter_.segment(frame.left_bgr);
  timing.segmentation_s = secondsSince(t0);

  t0 = std::chrono::steady_clock::now();
  result.tag =
      expected_T_world_tag
          ? tag_detector_.detectNear(frame.left_bgr, K, frame.T_world_camera, *expected_T_world_tag)
          : tag_detector_.detect(frame.left_bgr, K, frame.T_world_camera);
  timing.tag_s = secondsSince(t0);
  if (known_region) {
    result.region = known_region;
  } else if (config_.region.center_m) {
    result.region = ClusterRegion(*config_.region.center_m, config_.region.radius_m);
  } else if (result.tag) {
    result.region = ClusterRegion::fromTag(result.tag->T_world_tag, config_.region);
  }

  // Full resolution where the fine map and the TSDF need it: the Cluster Region's image
  // rectangle; without a region (no tag yet), around every segmented fruitlet pixel.
  cv::Rect fine;
  std::optional<DisparityWindow> window;
  if (result.region) {
    fine = clusterRegionImageBounds(*result.region, K, frame.T_world_camera);
    // The window's low edge is rejected (outside_window): pad past it.
    if (config_.disparity_window)
      window = clusterRegionDisparityWindow(*result.region, K, frame.T_world_camera,
                                            config_.window_depth_margin_m,
                                            config_.stereo.sgbm.saturation_margin_px + 1);
  } else {
    fine = cv::boundingRect(result.fruitlet_mask);
  }
  if (!fine.empty()) {
    const int m = config_.band_margin_px;
    fine = cv::Rect(fine.x - m, fine.y - m, fine.width + 2 * m, fine.height + 2 * m) &
           cv::Rect(0, 0, K.width_px, K.height_px);
  }

  SampleGrid grid;
  if (!frame.disparity_px.empty()) {
    // The frame's own disparity, as given, at full resolution everywhere.
    result.disparity.disparity_px = frame.disparity_px.clone();
    result.disparity.fine_rect = cv::Rect(0, 0, K.width_px, K.height_px);
    result.disparity.coarse_scale = 1;
    result.disparity.stats.fine_samples = static_cast<std::int64_t>(frame.disparity_px.total());
  } else {
    result.disparity = matcher_.compute(frame.left_bgr, frame.right_bgr, fine, window);
  }
  grid.full_res_rect = result.disparity.fine_rect;
  grid.coarse_step = result.disparity.coarse_scale;

  result.clouds = projector_.project(result.disparity.disparity_px, result.fruitlet_mask, K,
                                     frame.T_world_camera, grid);
  PerceptionStats& st = result.clouds.stats;
  const PerceptionStats& ds = result.disparity.stats;
  st.fine_samples = ds.fine_samples;
  st.coarse_samples = ds.coarse_samples;
  st.sgbm_invalid = ds.sgbm_invalid;
  st.saturated = ds.saturated;
  st.blind_band = ds.blind_band;
  st.no_signal = ds.no_signal;
  st.outside_window = ds.outside_window;
  st.window_from_coarse = ds.window_from_coarse;
  st.sgbm_s = ds.sgbm_s;
  st.segmentation_s = timing.segmentation_s;
  st.tag_s = timing.tag_s;
  return result;
}

}  // namespace fvp::host
