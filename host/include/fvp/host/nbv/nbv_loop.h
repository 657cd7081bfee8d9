// The next-best-view loop (paper Algorithm 1's outer loop, docs/design.md section 9) over narrow
// interfaces, so it runs the same on a robot and in the simulator: capture through a Camera
// at the Arm's pose -> perceive and map in the MappingSession -> plan with a ViewPlanner ->
// move the Arm, until the StopCondition holds. Without a successful move it plans again
// without a new capture. The loop holds no ground truth: scoring is the caller's.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "fvp/host/nbv/arm.h"
#include "fvp/host/nbv/camera.h"
#include "fvp/host/nbv/loop_clock.h"
#include "fvp/host/nbv/stop_condition.h"
#include "fvp/host/planner/view_planner.h"
#include "fvp/host/session/mapping_session.h"

namespace fvp::host::nbv {

/// One captured view, as the loop reports it.
struct ViewEvent {
  int index = 0;  ///< 0-based view number
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  const StereoFrame* frame = nullptr;  ///< the frame as captured
  const ViewResult* result = nullptr;  ///< what the session made of it
  double now_s = 0.0;                  ///< the loop clock after the view was mapped
};

/// One planning iteration, as the loop reports it.
struct PlanEvent {
  std::size_t iteration = 0;
  const planner::PlanStep* step = nullptr;
  double planning_s = 0.0;  ///< planner wall time less the moves and goal checks it made
  double now_s = 0.0;
};

/// Progress, logs and per-iteration timings; every hook is optional.
class LoopObserver {
 public:
  virtual ~LoopObserver() = default;
  virtual void onView(const ViewEvent& event) { (void)event; }
  virtual void onPlan(const PlanEvent& event) { (void)event; }
  virtual void onDroppedFrame(const std::string& detail) { (void)detail; }
};

/// NbvLoopOptions::max_failed_plans' default (docs/nbv-loop.md, "Failed plans end an iteration").
inline constexpr std::size_t kDefaultMaxFailedPlans = 6;

struct NbvLoopOptions {
  /// Frames dropped in a row after which the loop stops ("camera_failed"): a camera that
  /// never delivers must not spin the loop forever.
  int max_consecutive_dropped_frames = 10;
  /// Ranked views the arm's goal check (Arm::checkGoal) is asked about per call, ahead of
  /// the moves (planAndMove); 0: no goal checks, every ranked view goes to moveTo.
  std::size_t goal_check_batch = planner::kDefaultGoalCheckBatch;
  /// A view's cost besides its move, for trying each checked batch by information per
  /// second (planAndMove); 0: the planner's own order.
  double view_overhead_s = planner::kDefaultViewOverheadS;
  /// Motion plans that failed (timed out, which costs the arm its whole planning time, or
  /// found no path) after which a planning iteration ends without a move; the stall rule
  /// (StopCondition::stalled), where there is one, then counts it. 0: no limit.
  std::size_t max_failed_plans = kDefaultMaxFailedPlans;
};

/// Counted expected events of a run (never errors).
struct NbvEvents {
  std::size_t planning_iterations = 0, iterations_without_move = 0, move_attempts = 0,
              failed_moves = 0, rejected_clearance = 0, culled_rays = 0, views_without_tag = 0,
              dropped_frames = 0, obstacle_update_count = 0;
  /// Planning iterations ended by NbvLoopOptions::max_failed_plans.
  std::size_t iterations_ended_by_failed_plans = 0;
  /// Moves that first went back the way the arm came in (MoveResult::retreated).
  std::size_t retreats = 0;
  /// The arm's goal checks (PlanStep): poses checked, calls, and ranked views turned down.
  std::size_t goal_checks = 0, goal_check_batches = 0, rejected_no_ik = 0,
              rejected_no_collision_free_ik = 0;
  std::int64_t dropped_disparities = 0, saturated_disparities = 0;
  std::map<std::string, std::size_t> motion_status;  ///< toString(MoveStatus) -> count
};

/// Wall time spent in the loop's parts, seconds.
struct NbvWallTimes {
  double capture = 0.0, perception = 0.0, mapping = 0.0, tsdf = 0.0, planning = 0.0,
         goal_check = 0.0, motion_planning = 0.0, moving = 0.0;
};

struct NbvResult {
  int views = 0;
  /// Why the loop stopped: a StopCondition's reason, "no_region" (the first view showed no
  /// tag: nothing to plan on) or "camera_failed".
  std::string stop_reason;
  std::vector<Eigen::Isometry3d> camera_poses;  ///< of each captured view, in order
  NbvEvents events;
  NbvWallTimes wall_s;
};

class NbvLoop {
 public:
  /// Every reference must outlive the loop. The session holds the maps and the TSDF and
  /// may already hold views.
  NbvLoop(MappingSession& session, planner::ViewPlanner& planner, Camera& camera, Arm& arm,
          LoopClock& clock, NbvLoopOptions options = {});

  /// Runs until stop holds; the observer (optional) hears of each view and iteration.
  NbvResult run(const StopCondition& stop, LoopObserver* observer = nullptr);

 private:
  /// One planning iteration on the map: planAndMove with the arm's reachability, goal checks
  /// and moves, charged to the clock and counted into out; plan_s is the planning's share.
  planner::PlanStep planAndMove_(map::MapEngine& map, NbvResult& out, double& plan_s);

  MappingSession& session_;
  planner::ViewPlanner& planner_;
  Camera& camera_;
  Arm& arm_;
  LoopClock& clock_;
  NbvLoopOptions options_;
};

}  // namespace fvp::host::nbv
