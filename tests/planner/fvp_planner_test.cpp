// Samplers, the planner config and Algorithm 1 (threshold decay and reset) with a scripted
// motion planner that fails on purpose.
#include <gtest/gtest.h>

#include <cmath>
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

TEST(ViewpointSampler, SizingCandidatesLookAtTheirTargetFromDirectionsThatAddSpan) {
  PlannerConfig config;
  ViewpointSampler sampler(config, 7);
  SizingTarget unseen, once;
  unseen.center_m = {0.0, 0.0, 0.3};
  once.center_m = {0.02, 0.0, 0.3};
  once.seen_from = {Eigen::Vector3d::UnitZ()};
  const std::vector<SizingTarget> targets = {unseen, once};
  const auto candidates = sampler.sampleSizing(targets, 400, inShell);
  ASSERT_EQ(candidates.size(), 400u);
  int per_target[2] = {0, 0}, near_seen = 0;
  for (const Candidate& c : candidates) {
    ASSERT_EQ(c.kind, CandidateKind::kSizing);
    ASSERT_TRUE(c.sizing_target == 0 || c.sizing_target == 1);
    const SizingTarget& t = targets[std::size_t(c.sizing_target)];
    ++per_target[c.sizing_target];
    EXPECT_TRUE(c.target_m.isApprox(t.center_m, 0.0));
    const Eigen::Vector3d to_camera = c.position_m() - t.center_m;
    EXPECT_GE(to_camera.norm(), config.sensor_min_m - 1e-12);
    EXPECT_LE(to_camera.norm(), config.sensor_max_m + 1e-12);
    // Looking at the target: the optical axis (z) points from the camera to it.
    EXPECT_NEAR(c.T_world_camera.linear().col(2).dot(-to_camera.normalized()), 1.0, 1e-9);
    EXPECT_TRUE(addsViewSpan(t, to_camera.normalized()));
    if (c.sizing_target == 1 && to_camera.normalized().z() > std::cos(30.0 * M_PI / 180.0))
      ++near_seen;
  }
  EXPECT_GT(per_target[0], 150);
  EXPECT_GT(per_target[1], 150);
  EXPECT_EQ(near_seen, 0) << "within 30 degrees of its one well-seen view";
  EXPECT_TRUE(sampler.sampleSizing({}, 10, inShell).empty());
}

TEST(SizingTarget, AddsViewSpanFromOneOfItsViews) {
  SizingTarget t;
  EXPECT_TRUE(addsViewSpan(t, Eigen::Vector3d::UnitX())) << "no view yet: any direction";
  t.seen_from = {Eigen::Vector3d::UnitZ()};
  const double a = 29.0 * M_PI / 180.0, b = 31.0 * M_PI / 180.0;
  EXPECT_FALSE(addsViewSpan(t, Eigen::Vector3d(std::sin(a), 0.0, std::cos(a))));
  EXPECT_TRUE(addsViewSpan(t, Eigen::Vector3d(std::sin(b), 0.0, std::cos(b))));
  // Two views 10 degrees apart: a third 31 degrees from one of them adds the span.
  const double c = 10.0 * M_PI / 180.0;
  t.seen_from.push_back(Eigen::Vector3d(std::sin(c), 0.0, std::cos(c)));
  EXPECT_TRUE(addsViewSpan(t, Eigen::Vector3d(-std::sin(a), 0.0, std::cos(a))));
}

