#include "fvp/robot/sim/simulated_camera.h"

#include <chrono>
#include <memory>

namespace fvp::robot::sim {

SimulatedCamera::SimulatedCamera(const StereoRenderer& renderer, SimClock& clock,
                                 const PoseErrorModel* pose_errors)
    : SimulatedCamera(renderer, clock, SimulatedErrors{pose_errors, nullptr, nullptr}) {}

SimulatedCamera::SimulatedCamera(const StereoRenderer& renderer, SimClock& clock,
                                 SimulatedErrors errors)
    : renderer_(renderer), clock_(clock), errors_(errors) {}

host::nbv::CaptureResult SimulatedCamera::capture(const Eigen::Isometry3d& T_world_camera) {
  const int view = captures_++;
  last_true_pose_ = errors_.pose ? errors_.pose->truePose(T_world_camera, view) : T_world_camera;
  const auto t0 = std::chrono::steady_clock::now();
  // Wind: this view's canopy, in a scene of its own (building one takes milliseconds).
  std::unique_ptr<StereoRenderer> windblown;
  if (errors_.wind && errors_.wind->enabled())
    windblown = std::make_unique<StereoRenderer>(errors_.wind->worldAt(view), renderer_.config());
  const StereoRenderer& renderer = windblown ? *windblown : renderer_;
  host::nbv::CaptureResult out;
  if (errors_.segmentation && errors_.segmentation->enabled()) {
    RenderedView rendered = renderer.renderWithGroundTruth(last_true_pose_);
    out.frame = std::move(rendered.frame);
    const cv::Mat& ids = rendered.ground_truth.object_id;
    out.frame.fruitlet_mask = errors_.segmentation->instances()
                                  ? errors_.segmentation->instancesFor(ids, view)
                                  : errors_.segmentation->maskFor(ids, view);
  } else {
    out.frame = renderer.render(last_true_pose_);
  }
  out.frame.T_world_camera = T_world_camera;  // what the robot believes
  out.status = host::nbv::CaptureStatus::kOk;
  last_render_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  total_render_s_ += last_render_s_;
  clock_.chargeCapture();
  clock_.recordUncharged(last_render_s_, 0.0);
  return out;
}

}  // namespace fvp::robot::sim
