#include "fvp/robot/sim/simulated_camera.h"

namespace fvp::robot::sim {

SimulatedCamera::SimulatedCamera(const StereoRenderer& renderer, SimClock& clock)
    : renderer_(renderer), clock_(clock) {}

host::nbv::CaptureResult SimulatedCamera::capture(const Eigen::Isometry3d& T_world_camera) {
  RenderOptions options;
  host::nbv::CaptureResult out;
  out.frame = renderer_.render(T_world_camera, options);
  out.status = host::nbv::CaptureStatus::kOk;
  last_render_s_ = renderer_.lastRenderSeconds();
  total_render_s_ += last_render_s_;
  clock_.chargeCapture();
  clock_.recordUncharged(last_render_s_, 0.0);
  return out;
}

}  // namespace fvp::robot::sim
