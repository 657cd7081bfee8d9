// The FVP planner (paper, "Viewpoint Planning", Algorithm 1): ROI-targeted + exploration
// candidates, scored by information gain (Eq. 1-2) minus alpha times the distance the camera
// moves (Eq. 3), all in one heap; candidates are popped while their utility exceeds the
// threshold u_t until the motion planner reaches one. A round without a move decays u_t by b
// and samples again; a move resets u_t to u_t0. u_t persists across calls.
#pragma once

#include <cstdint>
#include <string>

#include "fvp/host/map/frontier_voxel.h"
#include "fvp/host/planner/info_gain_evaluator.h"
#include "fvp/host/planner/planner_config.h"
#include "fvp/host/planner/view_planner.h"
#include "fvp/host/planner/viewpoint_sampler.h"

namespace fvp::host::planner {

class FvpPlanner : public ViewPlanner {
 public:
  /// seed: the trial's; mixed with config.seed so trials differ and repeat. backend: where
  /// the information-gain walks run (null: on the host, without a backend).
  FvpPlanner(const PlannerConfig& config, std::uint64_t seed, accel::Backend* backend = nullptr);

  std::string_view name() const override { return "fvp"; }
  /// Algorithm 1's rounds: up to max_sampling_rounds; ranks the reachable candidates whose
  /// utility exceeds the current threshold.
  std::optional<Ranking> rank(map::MapEngine& map, const Eigen::Isometry3d& T_world_camera_now,
                              const ReachabilityFn& reachable, std::size_t round,
                              PlanStep& step) override;
  /// Resets the threshold after a move (line 16), decays it after a round without (line 18).
  void roundDone(bool moved) override;
  std::string configJson() const override;
  /// With sizing_samples > 0, each sampling round also aims that many candidates at these
  /// (scored by the fraction of the fruitlet the map predicts in view, when it reaches the
  /// target's min_visible_fraction; else 0), minus the same travel cost.
  void setSizingTargets(std::vector<SizingTarget> targets) override {
    sizing_targets_ = std::move(targets);
  }

  /// The current threshold u_t.
  double utilityThreshold() const { return u_t_; }
  const PlannerConfig& config() const { return config_; }

  /// Scores candidates in place (IG of the reachable ones in one batch; Eq. 3), using the
  /// snapshot of the last refresh. Unreachable candidates keep IG 0 and utility -infinity.
  /// stats: what the gain evaluation did (rays, Embree culling, walk time), if wanted.
  void score(std::vector<Candidate>& candidates, const Eigen::Vector3d& camera_m,
             EvaluateStats* stats = nullptr) const;
  /// Rebuilds the distance field and the gain snapshot; returns its wall time.
  double refresh(map::MapEngine& map) { return gain_.refresh(map); }

 private:
  PlannerConfig config_;
  ViewpointSampler sampler_;
  InfoGainEvaluator gain_;
  double u_t_;
  // The frontiers hold until new scans arrive (planning again after failed moves reuses
  // them): which map and scan count they were extracted from.
  std::vector<map::FrontierVoxel> frontiers_;
  const map::MapEngine* frontiers_map_ = nullptr;
  std::size_t frontiers_scans_ = 0;
  std::vector<SizingTarget> sizing_targets_;
};

}  // namespace fvp::host::planner
