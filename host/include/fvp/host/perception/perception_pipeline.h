// The perception chain of one view (paper, "Perception"; docs/design.md §1 step 1):
// HSV segmentation -> AprilTag -> Cluster Region -> SGBM (full resolution over the band
// covering the Cluster Region and the segmented fruitlets, reduced resolution elsewhere)
// -> ROI and non-ROI world-frame clouds.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>

#include "fvp/host/core/cluster_region.h"
#include "fvp/host/core/labeled_clouds.h"
#include "fvp/host/perception/apriltag_detector.h"
#include "fvp/host/perception/cloud_projector.h"
#include "fvp/host/perception/fruitlet_segmenter.h"
#include "fvp/host/perception/stereo_frame.h"
#include "fvp/host/perception/stereo_matcher.h"

namespace fvp::host {

inline constexpr int kDefaultBandMarginPx = 16;
/// Depth added behind the Cluster Region for the fine pass's disparity window:
/// several times the field preset's errors of the region's placement (tag, hand-eye and arm,
/// a few millimetres together; docs/simulation.md) and of the baseline (0.5 %).
inline constexpr double kDefaultWindowDepthMarginM = 0.01;

struct PerceptionConfig {
  SegmentationConfig segmentation;
  StereoMatcherConfig stereo;
  AprilTagDetectorConfig tag;
  ClusterRegionConfig region;
  ProjectionConfig projection;
  int band_margin_px = kDefaultBandMarginPx;  ///< added around the fine rectangle
  /// Search the fine band only over disparities of the Cluster Region and nearer
  /// (StereoMatcher's fine_window); false: the whole range, as without a region. Off by
  /// default: ~40 % less stereo time and the same accuracy, but its effect on a cluster's
  /// time is not settled (docs/results.md, "The stereo window").
  bool disparity_window = false;
  double window_depth_margin_m = kDefaultWindowDepthMarginM;
  void validate() const;
  /// The user-facing keys (docs/capture-format.md "Perception configuration"): the tag
  /// (family, id, size), the Cluster Region (offset from the tag and radius, or an explicit
  /// centre in the world frame) and the HSV segmentation thresholds; unknown keys, wrong
  /// types and non-finite numbers are errors naming the file and the key.
  static PerceptionConfig fromYamlFile(const std::filesystem::path& path);
  /// The user-facing keys as JSON, from the same key table (an unset region_center_m left out).
  std::string toJson() const;
};

struct PerceptionResult {
  cv::Mat fruitlet_mask;       ///< CV_8U, 255 = fruitlet
  cv::Mat fruitlet_instances;  ///< CV_16U instance ids as the frame gave them; else empty
  DisparityResult disparity;   ///< full-size CV_32F map, fine rect, coarse scale
  LabeledClouds clouds;        ///< stats: all counts and timings of this view
  std::optional<TagDetection> tag;
  std::optional<ClusterRegion> region;  ///< the one used (given or from the tag)
};

/// What PerceptionPipeline::process requires of a frame (any source: a robot's driver, the
/// Python module, the simulator): a valid camera model and pose, a left image of the
/// intrinsics' size, and a right image, mask and disparity of that size where present (the
/// mask CV_8U or CV_16U, the disparity CV_32F). Throws std::invalid_argument "SOURCE: FIELD: ...".
void checkStereoFrame(const StereoFrame& frame, const std::string& source);

class PerceptionPipeline {
 public:
  /// backend: where the stereo matcher's kernels run (StereoMatcher; not owned, may be null).
  explicit PerceptionPipeline(PerceptionConfig config = {}, accel::Backend* backend = nullptr);
  const PerceptionConfig& config() const { return config_; }

  /// known_region: the Cluster Region from an earlier view (the tag is then still detected
  /// and reported, but the given region is used). expected_T_world_tag: where earlier views
  /// put the tag; it is then searched for only in the part of the image up to where it
  /// should appear (AprilTagDetector::detectNear; about a third of the image).
  PerceptionResult process(
      const StereoFrame& frame, const std::optional<ClusterRegion>& known_region = std::nullopt,
      const std::optional<Eigen::Isometry3d>& expected_T_world_tag = std::nullopt) const;

 private:
  PerceptionConfig config_;
  FruitletSegmenter segmenter_;
  StereoMatcher matcher_;
  AprilTagDetector tag_detector_;
  CloudProjector projector_;
};

}  // namespace fvp::host
