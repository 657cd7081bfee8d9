// PlannedArm, the real-robot arm, over a fake driver: an executor that records every
// trajectory and moves, refuses, fails halfway or claims a move it did not make; the joint
// state it moves. Planning is reproducible (seeded, check budgets), so every case is
// deterministic.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "fvp/host/core/cluster_region.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/planner/view_planner.h"
#include "fvp/robot/ik_reachability.h"
#include "fvp/robot/planned_arm.h"
#include "fvp/robot/sim/simulated_arm.h"
#include "fvp/robot/sim/world.h"

namespace fvp::robot {
namespace {

using host::nbv::MoveStatus;
using host::planner::GoalCheck;
using host::planner::GoalReach;

class FakeJointState : public JointStateSource {
 public:
  explicit FakeJointState(const JointVector& q) : q(q) {}
  JointVector jointPositions() const override { return q; }
  JointVector q;
};

class RecordingExecutor : public TrajectoryExecutor {
 public:
  enum class Mode { kMove, kRefuse, kFailHalfway, kClaimDone };
  RecordingExecutor(FakeJointState& joints, Mode mode) : joints_(joints), mode(mode) {}

  ExecutionResult execute(const Trajectory& trajectory) override {
    trajectories.push_back(trajectory);
    starts.push_back(joints_.q);
    switch (mode) {
      case Mode::kMove:
        joints_.q = trajectory.position(trajectory.duration_s());
        return {ExecutionStatus::kDone, {}};
      case Mode::kRefuse:
        return {ExecutionStatus::kRefused, "operator said no"};
      case Mode::kFailHalfway:
        joints_.q = trajectory.position(0.5 * trajectory.duration_s());
        return {ExecutionStatus::kFailed, "protective stop"};
      case Mode::kClaimDone:
        return {ExecutionStatus::kDone, {}};
    }
    return {};
  }

  std::vector<Trajectory> trajectories;
  std::vector<JointVector> starts;  ///< the joints when each trajectory was handed over

 private:
  FakeJointState& joints_;

 public:
  Mode mode;
};

/// The fake robot: model, reachability, joint state, executor and the arm over them.
struct FakeRobot {
  explicit FakeRobot(RecordingExecutor::Mode mode)
      : model(ArmConfig{}),
        reachability(model),
        joints(model.homeConfiguration()),
        executor(joints, mode),
        arm(model, reachability, joints, executor) {
    arm.setReproducibleMotionPlanning(17);
  }
  /// A pose the arm reaches from home: the camera of another configuration.
  Eigen::Isometry3d reachableGoal() const {
    JointVector target = model.homeConfiguration();
    target[0] = -0.3;
    target[1] = 0.4;
    return model.T_world_camera(target);
  }

