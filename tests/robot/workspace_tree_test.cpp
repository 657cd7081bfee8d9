// The workspace tree: agreement with direct IK, the cache (atomic, keyed, never trusted when
// corrupt or for other parameters). Trees of 0.2-1 M samples keep this fast; the paper's 10 M is
// in arm_heavy_test.cpp.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <random>
#include <sstream>

#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/workspace_tree.h"
#include "workspace_agreement.h"

namespace fvp::robot {
namespace {

ArmConfig smallTreeConfig(const std::string& cache_dir, std::int64_t samples = 200'000) {
  ArmConfig config;
  config.workspace_samples = samples;
  config.workspace_resolution_m = 0.08;
  config.workspace_direction_bins = 2;
  config.workspace_cache_dir = cache_dir;
  return config;
}

std::filesystem::path freshDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("fvp_workspace_test_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(WorkspaceTree, AgreesWithDirectIk) {
  const ArmModel arm(smallTreeConfig("", 1'000'000));
  const WorkspaceTree tree = WorkspaceTree::build(arm);
  const testing::Agreement agreement = testing::compareWithIk(arm, tree, 1000, 9);
  agreement.print(std::cout, tree);
  EXPECT_GE(agreement.rate(), 0.85);
  // The tree's misses are rare where IK says reachable (a coarse tree errs towards "yes").
  EXPECT_GE(agreement.ik_reachable, 200);
}

TEST(WorkspaceTree, IsDeterministic) {
  const ArmModel arm(smallTreeConfig(""));
  const WorkspaceTree a = WorkspaceTree::build(arm), b = WorkspaceTree::build(arm);
  EXPECT_EQ(a.nonEmptyBins(), b.nonEmptyBins());
  EXPECT_GT(a.nonEmptyBins(), 1000u);
}

TEST(WorkspaceTree, CacheIsWrittenLoadedAndNeverTrustedWhenCorrupt) {
  const auto dir = freshDir("cache");
  const ArmModel arm(smallTreeConfig(dir.string()));
  std::ostringstream log;
  const WorkspaceTree built = WorkspaceTree::loadOrBuild(arm, log);
  EXPECT_FALSE(built.fromCache());
  const auto path = WorkspaceTree::cachePath(arm);
  ASSERT_TRUE(std::filesystem::exists(path));
  // Only the cache file: the temporary file was renamed.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir),
                          std::filesystem::directory_iterator()),
            1);

  const auto start = std::chrono::steady_clock::now();
  const WorkspaceTree loaded = WorkspaceTree::loadOrBuild(arm, log);
  const double load_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(loaded.fromCache());
  EXPECT_LT(load_s, 1.0);
  EXPECT_EQ(loaded.nonEmptyBins(), built.nonEmptyBins());
  EXPECT_TRUE(log.str().empty()) << log.str();

  // Flip one byte in the middle: detected, warned about, rebuilt, rewritten.
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(std::filesystem::file_size(path) / 2));
    f.put('\x5a');
  }
  const WorkspaceTree rebuilt = WorkspaceTree::loadOrBuild(arm, log);
  EXPECT_FALSE(rebuilt.fromCache());
  EXPECT_NE(log.str().find("checksum"), std::string::npos) << log.str();
  EXPECT_EQ(rebuilt.nonEmptyBins(), built.nonEmptyBins());
  EXPECT_TRUE(WorkspaceTree::load(path, WorkspaceTree::cacheKey(arm), nullptr).has_value());

  // Truncated: rejected.
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 100);
  std::string why;
  EXPECT_FALSE(WorkspaceTree::load(path, WorkspaceTree::cacheKey(arm), &why).has_value());
  EXPECT_FALSE(why.empty());
}

TEST(WorkspaceTree, CacheForOtherParametersIsNotUsed) {
  const auto dir = freshDir("key");
  const ArmModel arm(smallTreeConfig(dir.string()));
  std::ostringstream log;
  WorkspaceTree::loadOrBuild(arm, log);
  ArmConfig other_config = smallTreeConfig(dir.string());
  other_config.workspace_seed = 2;
  const ArmModel other(other_config);
  EXPECT_NE(WorkspaceTree::cachePath(arm), WorkspaceTree::cachePath(other));
  std::string why;
  EXPECT_FALSE(
      WorkspaceTree::load(WorkspaceTree::cachePath(arm), WorkspaceTree::cacheKey(other), &why));
  EXPECT_NE(why.find("other parameters"), std::string::npos) << why;
  // Even a file renamed to the other key's name is rebuilt, with a warning.
  std::filesystem::copy_file(WorkspaceTree::cachePath(arm), WorkspaceTree::cachePath(other));
  EXPECT_FALSE(WorkspaceTree::loadOrBuild(other, log).fromCache());
  EXPECT_NE(log.str().find("other parameters"), std::string::npos) << log.str();
}

}  // namespace
}  // namespace fvp::robot
