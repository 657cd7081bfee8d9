// NbvLoop's contract, driven by fakes: it captures at the arm's pose, plans again without a
// capture after a failed move, counts refusals and dropped frames, stops when the stop
// condition holds (also between a capture and the planning that would follow it), stops
// without planning when no view showed the tag, and ends an iteration after
// max_failed_plans motion plans failed.
#include "fvp/host/nbv/nbv_loop.h"

#include <gtest/gtest.h>

#include <deque>
#include <optional>

#include "fvp/accel/backend.h"
#include "fvp/host/nbv/nbv_setup.h"
#include "seed2_orbit_frames.h"

namespace fvp::host::nbv {
namespace {

const StereoFrame& renderedFrame(std::size_t i) {
  return test::seed2OrbitFrame(i);
}

class FakeClock : public LoopClock {
 public:
  double now_s() const override { return now_; }
  void chargeCompute(LoopStage stage, double) override {
    ++compute_charges;
    if (stage == LoopStage::kGoalCheck) ++goal_check_charges;
    if (stage == LoopStage::kPerception) ++perception_charges;
  }
  void advance(double s) { now_ += s; }
  int compute_charges = 0, goal_check_charges = 0, perception_charges = 0;

 private:
  double now_ = 0.0;
};

/// Delivers the tagged frame (or the untagged one), dropping the frames whose capture index
/// is listed; each capture takes capture_s on the clock.
class FakeCamera : public Camera {
 public:
  FakeCamera(FakeClock& clock, std::size_t frame = 1) : clock_(clock), frame_(frame) {}
  CaptureResult capture(const Eigen::Isometry3d& T_world_camera) override {
    clock_.advance(capture_s);
    poses.push_back(T_world_camera);
    CaptureResult r;
    if (drop_all || (!drop.empty() && drop.front() == captures)) {
      if (!drop.empty() && drop.front() == captures) drop.pop_front();
      ++captures;
      r.status = CaptureStatus::kDropped;
      r.detail = "timeout";
      return r;
    }
    ++captures;
    r.status = CaptureStatus::kOk;
    r.frame = renderedFrame(frame_);
    return r;
  }
  std::deque<int> drop;  ///< capture indices to drop, ascending
  bool drop_all = false;
  double capture_s = 1.0;
  int captures = 0;
  std::vector<Eigen::Isometry3d> poses;

 private:
  FakeClock& clock_;
  std::size_t frame_;
};

/// An arm that fails every move with `fail_with` when set; else refuses every
/// `refuse_every`-th move (1-based), reports every `retreat_every`-th as having gone back the
/// way in, and moves instantly.
class FakeArm : public Arm {
 public:
  Eigen::Isometry3d cameraPose() const override { return pose_; }
  bool reachable(const Eigen::Isometry3d&) const override { return true; }
  MoveResult moveTo(const Eigen::Isometry3d& T) override {
    ++moves;
    if (fail_with) return {*fail_with, 0.0, 0.0};
    if (retreat_every && moves % retreat_every == 0) {
      pose_ = T;
      return {MoveStatus::kSuccess, 0.0, 0.0, /*retreated=*/true};
    }
    if (refuse_every && moves % refuse_every == 0) return {MoveStatus::kRefused, 0.0, 0.0};
    pose_ = T;
    return {MoveStatus::kSuccess, 0.0, 0.0};
  }
  std::size_t updateObstacles(map::MapEngine&) override { return ++obstacle_updates; }
  bool checksGoals() const override { return checks_goals; }
  /// Every `reject_every`-th goal check (1-based) finds only IK solutions in collision.
  planner::GoalReach checkGoal(const Eigen::Isometry3d&) const override {
    ++goal_checks;
    return {reject_every && goal_checks % reject_every == 0 ? planner::GoalCheck::kNoCollisionFreeIk
                                                            : planner::GoalCheck::kFeasible};
  }
  bool checks_goals = false;
  int reject_every = 0;
  mutable int goal_checks = 0;
  int refuse_every = 0, moves = 0;
  std::optional<MoveStatus> fail_with;  ///< every move fails so
  int retreat_every = 0;                ///< every n-th move goes back the way in first
  std::size_t obstacle_updates = 0;