  ArmModel model;
  IkReachability reachability;
  FakeJointState joints;
  RecordingExecutor executor;
  PlannedArm arm;
};

double rotationError_rad(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.rotation().transpose() * b.rotation()).angle();
}

TEST(PlannedArm, AReachablePoseMovesAlongATrajectoryFromTheCurrentJointsToTheGoal) {
  FakeRobot robot(RecordingExecutor::Mode::kMove);
  const JointVector start = robot.joints.q;
  const Eigen::Isometry3d goal = robot.reachableGoal();
  ASSERT_TRUE(robot.arm.reachable(goal));
  int plans_observed = 0;
  robot.arm.setPlanningObserver([&](const MotionPlan&) { ++plans_observed; });

  const host::nbv::MoveResult moved = robot.arm.moveTo(goal);
  ASSERT_EQ(moved.status, MoveStatus::kSuccess);
  EXPECT_GT(moved.planning_wall_s, 0.0);
  EXPECT_EQ(plans_observed, 1);
  ASSERT_EQ(robot.executor.trajectories.size(), 1u);
  const Trajectory& trajectory = robot.executor.trajectories[0];
  EXPECT_EQ(trajectory.waypoints().front(), start);
  EXPECT_EQ(trajectory.position(0.0), start);
  EXPECT_GT(trajectory.duration_s(), 0.0);
  EXPECT_EQ(moved.motion_s, trajectory.duration_s());  // the arm's time in motion
  const Eigen::Isometry3d T_end = robot.model.T_world_camera(trajectory.waypoints().back());
  EXPECT_LT((T_end.translation() - goal.translation()).norm(), 1e-6);
  EXPECT_LT(rotationError_rad(T_end, goal), 1e-6);
  // The arm reports where the joint state says it is: at the goal.
  EXPECT_LT((robot.arm.cameraPose().translation() - goal.translation()).norm(), 1e-6);
  EXPECT_LT(rotationError_rad(robot.arm.cameraPose(), goal), 1e-6);
}

TEST(PlannedArm, ARefusedTrajectoryIsRefusedAndTheArmStaysWhereItWas) {
  FakeRobot robot(RecordingExecutor::Mode::kRefuse);
  const JointVector start = robot.joints.q;
  const Eigen::Isometry3d T_before = robot.arm.cameraPose();
  const PlannedMove move = robot.arm.moveToPose(robot.reachableGoal());
  EXPECT_EQ(move.status, MoveStatus::kRefused);
  EXPECT_TRUE(move.plan.ok());
  EXPECT_EQ(move.execution.detail, "operator said no");
  EXPECT_EQ(robot.executor.trajectories.size(), 1u);
  EXPECT_EQ(robot.arm.joints(), start);
  EXPECT_TRUE(robot.arm.cameraPose().isApprox(T_before, 0.0));
  EXPECT_EQ(move.result().status, MoveStatus::kRefused);
  EXPECT_EQ(move.result().planning_wall_s, move.plan.planning_wall_s);
  EXPECT_EQ(move.result().motion_s, 0.0);  // refused: the arm did not move
}

TEST(PlannedArm, AnExecutionThatStopsShortFails) {
  FakeRobot robot(RecordingExecutor::Mode::kFailHalfway);
  EXPECT_EQ(robot.arm.moveTo(robot.reachableGoal()).status, MoveStatus::kExecutionFailed);
  // The next plan starts where the arm stopped.
  robot.executor.mode = RecordingExecutor::Mode::kMove;
  const JointVector stopped = robot.joints.q;
  EXPECT_EQ(robot.arm.moveTo(robot.reachableGoal()).status, MoveStatus::kSuccess);
  ASSERT_EQ(robot.executor.trajectories.size(), 2u);
  EXPECT_EQ(robot.executor.trajectories[1].waypoints().front(), stopped);
}

TEST(PlannedArm, DoneWithoutReachingTheEndIsAnExecutionFailure) {
  FakeRobot robot(RecordingExecutor::Mode::kClaimDone);
  const PlannedMove move = robot.arm.moveToPose(robot.reachableGoal());
  EXPECT_EQ(move.status, MoveStatus::kExecutionFailed);
  EXPECT_EQ(move.execution.status, ExecutionStatus::kFailed);
  EXPECT_NE(move.execution.detail.find("trajectory's end"), std::string::npos);
}

TEST(PlannedArm, PlanningFailuresAreStatusesAndNothingIsExecuted) {
  FakeRobot robot(RecordingExecutor::Mode::kMove);
  int plans_observed = 0;
  robot.arm.setPlanningObserver([&](const MotionPlan&) { ++plans_observed; });
  Eigen::Isometry3d far = robot.arm.cameraPose();
  far.translation().y() += 3.0;
  EXPECT_FALSE(robot.arm.reachable(far));
  EXPECT_EQ(robot.arm.moveTo(far).status, MoveStatus::kNoIk);

  // A wall of voxels through the home camera position, the arm away along the slider:
  // solutions exist, all collide.
  const Eigen::Isometry3d goal = robot.model.T_world_camera(robot.model.homeConfiguration());
  robot.joints.q[0] = 0.4;
  const JointVector start = robot.joints.q;
  octomap::OcTree wall(0.02);
  for (double x = -0.2; x <= 0.2; x += 0.01)
    for (double z = -0.2; z <= 0.2; z += 0.01)
      wall.updateNode(goal.translation().x() + x, goal.translation().y(),
                      goal.translation().z() + z, true);
  EXPECT_EQ(robot.arm.setMap(wall), 0u);  // the arm stands clear of the wall
  EXPECT_EQ(robot.arm.moveTo(goal).status, MoveStatus::kNoCollisionFreeIk);
  EXPECT_EQ(plans_observed, 2);
  EXPECT_TRUE(robot.executor.trajectories.empty());
  EXPECT_EQ(robot.arm.joints(), start);
}

/// A wall of 1 cm voxels, 0.6 m square, across the camera's optical axis ahead_m in front of it.
octomap::OcTree wallAcrossTheView(const Eigen::Isometry3d& T_world_camera, double ahead_m) {
  octomap::OcTree wall(0.01);
  for (double u = -0.3; u <= 0.3; u += 0.01)
    for (double v = -0.3; v <= 0.3; v += 0.01) {
      const Eigen::Vector3d p_world = T_world_camera * Eigen::Vector3d(u, v, ahead_m);
      wall.updateNode(p_world.x(), p_world.y(), p_world.z(), true);
    }
  return wall;
}

/// The arm at a generated world's start view (the camera level, looking at the cluster); a
/// wall across that view WALL_AHEAD_M in front of the camera; a view VIEW_AHEAD_M ahead,
/// behind the wall (the flange, 6 cm behind the lens, and the wrist would stand in it), and
/// one 5 cm back, in front of it.
struct WallScene {
  static constexpr double kWallAhead_m = 0.06, kViewAhead_m = 0.12;
  explicit WallScene(FakeRobot& robot)
      : T_start(sim::World::generate(sim::WorldConfig{}, 1).startCameraPose()),
        behind(T_start * Eigen::Translation3d(0.0, 0.0, kViewAhead_m)),
        in_front(T_start * Eigen::Translation3d(0.0, 0.0, -0.05)),
        wall(wallAcrossTheView(T_start, kWallAhead_m)) {
    const auto start = sim::SimulatedArm::startConfiguration(robot.model, T_start);
    if (!start) throw std::logic_error("the start view of world 1 is out of reach");
    robot.joints.q = *start;
  }
  Eigen::Isometry3d T_start, behind, in_front;
  octomap::OcTree wall;
};

TEST(PlannedArm, TheGoalCheckTurnsDownAViewBehindAWallWithoutPlanningAndKeepsOneInFront) {
  FakeRobot robot(RecordingExecutor::Mode::kMove);
  const WallScene scene(robot);
  int plans_observed = 0;
  robot.arm.setPlanningObserver([&](const MotionPlan&) { ++plans_observed; });
  Eigen::Isometry3d far = robot.arm.cameraPose();
  far.translation().y() += 3.0;
  EXPECT_TRUE(robot.arm.checksGoals());
  // Without the wall both views have a goal.
  ASSERT_EQ(robot.arm.checkGoal(scene.behind).check, GoalCheck::kFeasible);
  const GoalReach in_front = robot.arm.checkGoal(scene.in_front);
  ASSERT_EQ(in_front.check, GoalCheck::kFeasible);
  EXPECT_GT(in_front.travel_s, 0.0);  // a feasible answer says how long the move takes
  EXPECT_EQ(robot.arm.checkGoal(far).check, GoalCheck::kNoIk);
  EXPECT_TRUE(std::isnan(robot.arm.checkGoal(far).travel_s));
  ASSERT_EQ(robot.arm.setMap(scene.wall), 0u);  // the arm stands clear of the wall
  EXPECT_EQ(robot.arm.checkGoal(scene.behind).check, GoalCheck::kNoCollisionFreeIk);
  EXPECT_EQ(robot.arm.checkGoal(scene.in_front).check, GoalCheck::kFeasible);
  EXPECT_EQ(plans_observed, 0);  // nothing planned, nothing executed
  EXPECT_TRUE(robot.executor.trajectories.empty());
  // What the check said is what the moves find.
  EXPECT_EQ(robot.arm.moveTo(scene.behind).status, MoveStatus::kNoCollisionFreeIk);
  EXPECT_EQ(robot.arm.moveTo(scene.in_front).status, MoveStatus::kSuccess);
  // Nothing between: the straight motion to the checked goal, in the time the check gave.
  ASSERT_EQ(robot.executor.trajectories.size(), 1u);
  EXPECT_EQ(robot.executor.trajectories.back().waypoints().size(), 2u);
  EXPECT_DOUBLE_EQ(robot.executor.trajectories.back().duration_s(), in_front.travel_s);
}

TEST(PlannedArm, TravelTimeBetweenTwoPosesIsTheCheckedGoalsStraightMotion) {
  FakeRobot robot(RecordingExecutor::Mode::kMove);
  const WallScene scene(robot);
  Eigen::Isometry3d far = robot.arm.cameraPose();
  far.translation().y() += 3.0;
  // From where the camera is: the goal check's time.
  const double here_to_front = robot.arm.travelTime_s(scene.T_start, scene.in_front);
  EXPECT_DOUBLE_EQ(here_to_front, robot.arm.checkGoal(scene.in_front).travel_s);
  // Between two other poses: there and back take time, nothing for staying.
  const double front_to_behind = robot.arm.travelTime_s(scene.in_front, scene.behind);
  EXPECT_GT(front_to_behind, 0.0);
  EXPECT_GT(robot.arm.travelTime_s(scene.behind, scene.in_front), 0.0);
  EXPECT_DOUBLE_EQ(robot.arm.travelTime_s(scene.in_front, scene.in_front), 0.0);
  // Out of reach at either end, or behind the wall once it is known: unknown.
  EXPECT_TRUE(std::isnan(robot.arm.travelTime_s(scene.in_front, far)));
  EXPECT_TRUE(std::isnan(robot.arm.travelTime_s(far, scene.in_front)));
  ASSERT_EQ(robot.arm.setMap(scene.wall), 0u);
  EXPECT_TRUE(std::isnan(robot.arm.travelTime_s(scene.in_front, scene.behind)));
  EXPECT_TRUE(robot.executor.trajectories.empty());  // nothing moved
}

/// Ranks the views it is given, in that order, in one round.
class FixedRanking : public host::planner::ViewPlanner {
 public:
  explicit FixedRanking(std::vector<Eigen::Isometry3d> views) : views_(std::move(views)) {}
  std::string_view name() const override { return "fixed"; }
  std::string configJson() const override { return "{}"; }
  std::optional<host::planner::Ranking> rank(host::map::MapEngine&, const Eigen::Isometry3d&,
                                             const host::planner::ReachabilityFn&,
                                             std::size_t round, host::planner::PlanStep&) override {
    if (round > 0) return std::nullopt;
    host::planner::Ranking ranking;
    for (const Eigen::Isometry3d& T : views_) {
      ranking.order.push_back(ranking.candidates.size());
      ranking.candidates.emplace_back().T_world_camera = T;
    }
    return ranking;
  }

