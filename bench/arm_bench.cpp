// The arm: forward and inverse kinematics, the workspace tree (10 M-sample build, load from
// its cache) and moveToPose on simulated worlds. Each family checks its results before it
// reports: FK against IK round trips, IK against FK, the tree against direct IK, every
// motion plan's end pose.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <random>
#include <sstream>

#include "fvp/robot/sim/arm_controller.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/sim/world_occupancy.h"
#include "fvp/robot/ur5_kinematics.h"
#include "fvp/robot/workspace_tree.h"

namespace fvp::bench {
namespace {

using robot::ArmConfig;
using robot::ArmModel;
using robot::JointVector;
using robot::Ur5Kinematics;

constexpr int kBatch = 4096;

std::vector<JointVector> randomConfigurations(const ArmModel& arm, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<JointVector> out(static_cast<std::size_t>(n));
  for (JointVector& q : out) {
    for (int j = 0; j < robot::kArmJoints; ++j)
      q[j] = arm.lowerLimits()[j] + unit(rng) * (arm.upperLimits()[j] - arm.lowerLimits()[j]);
  }
  return out;
}

bool poseNear(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm() < 1e-6 &&
         Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() < 1e-6;
}

void BM_ForwardKinematics(benchmark::State& state) {
  const ArmModel arm{ArmConfig{}};
  const auto qs = randomConfigurations(arm, kBatch, 1);
  std::vector<Eigen::Isometry3d> poses(qs.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < qs.size(); ++i) poses[i] = arm.T_world_camera(qs[i]);
    benchmark::DoNotOptimize(poses.data());
  }
  // Check: IK of every pose at the sample's slider position finds the sample again.
  for (std::size_t i = 0; i < qs.size(); ++i) {
    std::vector<JointVector> solutions;
    arm.inverseAt(poses[i], qs[i][0], qs[i], solutions);
    const bool found = std::any_of(solutions.begin(), solutions.end(), [&](const JointVector& s) {
      return (s - qs[i]).cwiseAbs().maxCoeff() < 1e-6;
    });
    if (!found && std::abs(std::sin(qs[i][5])) > 1e-3) {
      state.SkipWithError("forward kinematics: IK does not recover a configuration");
      return;
    }
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

void BM_InverseKinematics(benchmark::State& state) {
  const bool along_travel = state.range(0) != 0;
  const ArmModel arm{ArmConfig{}};
  const auto qs = randomConfigurations(arm, along_travel ? 256 : kBatch, 2);
  std::vector<Eigen::Isometry3d> poses;
  for (const JointVector& q : qs) poses.push_back(arm.T_world_camera(q));
  std::size_t solutions = 0;
  std::vector<JointVector> out;
  std::array<Ur5Kinematics::Joints, Ur5Kinematics::kMaxSolutions> ur5;
  for (auto _ : state) {
    solutions = 0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (along_travel) {
        out = arm.inverse(poses[i], qs[i]);
        solutions += out.size();
      } else {
        const Eigen::Isometry3d T_base_flange =
            arm.T_world_base(qs[i][0]).inverse() * poses[i] * arm.T_flange_camera().inverse();
        solutions += static_cast<std::size_t>(Ur5Kinematics::inverse(T_base_flange, ur5));
      }
    }
    benchmark::DoNotOptimize(solutions);
  }
  // Check: every solution's forward kinematics gives the pose back.
  for (std::size_t i = 0; i < poses.size(); ++i) {
    for (const JointVector& s : arm.inverse(poses[i], qs[i])) {
      if (!poseNear(arm.T_world_camera(s), poses[i])) {
        state.SkipWithError("inverse kinematics: a solution misses its pose");
        return;
      }
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(poses.size()));
  state.counters["solutions_per_pose"] =
      static_cast<double>(solutions) / static_cast<double>(poses.size());
}

// Agreement of the tree with direct IK on random poses around the tree (the planner's box).
double agreementWithIk(const ArmModel& arm, const robot::WorkspaceTree& tree, int poses) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> x(-0.6, 0.6), y(-0.6, 0.2), z(0.7, 1.4), u(-1.0, 1.0);
  int agree = 0;
  for (int i = 0; i < poses; ++i) {
    const Eigen::Vector3d eye(x(rng), y(rng), z(rng)), dir(u(rng), u(rng), u(rng));
    const Eigen::Isometry3d T = robot::sim::lookAt(eye, eye + dir);
    agree += arm.reachableByIk(T) == tree.reachable(T) ? 1 : 0;
  }
  return static_cast<double>(agree) / poses;
}

void BM_WorkspaceBuild(benchmark::State& state) {
  ArmConfig config;
  config.workspace_samples = state.range(0);
  const ArmModel arm(config);
  std::uint64_t bins = 0;
  std::unique_ptr<robot::WorkspaceTree> tree;
  for (auto _ : state) {
    tree = std::make_unique<robot::WorkspaceTree>(robot::WorkspaceTree::build(arm));
    bins = tree->nonEmptyBins();
  }
  const double agreement = agreementWithIk(arm, *tree, 1000);
  if (agreement < 0.9) state.SkipWithError("workspace tree: under 90 % agreement with IK");
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.counters["non_empty_bins"] = static_cast<double>(bins);
  state.counters["agreement_with_ik"] = agreement;
  state.counters["resolution_m"] = tree->resolution_m();
  state.counters["direction_bins"] = tree->directionBins();
}

void BM_WorkspaceLoad(benchmark::State& state) {
  ArmConfig config;
  config.workspace_samples = state.range(0);
  const auto dir = std::filesystem::temp_directory_path() / "fvp_bench_workspace";
  config.workspace_cache_dir = dir.string();
  const ArmModel arm(config);
  std::ostringstream log;
  const robot::WorkspaceTree built = robot::WorkspaceTree::loadOrBuild(arm, log);
  const auto path = robot::WorkspaceTree::cachePath(arm);
  for (auto _ : state) {
    auto loaded = robot::WorkspaceTree::load(path, robot::WorkspaceTree::cacheKey(arm), nullptr);
    if (!loaded || loaded->nonEmptyBins() != built.nonEmptyBins()) {
      state.SkipWithError("workspace tree: the cache does not load back the same tree");
      return;
    }
  }
  state.counters["file_MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
}

// One feasible query: a world's map and start configuration, and a camera pose with a
// collision-free IK solution.
struct Query {
  int world = 0;
  JointVector start;
  Eigen::Isometry3d T_world_camera;
};

// The worlds of BM_MotionPlan: one cluster (range 0 = 0, the default world) or a four-cluster
// tree (1: world_tree.yaml's geometry), each mapped at the coarse map's 1 cm from the truth.
robot::sim::WorldConfig planningWorldConfig(std::int64_t tree) {
  robot::sim::WorldConfig config;
  if (tree != 0) {
    config.cluster_count = 4;
    config.min_cluster_spacing_m = 0.2;
    config.cluster_height_spread_m = 0.3;
  }
  return config;
}

// moveToPose over feasible queries on four worlds. range(0): one cluster (0) or a tree (1);
// range(1): the collision checker's distance field on (1) or FCL alone (0): each check gets the
// same answer, but the planner here is time-limited and unseeded, so the plans differ.
void BM_MotionPlan(benchmark::State& state) {
  const ArmModel arm{ArmConfig{}};
  constexpr int kWorlds = 4, kQueriesPerWorld = 25;
  std::vector<std::unique_ptr<robot::ArmCollisionChecker>> checkers;
  std::vector<Query> queries;
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int w = 0; w < kWorlds; ++w) {
    const auto world = robot::sim::World::generate(planningWorldConfig(state.range(0)), 500 + w);
    Eigen::AlignedBox3d box;
    for (const auto& cluster : world.clusters())
      box.extend(
          Eigen::AlignedBox3d(cluster.center_m.array() - 0.6, cluster.center_m.array() + 0.6));
    const auto tree = robot::sim::worldOccupancy(world, 0.01, box);
    checkers.push_back(std::make_unique<robot::ArmCollisionChecker>(arm));
    checkers.back()->setMap(*tree);
    checkers.back()->setUseDistanceField(state.range(1) != 0);
    const auto start = robot::sim::ArmController::startConfiguration(arm, world.startCameraPose());
    if (!start) {
      state.SkipWithError("motion plan: a start view is unreachable");
      return;
    }
    for (int found = 0; found < kQueriesPerWorld;) {
      const Eigen::Vector3d c =
          world.clusters()[static_cast<std::size_t>(found) % world.clusters().size()].center_m;
      const Eigen::Vector3d target = c + 0.04 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      const Eigen::Vector3d dir =
          Eigen::Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5).normalized();
      const Eigen::Isometry3d T =
          robot::sim::lookAt(target - (0.2 + 0.2 * unit(rng)) * dir, target);
      bool feasible = false;
      for (const JointVector& q : arm.inverse(T, *start))
        feasible = feasible || checkers.back()->isValid(q);
      if (!feasible) continue;
      queries.push_back({w, *start, T});
      ++found;
    }
  }
  std::vector<double> times_s;
  int succeeded = 0;
  std::uint64_t checks = 0;
  std::size_t next = 0;
  for (auto _ : state) {
    const Query& q = queries[next++ % queries.size()];
    const robot::MotionPlanner planner(*checkers[static_cast<std::size_t>(q.world)]);
    const robot::MotionPlan plan = planner.moveToPose(q.start, q.T_world_camera);
    times_s.push_back(plan.planning_wall_s);
    checks += plan.validity_checks;
    if (plan.ok()) {
      if (!poseNear(arm.T_world_camera(plan.trajectory.waypoints().back()), q.T_world_camera)) {
        state.SkipWithError("motion plan: the trajectory ends elsewhere");
        return;
      }
      ++succeeded;
    }
  }
  std::sort(times_s.begin(), times_s.end());
  const double success = static_cast<double>(succeeded) / static_cast<double>(times_s.size());
  if (success < 0.9) state.SkipWithError("motion plan: under 90 % of feasible queries succeeded");
  state.counters["success_rate"] = success;
  state.counters["median_s"] = times_s[times_s.size() / 2];
  state.counters["p95_s"] =
      times_s[static_cast<std::size_t>(0.95 * static_cast<double>(times_s.size() - 1))];
  // The rate the reproducible planner's check budgets are set from (arm_config.h).
  double wall_s = 0.0;
  for (const double t : times_s) wall_s += t;
  state.counters["validity_checks_per_s"] = static_cast<double>(checks) / wall_s;
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK(BM_ForwardKinematics)->Name("BM_ForwardKinematics/arm/cpu");
BENCHMARK(BM_InverseKinematics)->Name("BM_InverseKinematics/ur5/cpu")->Arg(0);
BENCHMARK(BM_InverseKinematics)->Name("BM_InverseKinematics/arm_along_travel/cpu")->Arg(1);
BENCHMARK(BM_WorkspaceBuild)
    ->Name("BM_WorkspaceBuild/grid/cpu")
    ->Arg(10'000'000)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();
BENCHMARK(BM_WorkspaceLoad)
    ->Name("BM_WorkspaceLoad/grid/cpu")
    ->Arg(10'000'000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_MotionPlan)
    ->Name("BM_MotionPlan/rrtconnect/cpu")
    ->ArgNames({"tree", "field"})
    ->Args({0, 1})
    ->Args({0, 0})
    ->Args({1, 1})
    ->Args({1, 0})
    ->Iterations(100)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace fvp::bench
