// Viewpoint sampling (paper, "Viewpoint Sampling"): ROI-targeted candidates look at ROI
// frontier voxels from a random direction; exploration candidates look at exploration
// frontier voxels from along the frontier's estimated surface normal (away from the
// unknown side). Distances are uniform in [sensor_min_m, sensor_max_m]. Every candidate is a
// full camera pose looking at its target; the reachability filter marks, it does not drop,
// so that plan.json shows what was rejected. Seeded: the same seed and frontiers give the
// same candidates. Sizing candidates look at the fruitlets the automatic stop still waits for,
// from directions their well-seen images lack (sizing_target.h).
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "fvp/host/map/frontier_voxel.h"
#include "fvp/host/planner/planner_config.h"
#include "fvp/host/planner/sizing_target.h"
#include "fvp/host/planner/view_planner.h"

namespace fvp::host::planner {

class ViewpointSampler {
 public:
  ViewpointSampler(const PlannerConfig& config, std::uint64_t seed);

  /// `count` candidates at ROI frontier voxels of `frontiers` (none when there are none).
  std::vector<Candidate> sampleRoi(const std::vector<map::FrontierVoxel>& frontiers, int count,
                                   const ReachabilityFn& reachable);
  /// `count` candidates at exploration frontier voxels (none when there are none). A
  /// frontier without a normal gets a random direction.
  std::vector<Candidate> sampleExploration(const std::vector<map::FrontierVoxel>& frontiers,
                                           int count, const ReachabilityFn& reachable);
  /// Up to `count` candidates, each looking at a target picked at random from a direction
  /// that adds the span it lacks (addsViewSpan); none without targets.
  std::vector<Candidate> sampleSizing(const std::vector<SizingTarget>& targets, int count,
                                      const ReachabilityFn& reachable);

 private:
  static constexpr int kSizingDirectionAttempts = 32;
  std::vector<Candidate> sample(CandidateKind kind,
                                const std::vector<map::FrontierVoxel>& frontiers, int count,
                                const ReachabilityFn& reachable);
  Candidate make(CandidateKind kind, const Eigen::Vector3d& target_m,
                 const Eigen::Vector3d& direction, const ReachabilityFn& reachable);
  Eigen::Vector3d randomUnitVector();

  PlannerConfig config_;
  std::mt19937_64 rng_;
};

}  // namespace fvp::host::planner