 private:
  std::vector<Eigen::Isometry3d> views_;
};

TEST(PlannedArm, PlanAndMoveSkipsTheViewBehindTheWallBeforeAnyMoveIsTried) {
  FakeRobot robot(RecordingExecutor::Mode::kMove);
  const WallScene scene(robot);
  ASSERT_EQ(robot.arm.setMap(scene.wall), 0u);
  std::vector<Eigen::Isometry3d> planned;
  robot.arm.setPlanningObserver(
      [&](const MotionPlan& plan) { planned.push_back(robot.model.T_world_camera(plan.goal)); });
  FixedRanking planner({scene.behind, scene.in_front});  // the blocked view ranked first
  host::map::MapConfig config;
  config.observation_min_m = {-2.0, -2.0, 0.0};  // around the arm: the map is never read
  config.observation_max_m = {2.0, 2.0, 2.5};
  const auto map = host::map::createMapEngine(
      "octomap", config, host::ClusterRegion(scene.in_front.translation(), 0.04), nullptr);
  const host::planner::PlanStep step = host::planner::planAndMove(
      planner, *map, robot.arm.cameraPose(), {},
      [&](const Eigen::Isometry3d& T) { return robot.arm.moveTo(T).ok(); },
      [&](const std::vector<Eigen::Isometry3d>& poses) {
        std::vector<GoalReach> out;
        for (const Eigen::Isometry3d& T : poses) out.push_back(robot.arm.checkGoal(T));
        return out;
      });
  ASSERT_TRUE(step.moved());
  EXPECT_EQ(*step.chosen, 1u);
  EXPECT_EQ(step.move_attempts, 1u);  // the blocked view never reached the motion planner
  EXPECT_EQ(step.failed_moves, 0u);
  EXPECT_EQ(step.rejected_no_collision_free_ik, 1u);
  EXPECT_EQ(step.rejected_no_ik, 0u);
  ASSERT_EQ(planned.size(), 1u);
  EXPECT_LT((planned[0].translation() - scene.in_front.translation()).norm(), 1e-6);
}

TEST(PlannedArm, TheMapIsFreedWhereTheArmStands) {
  FakeRobot robot(RecordingExecutor::Mode::kMove);
  // Voxels at the camera itself (stereo noise on the lens): freed, so planning can start.
  const Eigen::Vector3d p_camera = robot.arm.cameraPose().translation();
  octomap::OcTree map(0.01);
  map.updateNode(p_camera.x(), p_camera.y(), p_camera.z(), true);
  EXPECT_GE(robot.arm.setMap(map), 1u);
  EXPECT_TRUE(robot.arm.checker().isValid(robot.arm.joints()));
  EXPECT_EQ(robot.arm.moveTo(robot.reachableGoal()).status, MoveStatus::kSuccess);
}

TEST(PlannedArm, AMoveThatWentBackTheWayInSaysSo) {
  PlannedMove move;
  move.status = host::nbv::MoveStatus::kSuccess;
  EXPECT_FALSE(move.result().retreated);
  move.plan.retreat_turn = 2;  // the way back's last waypoint, where the onward path began
  EXPECT_TRUE(move.result().retreated);
  move.status = host::nbv::MoveStatus::kRefused;  // a plan that did not move the arm
  EXPECT_FALSE(move.result().retreated);
}

TEST(PlannedArm, MisconfigurationThrows) {
  FakeRobot robot(RecordingExecutor::Mode::kMove);
  EXPECT_THROW(PlannedArm(robot.model, robot.reachability, robot.joints, robot.executor, 0.0),
               std::invalid_argument);
  robot.joints.q[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(robot.arm.cameraPose(), std::runtime_error);
  EXPECT_THROW(robot.arm.moveTo(robot.reachableGoal()), std::runtime_error);
}

TEST(PlannedArm, StatusNamesAndSampleTimes) {
  EXPECT_STREQ(toString(ExecutionStatus::kRefused), "refused");
  EXPECT_EQ(toMoveStatus(MotionStatus::kTimeout), MoveStatus::kTimeout);
  const ArmModel model{ArmConfig{}};
  JointVector end = model.homeConfiguration();
  end[2] += 1.0;
  const Trajectory trajectory({model.homeConfiguration(), end}, model.maxVelocity(),
                              model.maxAcceleration());
  const std::vector<double> t = sampleTimes_s(trajectory, 0.05);
  ASSERT_GE(t.size(), 3u);
  EXPECT_EQ(t.front(), 0.0);
  EXPECT_EQ(t.back(), trajectory.duration_s());
  for (std::size_t i = 1; i < t.size(); ++i) {
    EXPECT_GT(t[i], t[i - 1]);
    EXPECT_LE(t[i] - t[i - 1], 0.05 + 1e-12);
  }
  EXPECT_EQ(sampleTimes_s(Trajectory({end}, model.maxVelocity(), model.maxAcceleration()), 0.1),
            std::vector<double>{0.0});
  EXPECT_THROW(sampleTimes_s(trajectory, 0.0), std::invalid_argument);
}

// A simulated arm on the fixed clock, planning reproducibly.
struct FixedClockArm {
  explicit FixedClockArm(const ArmConfig& config)
      : model(config), reachability(model), arm(model, reachability, clock, home()) {
    arm.setReproducibleMotionPlanning(5);
  }
  JointVector home() const { return model.homeConfiguration(); }
  /// One move from home along the slider, turned at wrist 2: a free straight move.
  PlannedMove moveOnce() {
    JointVector target = home();
    target[0] = 0.2;
    target[4] = 0.5;
    clock.beginIteration();
    return arm.planned().moveToPose(model.T_world_camera(target));
  }
  const ArmModel model;
  const IkReachability reachability;
  sim::SimClock clock{sim::SimClock::Mode::kFixed, 0.2, 0.1};
  sim::SimulatedArm arm;
};

TEST(SimulatedArm, ChargesPlanningThenMotionAndMovesTheJoints) {
  FixedClockArm fixed{ArmConfig{}};
  const PlannedMove move = fixed.moveOnce();
  ASSERT_EQ(move.status, MoveStatus::kSuccess);
  EXPECT_TRUE(move.execution.done());
  EXPECT_EQ(fixed.clock.now_s(), 0.1 + move.plan.trajectory.duration_s());
  EXPECT_EQ(fixed.arm.joints(), move.plan.trajectory.waypoints().back());
}

TEST(SimulatedArm, TheFixedClockChargesAPlanItsValidityChecks) {
  // A reference computer of 10 checks a second (the budget over planning_time_s): every
  // check of the query counts, at that rate, above the stage's constant.
  ArmConfig config;
  config.planning_time_s = 100.0;
  config.reproducible_planning_checks = 1000;
  FixedClockArm fixed{config};
  const PlannedMove move = fixed.moveOnce();
  ASSERT_EQ(move.status, MoveStatus::kSuccess);
  ASSERT_GT(move.plan.validity_checks, 10u);
  EXPECT_DOUBLE_EQ(fixed.clock.iterations()[0].charged(sim::ClockStage::kMotionPlanning),
                   static_cast<double>(move.plan.validity_checks) / 10.0);
}

}  // namespace
}  // namespace fvp::robot
