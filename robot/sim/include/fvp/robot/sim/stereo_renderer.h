// Embree ray-traced rectified stereo pair of a World, as the flash stereo camera sees it
// (DESIGN.md section 8): point light at the camera with inverse-square falloff, Lambertian
// surfaces with procedural texture, anti-aliasing, sensor noise; plus the left camera's
// exact depth and per-pixel object ids (ground truth for tests and ablations only).
//
// API CONTRACT used by perception tests and `fvp capture`.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>

#include "fvp/host/perception/stereo_frame.h"
#include "fvp/robot/sim/world.h"

namespace fvp::robot::sim {

struct RenderConfig {
  host::StereoIntrinsics intrinsics;
  int samples_per_pixel = 4;        ///< anti-aliasing (stratified sub-pixel samples)
  double flash_power = 1.0;         ///< radiance scale of the point light at the camera
  double noise_sigma = 2.0;         ///< Gaussian sensor noise, 8-bit grey levels
  std::uint64_t noise_seed = 0;     ///< mixed with the pose so each view's noise differs
  int threads = 0;                  ///< 0: all cores
};

struct RenderOptions {
  bool with_leaves = true;          ///< false: render without leaves (occlusion statistic)
  bool ground_truth = true;         ///< fill gt_depth_m and gt_object_id
};

class StereoRenderer {
 public:
  StereoRenderer(const World& world, const RenderConfig& config = {});
  ~StereoRenderer();
  StereoRenderer(const StereoRenderer&) = delete;
  StereoRenderer& operator=(const StereoRenderer&) = delete;

  /// Renders the pair seen from T_world_camera (the left camera's optical frame).
  host::StereoFrame render(const Eigen::Isometry3d& T_world_camera,
                           const RenderOptions& options = {}) const;
  /// Wall time of the last render() call, seconds.
  double lastRenderSeconds() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fvp::robot::sim
