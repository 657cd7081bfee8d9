// The capture format: one stereo view on disk (docs/capture-format.md), written by
// `fvp capture` and readable from a real robot's exported data.
//
//   DIR/left.png, right.png    rectified 8-bit BGR (or grey) pair        required
//   DIR/camera.yaml            intrinsics, baseline, T_world_camera       required
//   DIR/disparity.png          16-bit, disparity * disparity_scale, 0 invalid   optional
//   DIR/mask.png               8-bit fruitlet mask (nonzero = fruitlet)   optional
//   DIR/roi.ply, other.ply     binary little-endian PLY, float x y z, world frame  optional
//   DIR/ground_truth.json      the simulated world's ground truth (sim only)  optional
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "fvp/host/core/stereo_intrinsics.h"
#include "fvp/host/perception/stereo_frame.h"

namespace fvp::host {

inline constexpr double kDefaultDisparityScale = 16.0;  ///< OpenCV's fixed point (1/16 px)
/// Largest image readCapture accepts, width x height (64 Mi pixels, e.g. 8192 x 8192): the
/// images and their per-pixel working copies must fit in memory.
inline constexpr std::int64_t kMaxCapturePixels = std::int64_t{1} << 26;
/// What a capture's files may weigh, checked before they are read (docs/capture-format.md,
/// "Size limits"): camera.yaml 64 KiB; ground_truth.json 16 MiB; a PNG 8 bytes a pixel (a
/// 16-bit RGBA image stored without compression) plus 16 MiB of other chunks; a PLY 32 bytes
/// a pixel (a point per pixel with extra properties) plus 1 MiB.
inline constexpr std::uint64_t kMaxCameraYamlBytes = std::uint64_t{64} << 10;
inline constexpr std::uint64_t kMaxGroundTruthBytes = std::uint64_t{16} << 20;
inline std::uint64_t maxCaptureImageBytes(const StereoIntrinsics& K) {
  return std::uint64_t(K.width_px) * std::uint64_t(K.height_px) * 8 + (std::uint64_t{16} << 20);
}
inline std::uint64_t maxCaptureCloudBytes(const StereoIntrinsics& K) {
  return std::uint64_t(K.width_px) * std::uint64_t(K.height_px) * 32 + (std::uint64_t{1} << 20);
}

struct Capture {
  cv::Mat left_bgr;  ///< CV_8UC3 (a grey PNG is read as CV_8UC3 too)
  cv::Mat right_bgr;
  StereoIntrinsics intrinsics;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  cv::Mat disparity_px;  ///< CV_32F, 0 = invalid; empty if absent
  /// CV_8U, 255 = fruitlet; or CV_16U instance ids (StereoFrame::fruitlet_mask); empty if absent
  cv::Mat fruitlet_mask;
  std::vector<Eigen::Vector3f> roi_points_m;    ///< world frame; empty if absent
  std::vector<Eigen::Vector3f> other_points_m;  ///< world frame
  bool has_clouds = false;                      ///< roi.ply and other.ply present
  std::string ground_truth_json;                ///< empty if absent
  double disparity_scale = kDefaultDisparityScale;
};

/// Creates dir if needed and writes every present part; each file is written to a temporary
/// name and renamed, so no file is ever half-written. Throws std::runtime_error (naming the
/// file) on I/O failure and std::invalid_argument for inconsistent sizes.
void writeCapture(const std::filesystem::path& dir, const Capture& capture);

/// The capture as the frame perception takes: the pair, intrinsics, pose, and the capture's
/// own mask and disparity (used as given when present).
StereoFrame toStereoFrame(const Capture& capture);

/// Its inverse: the frame as a capture (no clouds, no ground truth), to be written.
Capture captureOfFrame(const StereoFrame& frame);

/// Reads and validates a capture; throws std::runtime_error whose message names the file,
/// the field and what was expected.
Capture readCapture(const std::filesystem::path& dir);

/// Only dir/camera.yaml's intrinsics, checked as readCapture checks them (to size a set's
/// needs before its images are read).
StereoIntrinsics readCaptureIntrinsics(const std::filesystem::path& dir);

}  // namespace fvp::host
