// The simulator as the next-best-view loop's camera: the Embree flash stereo renderer at the
// arm's pose, each capture charged to the simulated clock.
#pragma once

#include "fvp/host/nbv/camera.h"
#include "fvp/robot/sim/sim_clock.h"
#include "fvp/robot/sim/stereo_renderer.h"

namespace fvp::robot::sim {

class SimulatedCamera : public host::nbv::Camera {
 public:
  /// renderer and clock must outlive the camera.
  SimulatedCamera(const StereoRenderer& renderer, SimClock& clock);

  /// Renders the images alone (no ground-truth depth or ids: the loop perceives from the
  /// images) and charges the capture; rendering itself is the simulator's cost, recorded,
  /// not charged.
  host::nbv::CaptureResult capture(const Eigen::Isometry3d& T_world_camera) override;

  double lastRenderSeconds() const { return last_render_s_; }
  double totalRenderSeconds() const { return total_render_s_; }

 private:
  const StereoRenderer& renderer_;
  SimClock& clock_;
  double last_render_s_ = 0.0, total_render_s_ = 0.0;
};

}  // namespace fvp::robot::sim
