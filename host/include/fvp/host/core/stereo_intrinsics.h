// Rectified stereo camera model shared by the simulator, perception and sizing.
// Frames: the camera frame is OpenCV's optical frame (x right, y down, z forward) of the
// LEFT camera; T_world_camera maps camera-frame points to world points. The right camera
// sits at +baseline_m along the left camera's x axis, with identical intrinsics.
#pragma once

#include <Eigen/Core>
#include <optional>

namespace fvp::host {

inline constexpr int kDefaultImageWidthPx = 1440;
inline constexpr int kDefaultImageHeightPx = 1080;
inline constexpr double kDefaultFocalPx = 1100.0;
inline constexpr double kDefaultBaselineM = 0.05;

struct StereoIntrinsics {
  int width_px = kDefaultImageWidthPx;
  int height_px = kDefaultImageHeightPx;
  double fx_px = kDefaultFocalPx;
  double fy_px = kDefaultFocalPx;
  double cx_px = 0.5 * (kDefaultImageWidthPx - 1);
  double cy_px = 0.5 * (kDefaultImageHeightPx - 1);
  double baseline_m = kDefaultBaselineM;

  /// Pixel of a left-camera-frame point; nullopt behind the camera. Pixel centres are
  /// at integer coordinates (OpenCV convention).
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_camera_m) const {
    if (!(p_camera_m.z() > 0.0)) return std::nullopt;
    return Eigen::Vector2d(fx_px * p_camera_m.x() / p_camera_m.z() + cx_px,
                           fy_px * p_camera_m.y() / p_camera_m.z() + cy_px);
  }
  /// Left-camera-frame point of pixel (u, v) at depth z.
  Eigen::Vector3d unproject(double u_px, double v_px, double z_m) const {
    return {(u_px - cx_px) / fx_px * z_m, (v_px - cy_px) / fy_px * z_m, z_m};
  }
  /// Depth of a disparity (rectified pair): z = fx * b / d.
  double depthFromDisparity(double disparity_px) const { return fx_px * baseline_m / disparity_px; }
  /// Its inverse: d = fx * b / z.
  double disparityFromDepth(double depth_m) const { return fx_px * baseline_m / depth_m; }
};

}  // namespace fvp::host