 private:
  Eigen::Isometry3d pose_ = renderedFrame(1).T_world_camera;
};

/// Offers `per_round` candidates per iteration, 1 cm apart along x from the current pose,
/// ranked when reachable.
class FakePlanner : public planner::ViewPlanner {
 public:
  std::string_view name() const override { return "fake"; }
  std::string configJson() const override { return "{}"; }
  std::optional<planner::Ranking> rank(map::MapEngine&, const Eigen::Isometry3d& T_now,
                                       const planner::ReachabilityFn& reachable, std::size_t round,
                                       planner::PlanStep&) override {
    if (round > 0) return std::nullopt;
    planner::Ranking ranking;
    for (std::size_t k = 0; k < per_round; ++k) {
      planner::Candidate c;
      c.T_world_camera = T_now;
      c.T_world_camera.translation().x() += 0.01 * static_cast<double>(k + 1);
      c.reachable = reachable(c.T_world_camera);
      ranking.candidates.push_back(c);
      if (c.reachable) ranking.order.push_back(k);
    }
    ++calls;
    return ranking;
  }
  int calls = 0;
  std::size_t per_round = 1;
};

struct Rig {
  std::unique_ptr<accel::Backend> backend = accel::createBackend("cpu");
  MappingSession session{PerceptionConfig{}, "grid", map::MapConfig{}, backend.get()};
  FakeClock clock;
  FakeCamera camera{clock};
  FakeArm arm;
  FakePlanner planner;
  NbvLoopOptions options;
  NbvResult run(const StopCondition& stop) {
    return NbvLoop(session, planner, camera, arm, clock, options).run(stop);
  }
};

TEST(NbvLoop, CapturesAtTheArmsPoseUntilTheViewCountAndCountsEachStep) {
  Rig rig;
  const NbvResult r = rig.run(StopCondition::views(3));
  EXPECT_EQ(r.views, 3);
  EXPECT_EQ(r.stop_reason, "max_views");
  // Plans after views 1 and 2; the third view meets the stop before any planning.
  EXPECT_EQ(rig.planner.calls, 2);
  EXPECT_EQ(r.events.planning_iterations, 2u);
  EXPECT_EQ(r.events.motion_status.at("success"), 2u);
  ASSERT_EQ(rig.camera.poses.size(), 3u);
  EXPECT_NEAR(rig.camera.poses[2].translation().x() - rig.camera.poses[0].translation().x(), 0.02,
              1e-12);
  EXPECT_EQ(r.camera_poses.size(), 3u);
  EXPECT_EQ(rig.arm.obstacle_updates, 2u);  // after each new view that was planned on
  EXPECT_EQ(r.events.obstacle_update_count, 1u + 2u);
}

TEST(NbvLoop, AViewTheGoalCheckTurnsDownIsNotMovedToAndEachBatchIsCharged) {
  Rig rig;
  rig.arm.checks_goals = true;
  rig.arm.reject_every = 2;  // the second planning iteration's view has no free IK solution
  const NbvResult r = rig.run(StopCondition::views(3));
  EXPECT_EQ(r.views, 3);
  EXPECT_EQ(r.events.planning_iterations, 3u);
  EXPECT_EQ(r.events.goal_checks, 3u);
  EXPECT_EQ(r.events.goal_check_batches, 3u);
  EXPECT_EQ(r.events.rejected_no_collision_free_ik, 1u);
  EXPECT_EQ(r.events.rejected_no_ik, 0u);
  EXPECT_EQ(r.events.move_attempts, 2u);  // the turned-down view never reached moveTo
  EXPECT_EQ(r.events.failed_moves, 0u);
  EXPECT_EQ(rig.arm.moves, 2);
  EXPECT_EQ(r.events.iterations_without_move, 1u);
  EXPECT_EQ(rig.clock.goal_check_charges, 3);  // each batch a compute stage of its own
  EXPECT_EQ(rig.clock.perception_charges, 3);  // each view's perception, once
}

TEST(NbvLoop, NoGoalChecksWhenTheArmHasNoneOrTheyAreOff) {
  Rig without;
  without.run(StopCondition::views(2));
  EXPECT_EQ(without.clock.goal_check_charges, 0);
  Rig off;
  off.arm.checks_goals = true;
  off.options.goal_check_batch = 0;
  const NbvResult r = off.run(StopCondition::views(2));
  EXPECT_EQ(off.arm.goal_checks, 0);
  EXPECT_EQ(r.events.goal_checks, 0u);
  EXPECT_EQ(off.clock.goal_check_charges, 0);
}

TEST(NbvLoop, MovesThatWentBackTheWayInAreCounted) {
  Rig rig;
  rig.arm.retreat_every = 2;
  const NbvResult r = rig.run(StopCondition::views(5));  // four moves
  EXPECT_EQ(r.events.retreats, 2u);
  EXPECT_EQ(r.events.motion_status.at("success"), 4u);
}

TEST(NbvLoop, ARefusedMoveIsCountedAndPlannedAgainWithoutACapture) {
  Rig rig;
  rig.arm.refuse_every = 2;  // every other move refused
  const NbvResult r = rig.run(StopCondition::views(4));
  EXPECT_EQ(r.views, 4);
  EXPECT_EQ(rig.camera.captures, 4);  // no capture after a refused move
  EXPECT_EQ(r.events.motion_status.at("refused"), 2u);
  EXPECT_EQ(r.events.motion_status.at("success"), 3u);
  EXPECT_EQ(r.events.failed_moves, 2u);
  EXPECT_EQ(r.events.iterations_without_move, 2u);
  EXPECT_EQ(r.events.planning_iterations, 5u);
  // The map did not change after a refused move: the arm's obstacles were not rebuilt.
  EXPECT_EQ(rig.arm.obstacle_updates, 3u);
}

TEST(NbvLoop, DroppedFramesAreCountedAndCapturedAgain) {
  Rig rig;
  rig.camera.drop = {1, 2};  // the second and third captures fail
  const NbvResult r = rig.run(StopCondition::views(2));
  EXPECT_EQ(r.views, 2);
  EXPECT_EQ(r.events.dropped_frames, 2u);
  EXPECT_EQ(rig.camera.captures, 4);
  EXPECT_EQ(rig.planner.calls, 1);
  EXPECT_EQ(rig.clock.perception_charges, 2);  // a dropped frame has nothing to perceive
}

TEST(NbvLoop, ACameraThatNeverDeliversStopsTheLoop) {
  Rig rig;
  rig.camera.drop_all = true;
  const NbvResult r = rig.run(StopCondition::views(2));
  EXPECT_EQ(r.stop_reason, "camera_failed");
  EXPECT_EQ(r.views, 0);
  EXPECT_EQ(r.events.dropped_frames, std::size_t(NbvLoopOptions{}.max_consecutive_dropped_frames));
}

TEST(NbvLoop, ABudgetSpentByACaptureStopsBeforeThePlanningThatWouldFollow) {
  Rig rig;
  rig.camera.capture_s = 10.0;
  const NbvResult r = rig.run(StopCondition::budget(15.0) || StopCondition::views(100));
  EXPECT_EQ(r.stop_reason, "budget");
  EXPECT_EQ(r.views, 2);  // at 10 s and 20 s
  EXPECT_EQ(rig.planner.calls, 1);
}

TEST(NbvLoop, AUserPredicateStopsTheLoop) {
  Rig rig;
  const StopCondition enough({[](const LoopState& s) { return s.iterations >= 3; }, "enough"});
  const NbvResult r = rig.run(enough || StopCondition::views(100));
  EXPECT_EQ(r.stop_reason, "enough");
  EXPECT_EQ(r.events.planning_iterations, 3u);
}

TEST(NbvLoop, NoTagInTheFirstViewStopsWithoutPlanning) {
  Rig rig;
  FakeCamera untagged(rig.clock, 0);
  const NbvResult r =
      NbvLoop(rig.session, rig.planner, untagged, rig.arm, rig.clock).run(StopCondition::views(3));
  EXPECT_EQ(r.stop_reason, "no_region");
  EXPECT_EQ(r.views, 1);
  EXPECT_EQ(r.events.views_without_tag, 1u);
  EXPECT_EQ(rig.planner.calls, 0);
}

TEST(NbvLoop, APlannerThatCannotMoveStopsTheLoopOnceStalled) {
  Rig rig;
  rig.arm.refuse_every = 1;  // every move refused: no second view
  const NbvResult r = rig.run(StopCondition::stalled(3) || StopCondition::views(5));
  EXPECT_EQ(r.stop_reason, "no_reachable_view");
  EXPECT_EQ(r.views, 1);
  EXPECT_EQ(r.events.planning_iterations, 3u);
  EXPECT_EQ(r.events.iterations_without_move, 3u);
}

TEST(NbvLoop, AMoveStartsTheStallCountAfresh) {
  Rig rig;
  rig.arm.refuse_every = 2;  // one iteration without a view between views
  const NbvResult r = rig.run(StopCondition::stalled(2) || StopCondition::views(4));
  EXPECT_EQ(r.stop_reason, "max_views");
  EXPECT_EQ(r.events.iterations_without_move, 2u);
}

TEST(NbvLoop, FailedPlansEndAnIterationAndTheStallRuleEndsTheLoop) {
  for (const MoveStatus status : {MoveStatus::kTimeout, MoveStatus::kNoPath}) {
    Rig rig;
    rig.planner.per_round = 10;
    rig.arm.fail_with = status;
    rig.options.max_failed_plans = 3;
    const NbvResult r = rig.run(StopCondition::stalled(2) || StopCondition::views(5));
    EXPECT_EQ(r.stop_reason, "no_reachable_view") << toString(status);
    EXPECT_EQ(r.events.planning_iterations, 2u) << toString(status);
    EXPECT_EQ(r.events.move_attempts, 6u) << toString(status);  // 3 of each iteration's 10
    EXPECT_EQ(r.events.motion_status.at(toString(status)), 6u);
    EXPECT_EQ(r.events.iterations_ended_by_failed_plans, 2u) << toString(status);
  }
}

TEST(NbvLoop, OnlyFailedPlansEndAnIteration) {
  // Failures before any planning, and after a plan was found, do not count.
  for (const MoveStatus status :
       {MoveStatus::kNoIk, MoveStatus::kNoCollisionFreeIk, MoveStatus::kStartInvalid,
        MoveStatus::kRefused, MoveStatus::kExecutionFailed}) {
    Rig rig;
    rig.planner.per_round = 10;
    rig.arm.fail_with = status;
    rig.options.max_failed_plans = 3;
    const NbvResult r = rig.run(StopCondition::stalled(1) || StopCondition::views(5));
    EXPECT_EQ(r.events.move_attempts, 10u) << toString(status);
    EXPECT_EQ(r.events.iterations_ended_by_failed_plans, 0u) << toString(status);
  }
  Rig unlimited;
  unlimited.planner.per_round = 10;
  unlimited.arm.fail_with = MoveStatus::kNoPath;
  unlimited.options.max_failed_plans = 0;
  const NbvResult r = unlimited.run(StopCondition::stalled(1) || StopCondition::views(5));
  EXPECT_EQ(r.events.move_attempts, 10u);
  EXPECT_EQ(r.events.iterations_ended_by_failed_plans, 0u);
}

TEST(StopCondition, RefusesNonsenseAndReportsTheFirstThatHolds) {
  EXPECT_THROW(StopCondition::stalled(0), std::invalid_argument);
  EXPECT_THROW(StopCondition::budget(0.0), std::invalid_argument);
  EXPECT_THROW(StopCondition::budget(INFINITY), std::invalid_argument);
  EXPECT_THROW(StopCondition::views(0), std::invalid_argument);
  const StopCondition both = StopCondition::views(2) || StopCondition::budget(5.0);
  EXPECT_FALSE(both.check({1, 0, 1.0, 0}));
  EXPECT_EQ(both.check({2, 0, 9.0, 0}), "max_views");
  EXPECT_EQ(both.check({1, 0, 9.0, 0}), "budget");
}

// The setup's disparity_window decides every cluster's perception, over the perception
// config's own (a config read from a file does not carry it).
TEST(NbvSetup, DisparityWindowReachesEveryClustersPerception) {
  for (const bool window : {false, true}) {
    NbvSetupOptions options;
    options.backend = accel::BackendChoice::kCpu;
    options.disparity_window = window;
    options.perception.disparity_window = !window;
    NbvSetup setup(options);
    for (std::size_t k = 0; k < 2; ++k)
      EXPECT_EQ(setup.makeWork({}, k)->session->perception().config().disparity_window, window);
  }
}

}  // namespace
}  // namespace fvp::host::nbv
