// moveToPose: statuses, and a small version of the statistical planning test (the full
// 100-query one is in arm_heavy_test.cpp).
#include <gtest/gtest.h>

#include <random>

#include "fvp/robot/motion_planner.h"
#include "fvp/robot/sim/arm_controller.h"
#include "planning_queries.h"

namespace fvp::robot {
namespace {
using sim::ArmController;
using sim::ClockStage;
using sim::SimClock;

TEST(MotionPlanner, SucceedsOnRandomFeasibleQueriesInClutteredWorlds) {
  // A success-rate test, not a speed test (BM_MotionPlan measures speed): a generous limit
  // keeps it deterministic on a loaded machine or under sanitizers, where the default 1 s
  // runs several times slower.
  const testing::QueryStats stats = testing::runPlanningQueries(3, 5, 100, 10.0);
  stats.print(std::cout);
  EXPECT_EQ(stats.feasible, 15);
  EXPECT_GE(stats.succeeded, 14);
  EXPECT_EQ(stats.path_invalid, 0);
  // Both ways of reaching a goal were taken, and neither touched the map (path_invalid).
  EXPECT_GT(stats.straight, 0);
  EXPECT_LT(stats.straight, stats.succeeded);
}

TEST(MotionPlanner, BlendedTimingIsFasterAndStaysCollisionFree) {
  // The same queries timed through the via points: every blended trajectory is checked
  // against the unpadded arm every 5 ms, and none takes longer than rest to rest.
  const testing::QueryStats stats = testing::runPlanningQueries(3, 5, 100, 10.0, "blended");
  stats.print(std::cout);
  EXPECT_EQ(stats.feasible, 15);
  EXPECT_GE(stats.succeeded, 14);
  EXPECT_EQ(stats.path_invalid, 0);
  EXPECT_GT(stats.blended, 0);
  for (std::size_t i = 0; i < stats.motion_s.size(); ++i)
    EXPECT_LE(stats.motion_s[i], stats.rest_to_rest_s[i] * (1.0 + 1e-9));
  EXPECT_LT(testing::QueryStats::mean(stats.motion_s),
            testing::QueryStats::mean(stats.rest_to_rest_s));
}

TEST(MotionPlanner, ReportsStatusesWithoutThrowing) {
  const ArmModel arm{ArmConfig{}};
  ArmCollisionChecker checker(arm);
  const MotionPlanner planner(checker);
  const JointVector home = arm.homeConfiguration();
  // Out of reach.
  Eigen::Isometry3d far = arm.T_world_camera(home);
  far.translation().y() += 3.0;
  EXPECT_EQ(planner.moveToPose(home, far).status, MotionStatus::kNoIk);
  // Reachable but blocked: a wall of voxels through the camera's position.
  const Eigen::Isometry3d goal = arm.T_world_camera(home);
  octomap::OcTree tree(0.02);
  for (double x = -0.2; x <= 0.2; x += 0.01)
    for (double z = -0.2; z <= 0.2; z += 0.01)
      tree.updateNode(goal.translation().x() + x, goal.translation().y(),
                      goal.translation().z() + z, true);
  checker.setMap(tree);
  JointVector elsewhere = home;
  elsewhere[0] = 0.4;
  // Every check of a query is its work (what the fixed clock charges): the goals' too.
  std::uint64_t before = checker.checks();
  const MotionPlan blocked = planner.moveToPose(elsewhere, goal);
  EXPECT_EQ(blocked.status, MotionStatus::kNoCollisionFreeIk);
  EXPECT_GT(blocked.validity_checks, 0u);
  EXPECT_EQ(blocked.validity_checks, checker.checks() - before);
  EXPECT_EQ(planner.moveToPose(home, arm.T_world_camera(elsewhere)).status,
            MotionStatus::kStartInvalid);
  // Free space: success, and the trajectory ends at the goal.
  checker.clearMap();
  before = checker.checks();
  const MotionPlan plan = planner.moveToPose(elsewhere, goal);
  ASSERT_EQ(plan.status, MotionStatus::kSuccess);
  EXPECT_EQ(plan.validity_checks, checker.checks() - before);
  // Nothing in the way: the straight motion, as fast as the joints allow.
  EXPECT_TRUE(plan.straight);
  EXPECT_EQ(plan.trajectory.waypoints().size(), 2u);
  EXPECT_DOUBLE_EQ(plan.trajectory.duration_s(), arm.travelTime_s(elsewhere, plan.goal));
  EXPECT_LT(
      (arm.T_world_camera(plan.trajectory.waypoints().back()).translation() - goal.translation())
          .norm(),
      1e-6);
  EXPECT_GT(plan.trajectory.duration_s(), 0.0);
  EXPECT_STREQ(toString(MotionStatus::kTimeout), "timeout");
}

// Going back the way in (ArmConfig retreat_share): where the straight motion from the arm's
// configuration to every goal is blocked and a small budget leaves OMPL without a path, but the
// goal is straight from where the arm came from, the arm goes back and on, collision-free;
// with the way back closed, or retreat_share 0, it does not, and retreat_share 0 plans as
// before.
TEST(MotionPlanner, GoesBackTheWayInWhenPlansFail) {
  ArmConfig config;
  config.reproducible_planning_checks = 400;
  config.reproducible_simplify_checks = 0;
  ArmConfig off_config = config;
  config.retreat_share = 0.3;
  const ArmModel arm{config}, arm_off{off_config};
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> offset(-0.5, 0.5);
  int cases = 0;
  for (int attempt = 0; attempt < 300 && cases < 3; ++attempt) {
    const JointVector came_from = arm.homeConfiguration();
    JointVector current = came_from, goal_q = came_from;
    for (int j = 1; j < kArmJoints; ++j) current[j] += offset(rng), goal_q[j] += offset(rng);
    const Eigen::Isometry3d goal = arm.T_world_camera(goal_q);
    // Voxels where the camera is halfway along the straight motion to each goal.
    octomap::OcTree tree(0.02);
    for (const JointVector& g : arm.inverse(goal, current)) {
      const Eigen::Vector3d p = arm.T_world_camera(0.5 * (current + g)).translation();
      tree.updateNode(p.x(), p.y(), p.z(), true);
    }
    ArmCollisionChecker checker(arm), checker_off(arm_off);
    checker.setMap(tree);
    checker_off.setMap(tree);
    const std::vector<JointVector> way_in{came_from, current};
    const Trajectory way_back({current, came_from}, arm.maxVelocity(), arm.maxAcceleration());
    if (!checker.isValid(current) || !testing::pathValid(checker, way_back, 0.004)) continue;
    MotionPlanner off(checker_off), on(checker);
    off.setReproducible(7);
    on.setReproducible(7);
    const MotionPlan without = off.moveToPose(current, goal, way_in);
    if (without.ok() || without.status == MotionStatus::kNoCollisionFreeIk) continue;
    // retreat_share 0: the way in changes nothing.
    MotionPlanner off_again(checker_off);
    off_again.setReproducible(7);
    const MotionPlan plain = off_again.moveToPose(current, goal);
    EXPECT_EQ(plain.status, without.status);
    EXPECT_EQ(plain.validity_checks, without.validity_checks);
    const MotionPlan with = on.moveToPose(current, goal, way_in);
    if (!with.ok()) continue;  // the goal not straight from where the arm came from either
    ++cases;
    EXPECT_TRUE(with.retreated());
    const std::vector<JointVector>& w = with.trajectory.waypoints();
    EXPECT_EQ(w.front(), current);
    ASSERT_EQ(with.retreat_turn, 1u);  // the next move's way in starts where it turned
    EXPECT_LT(jointDistance(w[1], came_from), 1e-12);
    EXPECT_LT((arm.T_world_camera(w.back()).translation() - goal.translation()).norm(), 1e-6);
    EXPECT_TRUE(testing::pathValid(checker, with.trajectory, 0.004) || with.trajectory.isBlended());
    EXPECT_TRUE(testing::timedPathValid(checker, with.trajectory));
    // The way back closed (a voxel where the camera is halfway back): no retreat.
    octomap::OcTree closed = tree;
    const Eigen::Vector3d back = arm.T_world_camera(0.5 * (current + came_from)).translation();
    closed.updateNode(back.x(), back.y(), back.z(), true);
    checker.setMap(closed);
    if (!checker.isValid(current)) continue;
    MotionPlanner blocked(checker), blocked_off(checker_off);
    blocked.setReproducible(7);
    blocked_off.setReproducible(7);
    checker_off.setMap(closed);
    // No retreat, and the whole-space query keeps its whole share: the plan without one.
    const MotionPlan closed_plan = blocked.moveToPose(current, goal, way_in);
    EXPECT_FALSE(closed_plan.retreated());
    EXPECT_EQ(closed_plan.status, blocked_off.moveToPose(current, goal, way_in).status);
  }
  EXPECT_EQ(cases, 3);
}

TEST(MotionPlanner, GoalStatusIsMoveToPosesFirstStepWithoutPlanning) {
  // Views of a generated world's cluster from the sensor range, on the world's full coarse
  // map: a pose the goal check turns down fails moveToPose with the same status, and one it
  // passes goes on to motion planning.
  const ArmModel arm{ArmConfig{}};
  const auto world = sim::World::generate(sim::WorldConfig{}, 3);
  const Eigen::Vector3d c = world.clusterCenter_m();
  const auto map =
      sim::worldOccupancy(world, 0.01, Eigen::AlignedBox3d(c.array() - 0.6, c.array() + 0.6));
  ArmCollisionChecker checker(arm);
  checker.setMap(*map);
  MotionPlanner planner(checker);
  planner.setReproducible(11);
  const auto start = ArmController::startConfiguration(arm, world.startCameraPose());
  ASSERT_TRUE(start.has_value());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int by_status[3] = {};
  int planned = 0;
  for (int i = 0; i < 80; ++i) {
    const Eigen::Vector3d dir =
        Eigen::Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5).normalized();
    const Eigen::Isometry3d T = sim::lookAt(c - (0.2 + 0.3 * unit(rng)) * dir, c);
    const MotionStatus check = planner.goalStatus(*start, T);
    ASSERT_TRUE(check == MotionStatus::kSuccess || check == MotionStatus::kNoIk ||
                check == MotionStatus::kNoCollisionFreeIk);
    ++by_status[check == MotionStatus::kSuccess ? 0 : check == MotionStatus::kNoIk ? 1 : 2];
    if (check != MotionStatus::kSuccess) {
      EXPECT_EQ(planner.moveToPose(*start, T).status, check);
    } else if (planned < 3) {  // OMPL is the slow part: a few suffice
      ++planned;
      const MotionStatus moved = planner.moveToPose(*start, T).status;
      EXPECT_NE(moved, MotionStatus::kNoIk);
      EXPECT_NE(moved, MotionStatus::kNoCollisionFreeIk);
    }
  }
  // Every kind of answer was seen, or the test would prove little.
  EXPECT_GT(by_status[0], 0);
  EXPECT_GT(by_status[1], 0);
  EXPECT_GT(by_status[2], 0);
}

TEST(ArmController, ChargesPlanningAndMotionToTheClock) {
  const ArmModel arm{ArmConfig{}};
  SimClock clock(SimClock::Mode::kFixed, 0.2, 0.1);
  ArmController controller(arm, clock, arm.homeConfiguration());
  JointVector target = arm.homeConfiguration();
  target[0] = -0.3;
  target[1] = 0.4;
  clock.beginIteration();
  const MotionPlan plan = controller.moveToPose(arm.T_world_camera(target));
  ASSERT_TRUE(plan.ok());
  EXPECT_NEAR(clock.now_s(), 0.1 + plan.trajectory.duration_s(), 1e-12);
  EXPECT_DOUBLE_EQ(clock.iterations()[0].charged(ClockStage::kMotion),
                   plan.trajectory.duration_s());
  EXPECT_LT(
      (controller.cameraPose().translation() - arm.T_world_camera(target).translation()).norm(),
      1e-6);
  // A failed plan charges only its planning time and leaves the arm where it was.
  const JointVector before = controller.joints();
  Eigen::Isometry3d far = controller.cameraPose();
  far.translation().z() += 5.0;
  EXPECT_EQ(controller.moveToPose(far).status, MotionStatus::kNoIk);
  EXPECT_EQ(controller.joints(), before);
  EXPECT_NEAR(clock.now_s(), 0.2 + plan.trajectory.duration_s(), 1e-12);
}

}  // namespace
}  // namespace fvp::robot
