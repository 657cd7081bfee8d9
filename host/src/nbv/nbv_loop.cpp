#include "fvp/host/nbv/nbv_loop.h"

#include <chrono>
#include <vector>

namespace fvp::host::nbv {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

const char* toString(MoveStatus status) {
  switch (status) {
    case MoveStatus::kSuccess:
      return "success";
    case MoveStatus::kNoIk:
      return "no_ik";
    case MoveStatus::kNoCollisionFreeIk:
      return "no_collision_free_ik";
    case MoveStatus::kStartInvalid:
      return "start_invalid";
    case MoveStatus::kNoPath:
      return "no_path";
    case MoveStatus::kTimeout:
      return "timeout";
    case MoveStatus::kRefused:
      return "refused";
    case MoveStatus::kExecutionFailed:
      return "execution_failed";
  }
  return "unknown";
}

NbvLoop::NbvLoop(MappingSession& session, planner::ViewPlanner& planner, Camera& camera, Arm& arm,
                 LoopClock& clock, NbvLoopOptions options)
    : session_(session),
      planner_(planner),
      camera_(camera),
      arm_(arm),
      clock_(clock),
      options_(options) {}

planner::PlanStep NbvLoop::planAndMove_(map::MapEngine& map, NbvResult& out, double& plan_s) {
  NbvEvents& events = out.events;
  // Planning is charged as its wall time less the moves it made (the arm's own time is
  // the arm's to account for: a simulated arm charges the simulated clock itself) and the
  // goal checks, each batch of which is a compute stage of its own.
  double move_wall_s = 0.0, goal_check_wall_s = 0.0;
  std::size_t failed_plans = 0;
  const planner::ReachabilityFn reachable = [&](const Eigen::Isometry3d& T) {
    return arm_.reachable(T);
  };
  const planner::MoveToPoseFn move = [&](const Eigen::Isometry3d& T) {
    const auto t_move = Clock::now();
    const MoveResult moved = arm_.moveTo(T);
    move_wall_s += secondsSince(t_move);
    out.wall_s.motion_planning += moved.planning_wall_s;
    ++events.motion_status[toString(moved.status)];
    events.retreats += moved.retreated ? 1 : 0;
    if (moved.status == MoveStatus::kTimeout || moved.status == MoveStatus::kNoPath) ++failed_plans;
    return moved.ok();
  };
  const planner::GiveUpFn give_up = [&] {
    return options_.max_failed_plans > 0 && failed_plans >= options_.max_failed_plans;
  };
  planner::GoalCheckFn check_goals;
  if (arm_.checksGoals() && options_.goal_check_batch > 0) {
    check_goals = [&](const std::vector<Eigen::Isometry3d>& poses) {
      const auto t_check = Clock::now();
      std::vector<planner::GoalReach> statuses;
      statuses.reserve(poses.size());
      for (const Eigen::Isometry3d& T : poses) statuses.push_back(arm_.checkGoal(T));
      const double check_s = secondsSince(t_check);
      goal_check_wall_s += check_s;
      clock_.chargeCompute(LoopStage::kGoalCheck, check_s);
      return statuses;
    };
  }
  const auto t_plan = Clock::now();
  planner::PlanStep step =
      planner::planAndMove(planner_, map, arm_.cameraPose(), reachable, move, check_goals,
                           options_.goal_check_batch, options_.view_overhead_s, give_up);
  plan_s = std::max(0.0, secondsSince(t_plan) - move_wall_s - goal_check_wall_s);
  out.wall_s.planning += plan_s;
  out.wall_s.goal_check += goal_check_wall_s;
  out.wall_s.moving += move_wall_s;
  clock_.chargeCompute(LoopStage::kPlanning, plan_s);
  ++events.planning_iterations;
  events.move_attempts += step.move_attempts;
  events.failed_moves += step.failed_moves;
  events.iterations_ended_by_failed_plans += step.gave_up ? 1 : 0;
  events.rejected_clearance += step.rejected_clearance;
  events.goal_checks += step.goal_checks;
  events.goal_check_batches += step.goal_check_batches;
  events.rejected_no_ik += step.rejected_no_ik;
  events.rejected_no_collision_free_ik += step.rejected_no_collision_free_ik;
  events.culled_rays += step.culled_rays;
  return step;
}

NbvResult NbvLoop::run(const StopCondition& stop, LoopObserver* observer) {
  NbvResult out;
  NbvEvents& events = out.events;
  LoopState state;
  std::size_t iterations_without_view = 0;
  const auto update = [&] {
    state.views = out.views;
    state.iterations = events.planning_iterations;
    state.now_s = clock_.now_s();
    state.dropped_frames = events.dropped_frames;
    state.iterations_without_view = iterations_without_view;
  };
  const auto stopped = [&] {
    update();
    if (const auto reason = stop.check(state)) {
      out.stop_reason = *reason;
      return true;
    }
    return false;
  };
  bool capture_next = true;
  int dropped_in_a_row = 0;
  std::size_t obstacle_scans = 0;  // the map's scan count when the arm last got it

  while (!stopped()) {
    clock_.beginIteration();
    if (capture_next) {
      const Eigen::Isometry3d T_world_camera = arm_.cameraPose();
      const auto t_capture = Clock::now();
      const CaptureResult captured = camera_.capture(T_world_camera);
      out.wall_s.capture += secondsSince(t_capture);
      if (!captured.ok()) {
        ++events.dropped_frames;
        if (observer) observer->onDroppedFrame(captured.detail);
        if (++dropped_in_a_row >= options_.max_consecutive_dropped_frames) {
          out.stop_reason = "camera_failed";
          break;
        }
        continue;  // capture again at the same pose
      }
      dropped_in_a_row = 0;
      const ViewResult view = session_.addView(captured.frame);
      out.wall_s.perception += view.perceive_s;
      out.wall_s.mapping += view.scan.seconds;
      out.wall_s.tsdf += view.tsdf_s;
      clock_.chargeCompute(LoopStage::kPerception, view.perceive_s);
      clock_.chargeCompute(LoopStage::kMapping, view.scan.seconds);
      clock_.chargeCompute(LoopStage::kTsdf, view.tsdf_s);
      clock_.recordStereoMatching(view.perception.sgbm_s);
      events.dropped_disparities += view.perception.droppedDisparities();
      events.saturated_disparities += view.perception.saturated;
      if (!view.tag_detected) ++events.views_without_tag;
      out.camera_poses.push_back(captured.frame.T_world_camera);
      ++out.views;
      if (observer)
        observer->onView(
            {out.views - 1, captured.frame.T_world_camera, &captured.frame, &view, clock_.now_s()});
      if (stopped()) break;
    }
    map::MapEngine* map = session_.map();
    if (!map) {
      // No Cluster Region yet: the first view saw no tag. Nothing to plan on; an expected
      // outcome of a heavily occluded tag, reported, never a crash.
      out.stop_reason = "no_region";
      break;
    }
    // The arm's obstacles follow the map after new scans only (planning again after a
    // failed move keeps them); that is map upkeep, charged as mapping.
    if (obstacle_scans != map->scanCount()) {
      const auto t_obstacles = Clock::now();
      events.obstacle_update_count += arm_.updateObstacles(*map);
      obstacle_scans = map->scanCount();
      const double obstacles_s = secondsSince(t_obstacles);
      out.wall_s.mapping += obstacles_s;
      clock_.chargeCompute(LoopStage::kMapping, obstacles_s);
    }
    double plan_s = 0.0;
    const planner::PlanStep step = planAndMove_(*map, out, plan_s);
    if (observer) observer->onPlan({events.planning_iterations - 1, &step, plan_s, clock_.now_s()});
    // Without a move a new capture would see the same view: plan again (the planner's
    // threshold has decayed) until a move succeeds or the loop stops.
    capture_next = step.moved();
    if (step.moved()) {
      iterations_without_view = 0;
    } else {
      ++events.iterations_without_move;
      ++iterations_without_view;
    }
  }
  return out;
}

}  // namespace fvp::host::nbv
