// The one interface the loop drives a viewpoint planner through (docs/design.md section 6):
// FVP (ours, Algorithm 1 over ROI-targeted + exploration candidates scored by paper Eq. 1-3)
// and RVP (Zaenker et al. 2020) both implement it, so `fvp run --planner fvp|rvp` and
// `fvp plan` share one path. A planner ranks views; the loop (planAndMove) tries the moves.
// The arm is reached through two callbacks, so the host planner does not depend on robot/: a
// cheap reachability filter (the workspace tree) and the move itself (IK + motion planning +
// execution), whose failure is an expected outcome.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fvp/host/planner/goal_check.h"
#include "fvp/host/planner/sizing_target.h"

namespace fvp::host::map {
class MapEngine;
}

namespace fvp::host::planner {

/// kRemembered: a view an earlier visit took that showed the cluster's fruitlets well
/// (host/nbv/remembered_views.h).
enum class CandidateKind { kRoi, kExploration, kSizing, kRemembered };
/// "roi", "exploration", "sizing" or "remembered" (plan.json's "kind").
const char* toString(CandidateKind kind);

/// One viewpoint candidate: a full camera pose (OpenCV optical frame of the left camera,
/// z forward) looking at its target.
struct Candidate {
  CandidateKind kind = CandidateKind::kRoi;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();
  double ig = 0.0;       ///< information gain (planner-specific definition)
  double utility = 0.0;  ///< ig - cost (paper Eq. 3 for FVP)
  bool reachable = false;
  /// kSizing: which of the planner's sizing targets it looks at; kRemembered: which
  /// remembered view it is (-1 for the other kinds).
  int sizing_target = -1;
  Eigen::Vector3d position_m() const { return T_world_camera.translation(); }
};

/// Whether the arm can put the camera at this pose (workspace tree); cheap, may be optimistic.
using ReachabilityFn = std::function<bool(const Eigen::Isometry3d& T_world_camera)>;
/// Plans and executes a move; false when it failed (no IK, no path, timeout: counted).
using MoveToPoseFn = std::function<bool(const Eigen::Isometry3d& T_world_camera)>;
/// Asked after each failed move of a planning iteration; true ends the iteration without a
/// move (as OMPL's PlannerTerminationCondition ends a query): the caller knows what the
/// failures cost and whether more are worth trying.
using GiveUpFn = std::function<bool()>;

/// Named wall-time parts of one planning iteration (e.g. "snapshot", "sample", "cull",
/// "info_gain", "select"), in seconds, in the order they ran.
using StageTimings = std::vector<std::pair<std::string, double>>;

/// What one planning iteration did.
struct PlanStep {
  /// Every candidate scored this iteration (the last sampling round), reachable or not.
  std::vector<Candidate> candidates;
  /// Index into candidates of the view moved to; empty when no move succeeded.
  std::optional<std::size_t> chosen;
  std::size_t move_attempts = 0;  ///< moveToPose calls this iteration
  std::size_t failed_moves = 0;   ///< of which failed
  bool gave_up = false;           ///< ended by planAndMove's give_up after a failed move
  /// Ranked views the arm's goal check (goal_check.h) was asked about, in how many calls, and
  /// those it turned down before a move was tried (not counted as move attempts).
  std::size_t goal_checks = 0, goal_check_batches = 0;
  std::size_t rejected_no_ik = 0, rejected_no_collision_free_ik = 0;
  std::size_t sampling_rounds = 0;
  /// Reachable candidates dropped before scoring because the camera body would stand in
  /// occupied space (counted, not sent to the motion planner).
  std::size_t rejected_clearance = 0;
  /// Gain rays that Embree found blocked in the coarse map and the walks skipped
  /// (FVP with embree_cull), of gain_rays rays that entered the Cluster Region.
  std::size_t culled_rays = 0, gain_rays = 0;
  StageTimings timings_s;
  bool moved() const { return chosen.has_value(); }
};

/// One sampling round, scored: every candidate, and those the planner would move to, best first
/// (its own threshold applied).
struct Ranking {
  std::vector<Candidate> candidates;
  std::vector<std::size_t> order;  ///< indices into candidates
};

/// Planners rank, the loop acts (OMPL's planners return paths and leave execution to the
/// caller): a planner samples and scores views; planAndMove (below) tries the moves, in one
/// place for every planner, and counts them.
class ViewPlanner {
 public:
  virtual ~ViewPlanner() = default;
  /// "fvp" or "rvp".
  virtual std::string_view name() const = 0;
  /// Sampling round `round` (0, 1, ...) of a planning iteration on the current maps, or
  /// nothing when the planner's rule gives up for this iteration. Round 0 refreshes what
  /// the planner keeps of the maps. T_world_camera_now is the pose the motion cost is
  /// measured from; reachable is the arm's cheap filter. The round's timings and counts go
  /// into step (sampling_rounds, rejected_clearance, rays, timings_s).
  virtual std::optional<Ranking> rank(map::MapEngine& map,
                                      const Eigen::Isometry3d& T_world_camera_now,
                                      const ReachabilityFn& reachable, std::size_t round,
                                      PlanStep& step) = 0;
  /// How the round's moves went: moved to one of its ranked views, or none (FVP decays
  /// its utility threshold then, Algorithm 1 line 18).
  virtual void roundDone(bool moved) { (void)moved; }
  /// The round's view the arm moved to (called before roundDone(true)).
  virtual void movedTo(const Candidate& chosen) { (void)chosen; }
  /// The planner's configuration as JSON text (printed into every result).
  virtual std::string configJson() const = 0;
  /// The fruitlets the automatic stop still waits for, after each sizing (sizing_target.h).
  /// Planners that cannot aim at them ignore them (the default).
  virtual void setSizingTargets(std::vector<SizingTarget> targets) { (void)targets; }
};

/// One planning iteration: the planner's rounds, each round's ranked views tried in order
/// until a move succeeds (Algorithm 1, lines 6-18). PlanStep::candidates are the last
/// round's; move_attempts and failed_moves count every move tried. With check_goals, the
/// ranked views are first checked in batches of goal_check_batch, a batch ahead of the moves
/// (the next one only when the moves of the last have all failed), and a view the check
/// turns down is skipped: counted by its status, neither a move attempt nor a failed move.
/// With view_overhead_s > 0 and the check's travel times, each checked batch is tried by
/// information per second of the robot's time, ig / (travel_s + view_overhead_s): the
/// planner's rule picks the views worth a move, the arm's time orders them
/// (docs/nbv-loop.md, "Views ranked by time"). give_up (optional) is asked after each failed
/// move; when it says so the round ends as one without a move and the iteration ends there.
PlanStep planAndMove(ViewPlanner& planner, map::MapEngine& map,
                     const Eigen::Isometry3d& T_world_camera_now, const ReachabilityFn& reachable,
                     const MoveToPoseFn& move, const GoalCheckFn& check_goals = {},
                     std::size_t goal_check_batch = kDefaultGoalCheckBatch,
                     double view_overhead_s = kDefaultViewOverheadS, const GiveUpFn& give_up = {});

}  // namespace fvp::host::planner
