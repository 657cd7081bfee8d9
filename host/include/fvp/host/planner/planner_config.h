// The FVP planner's parameters (paper, "Viewpoint Planning" and Algorithm 1; docs/design.md
// section 6): sampling, information gain, utility and threshold decay. Every field is a key
// of the same name in host/config/planner_default.yaml, which documents the defaults.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace fvp::host::planner {

/// The most candidates a round may sample (roi_samples, exploration_samples, sizing_samples;
/// the RVP config's too): each is ray cast every round, so 10^7 exhausted memory where the
/// paper samples 200.
inline constexpr int kMaxCandidateSamples = 100'000;

// Paper's protocol: 100 ROI-targeted + 100 exploration candidates per iteration.
inline constexpr int kDefaultRoiSamples = 100;
inline constexpr int kDefaultExplorationSamples = 100;
// Sensor distance from the target. SGBM with 320 disparities saturates nearer than ~0.17 m
// with this camera (fx 1100 px, 5 cm baseline); 0.20 m keeps fruitlets at ~19-40 px radius,
// 0.40 m is the simulated start view's distance.
inline constexpr double kDefaultSensorMinM = 0.20;
inline constexpr double kDefaultSensorMaxM = 0.40;
// Eq. 1's max_d: unknown voxels within 2 cm of a known ROI weigh up to 1, others 0.5.
inline constexpr double kDefaultMaxDM = 0.02;
// Eq. 3's alpha, per metre of camera travel (Zaenker's 0.2 scaled to this IG's range).
inline constexpr double kDefaultAlphaPerM = 0.2;
// Algorithm 1: u_t0 and the decay b < 1.
inline constexpr double kDefaultUtilityThreshold = 0.3;
inline constexpr double kDefaultThresholdDecay = 0.8;
// Sampling rounds per planning call before it returns without a move (each round decays
// the threshold once).
inline constexpr int kDefaultMaxSamplingRounds = 8;
inline constexpr std::int64_t kDefaultPlannerSeed = 1;
// Candidates with an occupied coarse voxel this close to the camera are dropped before the
// motion planner is asked: the camera body (3 cm) plus the collision padding (1 cm) would
// stand in it. 0 disables the check.
inline constexpr double kDefaultCameraClearanceM = 0.04;
// Information gain: the paper's one ray per candidate, or our frustum of rays over the field
// of view (16 x 12 by default).
inline constexpr const char* kDefaultGainMode = "single_ray";
inline constexpr int kDefaultFrustumRaysX = 16;
inline constexpr int kDefaultFrustumRaysY = 12;
// Embree culling of rays blocked in the coarse map before the gain walks. Off by default:
// measured slower than letting the walk stop at the blocking voxel (docs/planner.md).
inline constexpr bool kDefaultEmbreeCull = false;
// Candidates per round aimed at the fruitlets the automatic stop still waits for
// (sizing_target.h), as many as each of the paper's two kinds; only the automatic stop hands
// targets over, so the paper's budget runs sample none. 0: never.
inline constexpr int kDefaultSizingSamples = 100;

struct PlannerConfig {
  int roi_samples = kDefaultRoiSamples;
  int exploration_samples = kDefaultExplorationSamples;
  double sensor_min_m = kDefaultSensorMinM;
  double sensor_max_m = kDefaultSensorMaxM;
  double max_d_m = kDefaultMaxDM;
  double alpha_per_m = kDefaultAlphaPerM;
  double utility_threshold = kDefaultUtilityThreshold;  ///< u_t0
  double threshold_decay = kDefaultThresholdDecay;      ///< b
  int max_sampling_rounds = kDefaultMaxSamplingRounds;
  std::int64_t seed = kDefaultPlannerSeed;  ///< mixed with the trial's seed
  double camera_clearance_m = kDefaultCameraClearanceM;
  std::string gain_mode = kDefaultGainMode;  ///< "single_ray" (paper Eq. 2) or "frustum"
  int frustum_rays_x = kDefaultFrustumRaysX;
  int frustum_rays_y = kDefaultFrustumRaysY;
  bool embree_cull = kDefaultEmbreeCull;
  int sizing_samples = kDefaultSizingSamples;

  /// Reads a YAML file; missing keys keep their defaults; unknown keys, wrong types and
  /// out-of-range values throw std::invalid_argument naming the file and the key.
  static PlannerConfig fromYamlFile(const std::filesystem::path& path);
  /// Throws std::invalid_argument naming the first bad key and what was expected.
  void validate(const std::string& source = "planner config") const;
  /// Every key and value as a JSON object text.
  std::string toJson() const;
};

}  // namespace fvp::host::planner
