// Random feasible planning queries in simulated worlds (the OMPL-style statistical test and
// its heavy version): the coarse map straight from the world's geometry (1 cm, a 1.2 m box
// around the cluster, as the trial's coarse map), camera poses looking at the cluster from
// the sensor range in random directions, the arm chained from the start view's configuration
// through every successful query.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "fvp/robot/sim/arm_controller.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/sim/world_occupancy.h"

namespace fvp::robot::testing {
using sim::ArmController;
using sim::SimClock;

struct QueryStats {
  int feasible = 0, succeeded = 0, infeasible = 0, path_invalid = 0, blended = 0;
  int straight = 0;  ///< successes by the straight joint-space motion (no sampling planner)
  int by_status[6] = {};
  std::vector<double> planning_s, path_length, motion_s, waypoints;
  std::vector<double> rest_to_rest_s;  ///< the same paths timed rest to rest

  static double mean(const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / static_cast<double>(v.size());
  }
  static double quantile(std::vector<double> v, double q) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
  }
  void print(std::ostream& out) const {
    out << "motion planning: " << succeeded << "/" << feasible << " feasible queries succeeded ("
        << 100.0 * succeeded / std::max(1, feasible) << " %); " << infeasible
        << " sampled poses had no collision-free IK; planning time mean " << mean(planning_s)
        << " s, median " << quantile(planning_s, 0.5) << " s, p95 " << quantile(planning_s, 0.95)
        << " s; joint-space path length mean " << mean(path_length) << ", waypoints mean "
        << mean(waypoints) << ", " << straight << " straight; motion time mean " << mean(motion_s)
        << " s (" << blended << " blended; rest to rest " << mean(rest_to_rest_s) << " s)\n";
  }
};

/// Whether the trajectory is valid at every step of `step` rad along its waypoints. The
/// planner checks padded capsules at a coarser step; this checks the arm's real geometry
/// (a checker without padding) densely, which is what the padding is there to guarantee.
inline bool pathValid(const ArmCollisionChecker& checker, const Trajectory& traj, double step) {
  const auto& w = traj.waypoints();
  for (std::size_t i = 0; i + 1 < w.size(); ++i) {
    const int n = std::max(1, static_cast<int>(std::ceil(jointDistance(w[i], w[i + 1]) / step)));
    for (int k = 0; k <= n; ++k) {
      if (!checker.isValid(w[i] + (static_cast<double>(k) / n) * (w[i + 1] - w[i]))) return false;
    }
  }
  return true;
}

/// Whether a trajectory is valid at every 5 ms of its timing (a blended one leaves the
/// straight segments near its via points).
inline bool timedPathValid(const ArmCollisionChecker& checker, const Trajectory& traj) {
  for (double t = 0.0; t < traj.duration_s() + 0.005; t += 0.005)
    if (!checker.isValid(traj.position(std::min(t, traj.duration_s())))) return false;
  return true;
}

/// planning_time_s: OMPL's limit per query (default: the config's); timing: the arm config's
/// trajectory_timing.
inline QueryStats runPlanningQueries(int worlds, int queries_per_world, std::uint64_t seed,
                                     double planning_time_s = ArmConfig{}.planning_time_s,
                                     const std::string& timing = ArmConfig{}.trajectory_timing) {
  QueryStats stats;
  ArmConfig config;
  config.planning_time_s = planning_time_s;
  config.trajectory_timing = timing;
  const ArmModel arm{config};
  ArmConfig unpadded_config = config;
  unpadded_config.collision_padding_m = 0.0;
  const ArmModel unpadded(unpadded_config);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int w = 0; w < worlds; ++w) {
    const auto world =
        sim::World::generate(sim::WorldConfig{}, seed + static_cast<std::uint64_t>(w));
    const Eigen::Vector3d c = world.clusterCenter_m();
    const Eigen::AlignedBox3d box(c.array() - 0.6, c.array() + 0.6);
    const auto tree = sim::worldOccupancy(world, 0.01, box);
    SimClock clock(SimClock::Mode::kFixed, 0.2, 0.1);
    const auto start = ArmController::startConfiguration(arm, world.startCameraPose());
    EXPECT_TRUE(start.has_value());
    if (!start) continue;
    ArmController controller(arm, clock, *start);
    controller.setMap(*tree);
    ArmCollisionChecker exact(unpadded);
    exact.setMap(*tree);
    int done = 0;
    for (int attempt = 0; done < queries_per_world && attempt < 50 * queries_per_world; ++attempt) {
      const Eigen::Vector3d target = c + 0.04 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      const Eigen::Vector3d dir =
          Eigen::Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5).normalized();
      const double distance = 0.2 + 0.2 * unit(rng);
      const Eigen::Isometry3d T = sim::lookAt(target - distance * dir, target);
      const MotionPlan plan = controller.moveToPose(T);
      if (plan.status == MotionStatus::kNoIk || plan.status == MotionStatus::kNoCollisionFreeIk) {
        ++stats.infeasible;
        continue;
      }
      ++done;
      ++stats.feasible;
      ++stats.by_status[static_cast<int>(plan.status)];
      stats.planning_s.push_back(plan.planning_wall_s);
      if (plan.ok()) {
        ++stats.succeeded;
        stats.path_length.push_back(plan.trajectory.pathLength());
        stats.motion_s.push_back(plan.trajectory.duration_s());
        stats.waypoints.push_back(double(plan.trajectory.waypoints().size()));
        stats.rest_to_rest_s.push_back(
            Trajectory(plan.trajectory.waypoints(), arm.maxVelocity(), arm.maxAcceleration())
                .duration_s());
        stats.blended += plan.trajectory.isBlended();
        stats.straight += plan.straight;
        if (plan.straight) {
          EXPECT_EQ(plan.trajectory.waypoints().size(), 2u);
        }
        const Eigen::Isometry3d reached = controller.cameraPose();
        EXPECT_LT((reached.translation() - T.translation()).norm(), 1e-6);
        EXPECT_LT((reached.linear() - T.linear()).norm(), 1e-6);
        if (!pathValid(exact, plan.trajectory, 0.004) && !plan.trajectory.isBlended())
          ++stats.path_invalid;
        if (!timedPathValid(exact, plan.trajectory)) ++stats.path_invalid;
      } else {
        std::cout << "world " << world.seed() << ": " << toString(plan.status) << " after "
                  << plan.planning_wall_s << " s\n";
      }
    }
  }
  return stats;
}

}  // namespace fvp::robot::testing
