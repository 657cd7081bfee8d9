// Seed 2's orbit of 3 views over 60 degrees, rendered at full resolution (the tag detector's
// working point) without ground-truth layers, once per test program when a test first needs
// a view: view 0 does not show the tag, view 1 (the start view's direction) does.
#pragma once

#include <optional>

#include "fvp/host/perception/stereo_frame.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"

namespace fvp::test {

inline const host::StereoFrame& seed2OrbitFrame(std::size_t i) {
  static const auto world = robot::sim::World::generate(robot::sim::WorldConfig{}, 2);
  static const robot::sim::StereoRenderer renderer(world);
  static const auto poses = robot::sim::orbitViews(world, 3, 60.0);
  static std::optional<host::StereoFrame> frames[2];
  if (!frames[i]) {
    robot::sim::RenderOptions options;
    frames[i] = renderer.render(poses[i], options);
  }
  return *frames[i];
}

}  // namespace fvp::test
