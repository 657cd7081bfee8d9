// The camera the next-best-view loop captures through (a real stereo head, or the
// simulator's renderer): one call, one stereo frame at the arm's current pose.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "fvp/host/perception/stereo_frame.h"

namespace fvp::host::nbv {

/// A dropped frame (a timeout, a torn transfer, an exposure the driver rejected) is an
/// expected outcome: the loop counts it and carries on.
enum class CaptureStatus { kOk, kDropped };

struct CaptureResult {
  CaptureStatus status = CaptureStatus::kDropped;
  /// The rectified pair with its intrinsics and T_world_camera (the pose the images were
  /// taken from). Optional parts a camera may fill: fruitlet_mask, disparity_px.
  StereoFrame frame;
  std::string detail;  ///< why a frame was dropped, for the log
  bool ok() const { return status == CaptureStatus::kOk; }
};

class Camera {
 public:
  virtual ~Camera() = default;
  /// Captures one frame. T_world_camera is where the arm says the camera is; a camera
  /// without its own pose source stamps the frame with it.
  virtual CaptureResult capture(const Eigen::Isometry3d& T_world_camera) = 0;
};

}  // namespace fvp::host::nbv
