// The simulator as the next-best-view loop's camera: the Embree flash stereo renderer at the
// arm's pose, each capture charged to the simulated clock.
#pragma once

#include "fvp/host/nbv/camera.h"
#include "fvp/robot/sim/pose_error_model.h"
#include "fvp/robot/sim/segmentation_model.h"
#include "fvp/robot/sim/sim_clock.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/wind_model.h"

namespace fvp::robot::sim {

/// The simulated errors a camera applies (docs/simulation.md); null: that error is off.
struct SimulatedErrors {
  const PoseErrorModel* pose = nullptr;
  const WindModel* wind = nullptr;  ///< each view renders the world as the wind moved it
  /// The frame carries this model's fruitlet mask (HSV segmentation then does not run).
  const SegmentationModel* segmentation = nullptr;
};

class SimulatedCamera : public host::nbv::Camera {
 public:
  /// renderer, clock and the error models (null: none) must outlive the camera.
  SimulatedCamera(const StereoRenderer& renderer, SimClock& clock,
                  const PoseErrorModel* pose_errors = nullptr);
  SimulatedCamera(const StereoRenderer& renderer, SimClock& clock, SimulatedErrors errors);

  /// Renders the images alone (no ground-truth depth or ids: the loop perceives from the
  /// images) and charges the capture; rendering itself is the simulator's cost, recorded,
  /// not charged. With pose errors the images are rendered from where the camera really is
  /// (PoseErrorModel::truePose) and the frame carries T_world_camera, the pose the robot was
  /// told. With wind the view's world is rendered (a renderer built for it); with a
  /// segmentation model the frame carries its mask.
  host::nbv::CaptureResult capture(const Eigen::Isometry3d& T_world_camera) override;

  double lastRenderSeconds() const { return last_render_s_; }
  double totalRenderSeconds() const { return total_render_s_; }
  bool hasPoseErrors() const { return errors_.pose != nullptr; }
  /// The pose the last capture was rendered from (the told one without pose errors).
  const Eigen::Isometry3d& lastTruePose() const { return last_true_pose_; }

 private:
  const StereoRenderer& renderer_;
  SimClock& clock_;
  SimulatedErrors errors_;
  int captures_ = 0;
  Eigen::Isometry3d last_true_pose_ = Eigen::Isometry3d::Identity();
  double last_render_s_ = 0.0, total_render_s_ = 0.0;
};

}  // namespace fvp::robot::sim
