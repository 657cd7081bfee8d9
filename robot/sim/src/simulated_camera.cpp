#include "fvp/robot/sim/simulated_camera.h"

namespace fvp::robot::sim {

SimulatedCamera::SimulatedCamera(const StereoRenderer& renderer, SimClock& clock,
                                 const PoseErrorModel* pose_errors)
    : renderer_(renderer), clock_(clock), pose_errors_(pose_errors) {}

host::nbv::CaptureResult SimulatedCamera::capture(const Eigen::Isometry3d& T_world_camera) {
  RenderOptions options;
  host::nbv::CaptureResult out;
  last_true_pose_ =
      pose_errors_ ? pose_errors_->truePose(T_world_camera, captures_) : T_world_camera;
  ++captures_;
  out.frame = renderer_.render(last_true_pose_, options);
  out.frame.T_world_camera = T_world_camera;  // what the robot believes
  out.status = host::nbv::CaptureStatus::kOk;
  last_render_s_ = renderer_.lastRenderSeconds();
  total_render_s_ += last_render_s_;
  clock_.chargeCapture();
  clock_.recordUncharged(last_render_s_, 0.0);
  return out;
}

}  // namespace fvp::robot::sim
