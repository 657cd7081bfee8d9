#include "fvp/robot/sim/simulated_mapping.h"

#include <chrono>

namespace fvp::robot::sim {
namespace {
double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

SimulatedMapping mapSimulatedViews(const World& world, const std::vector<Eigen::Isometry3d>& poses,
                                   const SimulatedMappingOptions& options,
                                   accel::Backend* backend) {
  SimulatedMapping out;
  const StereoRenderer renderer(world, options.render);
  host::MappingSession session(options.perception, options.engine, options.map, backend);
  for (const Eigen::Isometry3d& pose : poses) {
    MappedView view;
    view.T_world_camera = pose;
    const auto t0 = std::chrono::steady_clock::now();
    RenderOptions render_options;
    const host::StereoFrame frame = renderer.render(pose, render_options);
    view.render_s = secondsSince(t0);
    const host::ViewResult seen = session.addView(frame);
    view.perceive_s = seen.perceive_s;
    view.tag_detected = seen.tag_detected;
    view.roi_points = seen.roi_points;
    view.other_points = seen.other_points;
    out.views.push_back(view);
  }
  // Views seen before the tag got their scans later: take every scan from the session.
  for (std::size_t i = 0; i < out.views.size(); ++i) out.views[i].scan = session.views()[i].scan;
  out.region = session.region();
  out.map = std::move(session).releaseMap();
  return out;
}

}  // namespace fvp::robot::sim
