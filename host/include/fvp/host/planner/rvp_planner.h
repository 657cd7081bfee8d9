// RVP, the baseline the paper compares with (Zaenker et al. 2020, roi_viewpoint_planner as
// its public code did it in 2020; docs/design.md section 6), behind the same ViewPlanner
// interface as FVP:
// - ROI targets: free voxels 6-adjacent to an ROI voxel with an unknown 6-neighbour (the ROI
//   contour); a candidate is target + random unit direction x U(sensor_min, sensor_max),
//   looking at the target, kept if reachable. Gain: one ray from the target to the
//   candidate; the candidate is dropped when the ray meets an occupied voxel; IG = unknown
//   voxels / voxels on the ray.
// - Exploration: positions uniform in the reachable box, targets uniform in the sampling
//   (Cluster Region) box; gain over 8 x 6 rays over an 80 degree horizontal field of view,
//   each ray's unknown voxels inside the region (stopping at an occupied one) over its
//   length in voxels, averaged over rays.
// - Utility IG - 0.2 * distance from the current camera; the ROI set when its best utility
//   exceeds 0.2, else the exploration set; moves are tried in order of utility.
// Choices the code and the paper leave open, and what runs here: docs/planner.md.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>

#include "fvp/host/planner/info_gain_evaluator.h"
#include "fvp/host/planner/rvp_config.h"
#include "fvp/host/planner/view_planner.h"

namespace fvp::host::planner {

class RvpPlanner : public ViewPlanner {
 public:
  RvpPlanner(const RvpConfig& config, std::uint64_t seed);
  std::string_view name() const override { return "rvp"; }
  /// One round: the ROI set when its best utility exceeds the threshold, else exploration,
  /// its reachable candidates of finite utility ranked.
  std::optional<Ranking> rank(map::MapEngine& map, const Eigen::Isometry3d& T_world_camera_now,
                              const ReachabilityFn& reachable, std::size_t round,
                              PlanStep& step) override;
  std::string configJson() const override { return config_.toJson(); }

  /// The ROI contour targets of the map (fine grid indices' centres), sorted.
  static std::vector<Eigen::Vector3d> roiContourTargets(map::MapEngine& map);
  /// RVP's ROI gain of a candidate at camera_m for target_m (negative: occluded, dropped).
  double roiGain(const Eigen::Vector3d& target_m, const Eigen::Vector3d& camera_m) const;
  /// RVP's exploration gain of a camera pose.
  double explorationGain(const Eigen::Isometry3d& T_world_camera) const;
  /// Rebuilds the map snapshot the gains read.
  void refresh(map::MapEngine& map) { snapshot_.refresh(map); }

 private:
  RvpConfig config_;
  std::mt19937_64 rng_;
  InfoGainEvaluator snapshot_;
  // The ROI-contour targets hold until new scans arrive: which map and scan count.
  std::vector<Eigen::Vector3d> contour_;
  const map::MapEngine* contour_map_ = nullptr;
  std::size_t contour_scans_ = 0;
};

}  // namespace fvp::host::planner
