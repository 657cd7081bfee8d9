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
  const host::PerceptionPipeline perception(options.perception);
  // Clouds seen before the region was known, with the index of their view.
  std::vector<std::pair<std::size_t, host::LabeledClouds>> pending;
  for (const Eigen::Isometry3d& pose : poses) {
    MappedView view;
    view.T_world_camera = pose;
    auto t0 = std::chrono::steady_clock::now();
    RenderOptions render_options;
    render_options.ground_truth = false;
    const host::StereoFrame frame = renderer.render(pose, render_options);
    view.render_s = secondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    host::PerceptionResult perceived = perception.process(frame, out.region);
    view.perceive_s = secondsSince(t0);
    view.tag_detected = perceived.tag.has_value();
    view.roi_points = perceived.clouds.roi_points_m.size();
    view.other_points = perceived.clouds.other_points_m.size();
    if (!out.region && perceived.region) {
      out.region = perceived.region;
      out.map = host::map::createMapEngine(options.engine, options.map, *out.region, backend);
      for (const auto& [index, clouds] : pending) {
        out.views[index].scan =
            out.map->integrate(clouds.sensor_origin_m, clouds.roi_points_m, clouds.other_points_m);
      }
      pending.clear();
    }
    if (out.map) {
      view.scan =
          out.map->integrate(perceived.clouds.sensor_origin_m, perceived.clouds.roi_points_m,
                             perceived.clouds.other_points_m);
    } else {
      pending.emplace_back(out.views.size(), std::move(perceived.clouds));
    }
    out.views.push_back(view);
  }
  return out;
}

}  // namespace fvp::robot::sim
