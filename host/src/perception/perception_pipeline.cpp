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
  if (!(projection.max_depth_m > projection.min_depth_m))
    throw std::invalid_argument(
        "perception config: projection: expected min_depth_m < max_depth_m");
}

PerceptionPipeline::PerceptionPipeline(PerceptionConfig config)
    : config_((config.validate(), std::move(config))),
      segmenter_(config_.segmentation),
      matcher_(config_.stereo),
      tag_detector_(config_.tag),
      projector_(config_.projection) {}

PerceptionResult PerceptionPipeline::process(
    const StereoFrame& frame, const std::optional<ClusterRegion>& known_region) const {
  const StereoIntrinsics& K = frame.intrinsics;
  checkIntrinsics(K, "stereo frame: camera model");
  checkPose(frame.T_world_camera, "stereo frame", "T_world_camera");
  if (frame.left_bgr.empty() || frame.left_bgr.cols != K.width_px ||
      frame.left_bgr.rows != K.height_px)
    throw std::invalid_argument("PerceptionPipeline: left image does not match the intrinsics");
  PerceptionResult result;
  PerceptionStats timing;

  const cv::Size size(K.width_px, K.height_px);
  if (!frame.fruitlet_mask.empty() &&
      (frame.fruitlet_mask.size() != size || frame.fruitlet_mask.type() != CV_8UC1))
    throw std::invalid_argument(
        "PerceptionPipeline: the frame's fruitlet_mask must be CV_8UC1 of the image size");
  if (!frame.disparity_px.empty() &&
      (frame.disparity_px.size() != size || frame.disparity_px.type() != CV_32FC1))
    throw std::invalid_argument(
        "PerceptionPipeline: the frame's disparity_px must be CV_32FC1 of the image size");

  auto t0 = std::chrono::steady_clock::now();
  if (!frame.fruitlet_mask.empty())
    cv::compare(frame.fruitlet_mask, 0, result.fruitlet_mask, cv::CMP_NE);  // as given: 0 / 255
  else
    result.fruitlet_mask = segmenter_.segment(frame.left_bgr);
  timing.segmentation_s = secondsSince(t0);

  t0 = std::chrono::steady_clock::now();
  result.tag = tag_detector_.detect(frame.left_bgr, K, frame.T_world_camera);
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
  if (result.region) {
    fine = clusterRegionImageBounds(*result.region, K, frame.T_world_camera);
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
    result.disparity = matcher_.compute(frame.left_bgr, frame.right_bgr, fine);
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
  st.sgbm_s = ds.sgbm_s;
  st.segmentation_s = timing.segmentation_s;
  st.tag_s = timing.tag_s;
  return result;
}

}  // namespace fvp::host
