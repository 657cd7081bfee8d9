// The paper-size checks (CTest label `heavy`): 100 random feasible planning queries in
// cluttered simulated worlds (>= 97 % success), and the 10 M-sample workspace tree (build
// time, load time, agreement with IK).
#include <gtest/gtest.h>

#include <chrono>
#include <sstream>

#include "planning_queries.h"
#include "workspace_agreement.h"

namespace fvp::robot {
namespace {

TEST(ArmHeavy, PlanningSucceedsOnAtLeast97PercentOf100FeasibleQueries) {
  const testing::QueryStats stats = testing::runPlanningQueries(10, 10, 1000);
  stats.print(std::cout);
  EXPECT_EQ(stats.feasible, 100);
  EXPECT_GE(stats.succeeded, 97);
  EXPECT_EQ(stats.path_invalid, 0);
}

TEST(ArmHeavy, TenMillionSampleWorkspaceTree) {
  ArmConfig config;  // the defaults: 10 M samples
  const auto dir = std::filesystem::temp_directory_path() / "fvp_workspace_heavy";
  std::filesystem::remove_all(dir);
  config.workspace_cache_dir = dir.string();
  const ArmModel arm(config);
  std::ostringstream log;
  auto start = std::chrono::steady_clock::now();
  const WorkspaceTree built = WorkspaceTree::loadOrBuild(arm, log);
  const double build_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  start = std::chrono::steady_clock::now();
  const WorkspaceTree loaded = WorkspaceTree::loadOrBuild(arm, log);
  const double load_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "workspace tree: " << config.workspace_samples << " samples built in " << build_s
            << " s (incl. writing the cache), loaded in " << load_s << " s\n";
  EXPECT_TRUE(loaded.fromCache());
  EXPECT_LT(build_s, 60.0);
  EXPECT_LT(load_s, 1.0);
  const testing::Agreement agreement = testing::compareWithIk(arm, loaded, 2000, 21);
  agreement.print(std::cout, loaded);
  EXPECT_GE(agreement.rate(), 0.9);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace fvp::robot
