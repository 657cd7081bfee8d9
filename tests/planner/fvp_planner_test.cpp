// Samplers, the planner config and Algorithm 1 (threshold decay and reset) with a scripted
// motion planner that fails on purpose.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "fvp/host/map/map_engine.h"
#include "fvp/host/planner/fvp_planner.h"
#include "fvp/host/planner/rvp_planner.h"
#include "fvp/host/planner/viewpoint_sampler.h"
#include "planner_test_maps.h"

namespace fvp::host::planner {
namespace {

namespace fs = std::filesystem;

const ClusterRegion& kRegion = testing::kPlannerTestRegion;
std::unique_ptr<map::MapEngine> mappedEngine() {
  return testing::mappedTestEngine();
}

// A reachable shell around a base, standing in for the workspace tree in tests.
bool inShell(const Eigen::Isometry3d& T) {
  const double r = (T.translation() - Eigen::Vector3d(0.0, -0.6, 0.3)).norm();
  return r > 0.2 && r < 0.55;
}

TEST(ViewpointSampler, TargetsDistancesOrientationsAndReachability) {
  auto e = mappedEngine();
  const auto frontiers = e->frontiers();
  PlannerConfig config;
  ViewpointSampler sampler(config, 42);
  const auto roi = sampler.sampleRoi(frontiers, 300, inShell);
  const auto exploration = sampler.sampleExploration(frontiers, 300, inShell);
  ASSERT_EQ(roi.size(), 300u);
  ASSERT_EQ(exploration.size(), 300u);
  std::size_t reachable = 0;
  for (const auto* set : {&roi, &exploration}) {
    for (const Candidate& c : *set) {
      // The target is a frontier voxel centre of the candidate's kind.
      const auto it = std::find_if(frontiers.begin(), frontiers.end(), [&](const auto& f) {
        return (f.center_m - c.target_m).norm() < 1e-12;
      });
      ASSERT_NE(it, frontiers.end());
      EXPECT_TRUE(c.kind == CandidateKind::kRoi ? it->roi_frontier : it->exploration_frontier);
      const double d = (c.position_m() - c.target_m).norm();
      EXPECT_GE(d, config.sensor_min_m - 1e-12);
      EXPECT_LE(d, config.sensor_max_m + 1e-12);
      // The camera's z axis runs through the target; the rotation is proper.
      EXPECT_LT(
          (c.T_world_camera.linear().col(2) - (c.target_m - c.position_m()).normalized()).norm(),
          1e-9);
      EXPECT_NEAR(c.T_world_camera.linear().determinant(), 1.0, 1e-9);
      EXPECT_EQ(c.reachable, inShell(c.T_world_camera));
      reachable += c.reachable;
      if (c.kind == CandidateKind::kExploration && it->normal.squaredNorm() > 0.0) {
        EXPECT_LT(((c.position_m() - c.target_m).normalized() - it->normal.normalized()).norm(),
                  1e-9);
      }
    }
  }
  EXPECT_GT(reachable, 0u);
  // Deterministic for a seed.
  ViewpointSampler again(config, 42);
  const auto roi2 = again.sampleRoi(frontiers, 300, inShell);
  for (std::size_t i = 0; i < roi.size(); ++i)
    EXPECT_TRUE(roi[i].T_world_camera.isApprox(roi2[i].T_world_camera, 0.0));
  // No frontiers of a kind: no candidates of it.
  EXPECT_TRUE(sampler.sampleRoi({}, 10, inShell).empty());
}

TEST(FvpPlanner, ThresholdDecaysWhenEveryMoveFailsAndResetsOnSuccess) {
  auto e = mappedEngine();
  PlannerConfig config;
  config.roi_samples = 40;
  config.exploration_samples = 40;
  config.utility_threshold = -5.0;  // every reachable candidate is above it
  config.threshold_decay = 0.5;
  config.max_sampling_rounds = 3;
  FvpPlanner planner(config, 1);
  const Eigen::Isometry3d now = Eigen::Isometry3d(Eigen::Translation3d(0.0, -0.3, 0.35));

  std::size_t calls = 0;
  const PlanStep failed = planner.planAndMove(*e, now, inShell, [&](const Eigen::Isometry3d&) {
    ++calls;
    return false;
  });
  EXPECT_FALSE(failed.moved());
  EXPECT_EQ(failed.sampling_rounds, 3u);
  EXPECT_EQ(failed.move_attempts, calls);
  EXPECT_EQ(failed.failed_moves, calls);
  EXPECT_GT(calls, 0u);
  EXPECT_DOUBLE_EQ(planner.utilityThreshold(), -5.0 * 0.5 * 0.5 * 0.5);

  // The second attempt succeeds: the threshold resets to u_t0 and the chosen candidate is
  // the second best by utility.
  int attempt = 0;
  const PlanStep moved = planner.planAndMove(
      *e, now, inShell, [&](const Eigen::Isometry3d&) { return ++attempt == 2; });
  ASSERT_TRUE(moved.moved());
  EXPECT_EQ(moved.move_attempts, 2u);
  EXPECT_EQ(moved.failed_moves, 1u);
  EXPECT_DOUBLE_EQ(planner.utilityThreshold(), -5.0);
  std::vector<double> utilities;
  for (const auto& c : moved.candidates)
    if (c.reachable) utilities.push_back(c.utility);
  std::sort(utilities.rbegin(), utilities.rend());
  ASSERT_GE(utilities.size(), 2u);
  EXPECT_EQ(moved.candidates[*moved.chosen].utility, utilities[1]);
  // Eq. 3 on the chosen candidate.
  const Candidate& c = moved.candidates[*moved.chosen];
  EXPECT_NEAR(c.utility, c.ig - config.alpha_per_m * (c.position_m() - now.translation()).norm(),
              1e-12);
}

TEST(FvpPlanner, OnlyCandidatesAboveTheThresholdAreTried) {
  auto e = mappedEngine();
  PlannerConfig config;
  config.utility_threshold = 5.0;  // above any IG (<= 1): nothing is tried
  config.threshold_decay = 0.5;
  config.max_sampling_rounds = 2;
  FvpPlanner planner(config, 2);
  std::size_t calls = 0;
  const PlanStep step =
      planner.planAndMove(*e, Eigen::Isometry3d(Eigen::Translation3d(0.0, -0.3, 0.35)), inShell,
                          [&](const Eigen::Isometry3d&) { return ++calls, true; });
  EXPECT_EQ(calls, 0u);
  EXPECT_FALSE(step.moved());
  EXPECT_DOUBLE_EQ(planner.utilityThreshold(), 1.25);
}

TEST(PlannerConfig, DefaultsFileMatchesBuiltInDefaults) {
  const PlannerConfig file =
      PlannerConfig::fromYamlFile(fs::path(FVP_SOURCE_DIR) / "host/config/planner_default.yaml");
  EXPECT_EQ(file.toJson(), PlannerConfig{}.toJson());
}

TEST(RvpConfig, DefaultsFileMatchesBuiltInDefaults) {
  const RvpConfig file =
      RvpConfig::fromYamlFile(fs::path(FVP_SOURCE_DIR) / "host/config/rvp_default.yaml");
  EXPECT_EQ(file.toJson(), RvpConfig{}.toJson());
}

TEST(PlannerConfig, BadKeysAndValuesNameTheFileAndTheKey) {
  const fs::path dir = fs::temp_directory_path() / "fvp_planner_config_test";
  fs::create_directories(dir);
  const auto write = [&](const std::string& text) {
    std::ofstream(dir / "c.yaml") << text;
    return dir / "c.yaml";
  };
  const auto message = [&](const std::string& text) {
    try {
      PlannerConfig::fromYamlFile(write(text));
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("roi_samplez: 3\n").find("unknown key 'roi_samplez'"), std::string::npos);
  EXPECT_NE(message("threshold_decay: 1.5\n").find("'threshold_decay'"), std::string::npos);
  EXPECT_NE(message("sensor_min_m: abc\n").find("'sensor_min_m'"), std::string::npos);
  EXPECT_NE(message("sensor_min_m: 0.5\nsensor_max_m: 0.3\n").find("sensor_max_m"),
            std::string::npos);
  EXPECT_NE(message("roi_samples: 3\n").find("no error"), std::string::npos);
  EXPECT_NE(message("- a\n").find("c.yaml"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace fvp::host::planner
