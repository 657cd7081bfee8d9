// Embree ray-traced rectified stereo pair of a World, as the flash stereo camera sees it
// (docs/design.md section 8): point light at the camera with inverse-square falloff, Lambertian
// surfaces with procedural texture, anti-aliasing, sensor noise; plus the left camera's
// exact depth and per-pixel object ids (ground truth for tests and ablations only).
//
// Every primitive is an Embree user geometry with an analytic ray intersection (ellipsoids,
// capsules, curled elliptical leaves, the tag plate), so silhouettes and depths are exact.
// Images are sRGB-encoded 8-bit BGR. One flash lights both (simultaneous) exposures from the
// rig's centre, half the baseline along the left camera's x, with shadow rays: a light per
// camera would move the Lambertian shading across the small fruitlets between the two views
// and bias StereoSGBM by 1-2 px there (measured: fruitlet median depth error 0.8-3.3 mm vs
// ~0.6 mm with one flash, at 0.3 m).
//
// API CONTRACT used by perception tests and `fvp capture`.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <vector>

#include "fvp/host/perception/stereo_frame.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/sim/world_config.h"

namespace fvp::robot::sim {

/// Distance at which a white (albedo 1) surface facing the flash exposes to full scale with
/// flash_power 1: at 0.2 m such a surface reaches 81 % (unsaturated), at 0.4 m 20 % (~half
/// scale after sRGB encoding).
inline constexpr double kFlashFullScaleDistanceM = 0.18;

/// Diffuse skylight on a surface against direct sun on one facing it: about a fifth on a
/// clear day (the sky's share of global horizontal irradiance at mid elevations).
inline constexpr double kSkyToSunRatio = 0.2;

struct RenderConfig {
  host::StereoIntrinsics intrinsics;
  int samples_per_pixel = 4;  ///< anti-aliasing (stratified sub-pixel samples)
  /// Supersample only pixels with an edge inside (their four corners differ in object, shadow
  /// or tag print); the rest average their corners. false: every pixel gets the samples.
  bool adaptive_antialiasing = true;
  double flash_power = 1.0;      ///< radiance scale of the point light at the camera
  double noise_sigma = 2.0;      ///< Gaussian sensor noise, 8-bit grey levels
  std::uint64_t noise_seed = 0;  ///< mixed with the pose so each view's noise differs
  int threads = 0;               ///< 0: all cores
  /// Stereo calibration errors (docs/simulation.md "Stereo calibration"): the rig's true
  /// baseline is intrinsics.baseline_m times this, and a point appears this many pixels lower
  /// in the right image than in the left (a residual vertical misalignment after
  /// rectification). The frame's intrinsics stay the nominal ones, as a robot's calibration.
  double right_baseline_scale = 1.0;
  double right_vertical_offset_px = 0.0;
  /// Ambient light on top of the flash (docs/simulation.md "Ambient light"): the sun's
  /// irradiance in units of the flash's at kFlashFullScaleDistanceM (0: night, the flash
  /// alone), from sun_direction_world (unit, towards the sun), with shadow rays; and the
  /// sky's uniform diffuse irradiance, in the same unit, on every surface, and as the
  /// background's radiance where a ray hits nothing.
  double sun_irradiance = 0.0;
  Eigen::Vector3d sun_direction_world = Eigen::Vector3d::UnitZ();
  double sky_irradiance = 0.0;
};

/// The render config of a world: its stereo calibration errors (stereo_baseline_error,
/// stereo_vertical_misalignment_px) on top of base, and its ambient light (sun_strength;
/// the sun's direction drawn from seed on a stream of its own: elevation 20-70 degrees,
/// any azimuth).
RenderConfig renderConfigFor(const WorldConfig& world, RenderConfig base = {},
                             std::uint64_t seed = 0);

struct RenderOptions {
  bool with_leaves = true;  ///< false: render without leaves (occlusion statistic)
  bool images = true;       ///< false: skip the pair (left_bgr/right_bgr stay empty)
  /// The frame's disparity_px from the exact depth, as a robot's own stereo would hand it
  /// over (the exact-depth ablation of docs/design.md section 8; SGBM does not run then).
  bool exact_disparity = false;
};

/// The simulator's exact layers of the left image: what no real camera gives.
struct GroundTruthImages {
  cv::Mat depth_m;    ///< CV_32F z-depth per pixel, 0 where nothing was hit
  cv::Mat object_id;  ///< CV_32S object id (object_ids.h) of the surface at the pixel centre
};

/// A rendered frame with its ground truth beside it.
struct RenderedView {
  host::StereoFrame frame;
  GroundTruthImages ground_truth;
};

class StereoRenderer {
 public:
  /// Builds the Embree scene from a copy of the world; throws std::runtime_error naming the
  /// failed Embree call, and std::invalid_argument for a bad config.
  StereoRenderer(const World& world, const RenderConfig& config = {});
  ~StereoRenderer();
  StereoRenderer(const StereoRenderer&) = delete;
  StereoRenderer& operator=(const StereoRenderer&) = delete;

  /// Renders the pair seen from T_world_camera (the left camera's optical frame).
  host::StereoFrame render(const Eigen::Isometry3d& T_world_camera,
                           const RenderOptions& options = {}) const;
  /// The same, with the exact depth and object ids of the left image.
  RenderedView renderWithGroundTruth(const Eigen::Isometry3d& T_world_camera,
                                     const RenderOptions& options = {}) const;
  /// Wall time of the last render() call, seconds.
  double lastRenderSeconds() const;

  const RenderConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fvp::robot::sim
