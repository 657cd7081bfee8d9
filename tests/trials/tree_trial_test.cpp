// A trial over a tree: every cluster is visited once, nearest start view next; one whose
// start view the arm cannot reach is skipped and counted; the coarse map carries over from
// cluster to cluster; a fixed clock makes the run repeat exactly. Two views a cluster keep
// it short.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include "fvp/host/nbv/arm.h"
#include "fvp/robot/sim/world.h"
#include "fvp/trials/trial.h"

namespace fvp::trials {
namespace {

constexpr std::uint64_t kSeed = 2;

class TreeTrial : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("fvp_tree_trial_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "tree.yaml") << "cluster_count: 3\nleaf_count: 10\n";
    world_config_.cluster_count = 3;
    world_config_.leaf_count = 10;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  TrialOptions options() const {
    TrialOptions o;
    o.seed = kSeed;
    o.world_config = dir_ / "tree.yaml";
    o.backend = "cpu";
    o.clock = "fixed";
    o.max_views = 2;
    return o;
  }

  std::filesystem::path dir_;
  robot::sim::WorldConfig world_config_;
};

// The simulated arm, except that it cannot reach anywhere near one cluster's start view.
class ArmWithAnUnreachableCluster : public host::nbv::Arm {
 public:
  ArmWithAnUnreachableCluster(host::nbv::Arm& arm, const Eigen::Vector3d& blocked_m)
      : arm_(arm), blocked_m_(blocked_m) {}
  Eigen::Isometry3d cameraPose() const override { return arm_.cameraPose(); }
  bool reachable(const Eigen::Isometry3d& T) const override {
    return !blocked(T) && arm_.reachable(T);
  }
  host::nbv::MoveResult moveTo(const Eigen::Isometry3d& T) override {
    if (blocked(T)) return {host::nbv::MoveStatus::kNoIk, 0.0};
    return arm_.moveTo(T);
  }
  std::size_t updateObstacles(host::map::MapEngine& map) override {
    return arm_.updateObstacles(map);
  }

 private:
  bool blocked(const Eigen::Isometry3d& T) const {
    return (T.translation() - blocked_m_).norm() < 0.2;
  }
  host::nbv::Arm& arm_;
  Eigen::Vector3d blocked_m_;
};

TEST_F(TreeTrial, VisitsEveryClusterOnceAndSkipsOneItCannotReach) {
  const auto world = robot::sim::World::generate(world_config_, kSeed);
  ASSERT_EQ(world.clusters().size(), 3u);
  const int blocked = 2;
  TrialOptions o = options();
  o.out_dir = dir_ / "out";
  Trial trial(o);
  ArmWithAnUnreachableCluster arm(trial.simulatedArm(),
                                  world.clusters()[blocked].T_world_start_camera.translation());
  const nlohmann::json r = trial.run(trial.simulatedCamera(), arm);

  ASSERT_EQ(r.at("clusters").size(), 3u);
  std::set<int> visited;
  for (const auto& k : r.at("tour").at("order")) visited.insert(k.get<int>());
  EXPECT_EQ(visited, (std::set<int>{0, 1, 2}));
  EXPECT_EQ(r["tour"]["order"][0], 0) << "the arm starts at the first cluster's start view";
  EXPECT_EQ(r["tour"]["cluster_status"]["unreachable"], 1);
  EXPECT_EQ(r["tour"]["cluster_status"]["sized"], 2);
  int views = 0;
  for (const auto& c : r["clusters"]) {
    if (c["index"] == blocked) {
      EXPECT_EQ(c["status"], "unreachable");
      EXPECT_FALSE(c.contains("views"));
      continue;
    }
    EXPECT_EQ(c["status"], "sized");
    EXPECT_EQ(c["views"], 2);
    views += c["views"].get<int>();
    EXPECT_EQ(c["fruitlets"].size(),
              world.clusters()[c["index"].get<std::size_t>()].fruitlet_indices.size());
    EXPECT_TRUE(std::filesystem::exists(o.out_dir / ("cluster_" + c["index"].dump()) / "mesh.ply"));
  }
  EXPECT_EQ(r["views"], views);
  // Every fruitlet of the tree is scored once, the blocked cluster's as missed.
  ASSERT_EQ(r["fruitlets"].size(), world.fruitlets().size());
  for (const auto& f : r["fruitlets"]) {
    if (f["cluster"] == blocked) {
      EXPECT_FALSE(f["matched"].get<bool>());
    }
  }
  EXPECT_EQ(r["stop_reason"], "tour_done");

  // The coarse map written at the end still holds the first cluster's surroundings: the map
  // was carried from cluster to cluster, not started afresh.
  octomap::OcTree coarse((o.out_dir / "coarse.bt").string());
  const Eigen::Vector3d first = world.clusters()[0].center_m;
  int occupied_near_first = 0;
  for (auto it = coarse.begin_leafs(); it != coarse.end_leafs(); ++it)
    if (coarse.isNodeOccupied(*it) &&
        (Eigen::Vector3d(it.getX(), it.getY(), it.getZ()) - first).norm() < 0.05)
      ++occupied_near_first;
  EXPECT_GT(occupied_near_first, 10);
  EXPECT_NE(r["tour"]["order"].back(), 0);

  // The viewer's scene holds every fruitlet of the tree, the skipped cluster's too, and its
  // labels are the report's (C<k>.D<i>, C<k>.F<j>).
  std::ifstream page_in(o.out_dir / "viewer.html");
  const std::string page((std::istreambuf_iterator<char>(page_in)), {});
  const std::string open_tag = "<script type=\"application/json\" id=\"fvp-scene\">";
  const std::size_t begin = page.find(open_tag);
  ASSERT_NE(begin, std::string::npos);
  const std::size_t start = begin + open_tag.size();
  const nlohmann::json scene =
      nlohmann::json::parse(page.substr(start, page.find("</script>", start) - start));
  EXPECT_EQ(scene.at("ground_truth").size(), r["fruitlets"].size());
  std::ifstream report_in(o.out_dir / "report.md");
  const std::string report((std::istreambuf_iterator<char>(report_in)), {});
  std::size_t detections = 0;
  for (const auto& d : scene.at("detections")) {
    ++detections;
    EXPECT_NE(report.find("| " + d.at("label").get<std::string>() + " |"), std::string::npos)
        << d.at("label");
  }
  std::size_t expected_detections = 0;
  for (const auto& c : r["clusters"])
    if (c.contains("sized_fruitlets"))
      expected_detections += c["sized_fruitlets"].size() + c["unsupported_detections"].size();
  EXPECT_EQ(detections, expected_detections);
  for (const auto& f : scene.at("ground_truth"))
    EXPECT_NE(report.find("| " + f.at("label").get<std::string>() + " |"), std::string::npos)
        << f.at("label");
  EXPECT_EQ(scene.at("cluster_regions").size(), 2u);  // the sized clusters'
}

TEST_F(TreeTrial, RepeatsExactlyWithAFixedClock) {
  const nlohmann::json a = runTrial(options());
  const nlohmann::json b = runTrial(options());
  for (const char* key : {"tour", "views", "sim_time_s", "fruitlets", "detections", "metrics"})
    EXPECT_EQ(a.at(key), b.at(key)) << key;
  EXPECT_EQ(a["tour"]["cluster_status"].value("sized", 0), 3);
}

}  // namespace
}  // namespace fvp::trials