// A fruitlet under a leaf: a camera beside it sees it whole, one above sees none of it, and
// unknown space hides nothing.
TEST(InfoGainEvaluator, VisibleFractionIsBlockedByOccupiedSpaceOnly) {
  auto e = map::createMapEngine("octomap", testing::plannerTestConfig(), kRegion, nullptr);
  const Eigen::Vector3d fruitlet = kRegion.center_m();
  const double radius_m = 0.005;
  const Eigen::Vector3d side(0.0, -0.3, 0.3);
  std::vector<Eigen::Vector3f> roi, leaf;
  // The near side of the fruitlet as the side camera sees it, and a leaf 6 cm above it.
  for (int i = -4; i <= 4; ++i)
    for (int k = -4; k <= 4; ++k) {
      const Eigen::Vector3d o(0.001 * i, 0.0, 0.001 * k);
      if (o.norm() >= radius_m) continue;
      const double depth_m = std::sqrt(radius_m * radius_m - o.squaredNorm());
      roi.push_back((fruitlet + o - Eigen::Vector3d(0.0, depth_m, 0.0)).cast<float>());
    }
  for (double x = -0.06; x <= 0.06; x += 0.003)
    for (double y = -0.06; y <= 0.06; y += 0.003)
      leaf.push_back(Eigen::Vector3f(float(x), float(y), float(fruitlet.z() + 0.06)));
  e->integrate(map::testing::makeClouds(side, roi, leaf));
  InfoGainEvaluator gain(InfoGainConfig{});
  gain.refresh(*e);
  EXPECT_DOUBLE_EQ(gain.visibleFraction(side, fruitlet, radius_m), 1.0);
  EXPECT_DOUBLE_EQ(
      gain.visibleFraction(fruitlet + Eigen::Vector3d(0.0, 0.0, 0.3), fruitlet, radius_m), 0.0);
  // From the far side, through space no view has seen: nothing known blocks it.
  EXPECT_DOUBLE_EQ(gain.visibleFraction(Eigen::Vector3d(0.0, 0.3, 0.3), fruitlet, radius_m), 1.0);
  EXPECT_DOUBLE_EQ(gain.visibleFraction(fruitlet, fruitlet, radius_m), 0.0) << "inside";
}

// Sizing candidates join the heap with the predicted fraction in view as their gain.
TEST(FvpPlanner, AimsAtSizingTargetsOnlyWhenAskedAndScoresThemByWhatIsInView) {
  auto e = mappedEngine();
  PlannerConfig config;
  config.utility_threshold = 5.0;  // nothing is tried: every candidate is scored and kept
  config.max_sampling_rounds = 1;
  SizingTarget target;
  target.center_m = kRegion.center_m();
  target.radius_m = 0.006;
  const Eigen::Isometry3d now(Eigen::Translation3d(0.0, -0.3, 0.35));
  const auto never = [](const Eigen::Isometry3d&) { return false; };
  config.sizing_samples = 0;
  FvpPlanner off(config, 3);
  off.setSizingTargets({target});
  for (const Candidate& c : planAndMove(off, *e, now, inShell, never).candidates)
    EXPECT_NE(c.kind, CandidateKind::kSizing) << "sizing_samples 0: none";
  config.sizing_samples = 60;
  FvpPlanner on(config, 3);
  on.setSizingTargets({target});
  const PlanStep step = planAndMove(on, *e, now, inShell, never);
  std::size_t sizing = 0, scored = 0;
  for (const Candidate& c : step.candidates) {
    if (c.kind != CandidateKind::kSizing) continue;
    ++sizing;
    if (!c.reachable) continue;
    ++scored;
    EXPECT_TRUE(c.ig == 0.0 || c.ig >= target.min_visible_fraction) << c.ig;
    EXPECT_NEAR(c.utility, c.ig - config.alpha_per_m * (c.position_m() - now.translation()).norm(),
                1e-12);
  }
  EXPECT_EQ(sizing, 60u);
  EXPECT_GT(scored, 0u);
  on.setSizingTargets({});
  for (const Candidate& c : planAndMove(on, *e, now, inShell, never).candidates)
    EXPECT_NE(c.kind, CandidateKind::kSizing);
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
  const PlanStep failed = planAndMove(planner, *e, now, inShell, [&](const Eigen::Isometry3d&) {
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
  const PlanStep moved = planAndMove(planner, *e, now, inShell,
                                     [&](const Eigen::Isometry3d&) { return ++attempt == 2; });
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
      planAndMove(planner, *e, Eigen::Isometry3d(Eigen::Translation3d(0.0, -0.3, 0.35)), inShell,
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
