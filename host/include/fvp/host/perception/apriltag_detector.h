// AprilTag (tag36h11) detection with libapriltag on the left image and tag pose with
// libapriltag's estimate_tag_pose (homography + orthogonal iteration). Frames: see
// tag_detection.h.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fvp/host/core/stereo_intrinsics.h"
#include "fvp/host/perception/tag_detection.h"

namespace fvp::host {

inline constexpr int kDefaultTagId = 0;
inline constexpr double kDefaultTagSizeM = 0.03;  ///< black border edge, as libapriltag's tagsize
inline constexpr float kDefaultQuadDecimate = 1.0f;  ///< full resolution: best corner accuracy
inline constexpr int kDefaultMaxHamming = 1;
/// detectNear's margin around where the tag should appear, in degrees of view direction:
/// over 10x the field preset's pose errors (hand-eye 0.3 deg, arm 1 mm ~ 0.2 deg at 0.3 m),
/// room for an uncalibrated arm's drift.
inline constexpr double kDefaultSearchMarginDeg = 5.0;

struct AprilTagDetectorConfig {
  /// libapriltag family: tag36h11 (default), tag25h9, tag16h5, tagStandard41h12,
  /// tagStandard52h13, tagCircle21h7, tagCircle49h12, tagCustom48h12.
  std::string family = "tag36h11";
  int tag_id = kDefaultTagId;  ///< the cluster's tag; -1: accept any id (detect() returns the best)
  double tag_size_m = kDefaultTagSizeM;
  float quad_decimate = kDefaultQuadDecimate;
  float quad_sigma = 0.0f;
  bool refine_edges = true;
  int max_hamming = kDefaultMaxHamming;
  int threads = 0;                                     ///< 0: std::thread::hardware_concurrency()
  double search_margin_deg = kDefaultSearchMarginDeg;  ///< detectNear; 0: the whole image
  void validate() const;
};

class AprilTagDetector {
 public:
  explicit AprilTagDetector(AprilTagDetectorConfig config = {});
  ~AprilTagDetector();
  AprilTagDetector(const AprilTagDetector&) = delete;
  AprilTagDetector& operator=(const AprilTagDetector&) = delete;
  const AprilTagDetectorConfig& config() const { return config_; }

  /// Every tag36h11 tag in the image (CV_8UC3 BGR or CV_8UC1), with poses.
  std::vector<TagDetection> detectAll(const cv::Mat& image, const StereoIntrinsics& intrinsics,
                                      const Eigen::Isometry3d& T_world_camera) const;
  /// The configured tag (highest decision margin if seen more than once); nullopt if absent.
  std::optional<TagDetection> detect(const cv::Mat& image, const StereoIntrinsics& intrinsics,
                                     const Eigen::Isometry3d& T_world_camera) const;
  /// detect() in the window of the image up to where a tag at T_world_tag_expected appears
  /// from T_world_camera: from the image's corner (0, 0) to its corners' bounding box grown by
  /// search_margin_deg, so that a tag inside it is found as in the whole image, bit for bit.
  /// A tag outside the window is not searched for; the whole image is searched where there
  /// is no window (search_margin_deg 0, the tag behind or beside the camera).
  std::optional<TagDetection> detectNear(const cv::Mat& image, const StereoIntrinsics& intrinsics,
                                         const Eigen::Isometry3d& T_world_camera,
                                         const Eigen::Isometry3d& T_world_tag_expected) const;
  /// The window detectNear searches (empty: the whole image).
  cv::Rect searchWindow(const StereoIntrinsics& intrinsics, const Eigen::Isometry3d& T_world_camera,
                        const Eigen::Isometry3d& T_world_tag_expected) const;

 private:
  /// Every tag in `window` of the image (the whole image's camera model K).
  std::vector<TagDetection> detectIn(const cv::Mat& image, cv::Rect window,
                                     const StereoIntrinsics& K,
                                     const Eigen::Isometry3d& T_world_camera) const;
  std::optional<TagDetection> best(const std::vector<TagDetection>& detections) const;
  struct Impl;
  AprilTagDetectorConfig config_;
  std::unique_ptr<Impl> impl_;
  mutable std::mutex mutex_;  ///< libapriltag's detector is not re-entrant
};

}  // namespace fvp::host
