// Maps a simulated world from a sequence of camera poses: render each stereo pair and hand
// it to a host::MappingSession (perception, Cluster Region from the first view whose
// AprilTag is detected, coarse + fine maps). Used by `fvp map`, tests and benchmarks; the
// planner drives the same session one view at a time.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "fvp/host/map/map_engine.h"
#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"

namespace fvp::robot::sim {

struct MappedView {
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  double render_s = 0.0;
  double perceive_s = 0.0;
  std::size_t roi_points = 0, other_points = 0;
  bool tag_detected = false;
  host::map::ScanStats scan;  ///< empty when no view detected the tag
};

struct SimulatedMapping {
  std::optional<host::ClusterRegion> region;
  std::unique_ptr<host::map::MapEngine> map;  ///< null when no view saw the tag
  std::vector<MappedView> views;
};

struct SimulatedMappingOptions {
  std::string engine = "grid";  ///< "grid" or "octomap"
  host::map::MapConfig map;
  RenderConfig render;
  host::PerceptionConfig perception;
};

/// backend: required for the grid engine. Views seen before the tag is detected are
/// integrated, in order, as soon as the region is known (their clouds are kept).
SimulatedMapping mapSimulatedViews(const World& world, const std::vector<Eigen::Isometry3d>& poses,
                                   const SimulatedMappingOptions& options, accel::Backend* backend);

}  // namespace fvp::robot::sim
