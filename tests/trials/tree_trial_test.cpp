// A trial over a tree: every cluster is visited once, nearest start view next; one whose
// start view the arm cannot reach is skipped and counted; the coarse map carries over from
// cluster to cluster; a fixed clock makes the run repeat exactly. Two views a cluster keep
// it short.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>

#include "fvp/host/nbv/arm.h"
#include "fvp/host/nbv/camera.h"
#include "fvp/robot/sim/world.h"
#include "fvp/trials/experiment_directory.h"
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
    o.backend = accel::BackendChoice::kCpu;
    o.clock = robot::sim::SimClock::Mode::kFixed;
    o.max_views = 2;
    return o;
  }

  std::filesystem::path dir_;
  robot::sim::WorldConfig world_config_;
};

// The simulated arm, except where `blocked` says it cannot go.
class ArmWithABlockedRegion : public host::nbv::Arm {
 public:
  using Blocked = std::function<bool(const Eigen::Isometry3d&)>;
  ArmWithABlockedRegion(host::nbv::Arm& arm, Blocked blocked)
      : arm_(arm), blocked_(std::move(blocked)) {}
  Eigen::Isometry3d cameraPose() const override { return arm_.cameraPose(); }
  bool reachable(const Eigen::Isometry3d& T) const override {
    return !blocked_(T) && arm_.reachable(T);
  }
  host::nbv::MoveResult moveTo(const Eigen::Isometry3d& T) override {
    if (blocked_(T)) return {host::nbv::MoveStatus::kNoIk, 0.0, 0.0};
    return arm_.moveTo(T);
  }
  std::size_t updateObstacles(host::map::MapEngine& map) override {
    return arm_.updateObstacles(map);
  }

 private:
  host::nbv::Arm& arm_;
  Blocked blocked_;
};

// The simulated camera, except that from the poses `hidden` names the tag is not seen: the
// left image is blacked out (a leaf before the tag from there).
class CameraWithAHiddenTag : public host::nbv::Camera {
 public:
  using Hidden = std::function<bool(const Eigen::Isometry3d&)>;
  CameraWithAHiddenTag(host::nbv::Camera& camera, Hidden hidden)
      : camera_(camera), hidden_(std::move(hidden)) {}
  host::nbv::CaptureResult capture(const Eigen::Isometry3d& T_world_camera) override {
    host::nbv::CaptureResult r = camera_.capture(T_world_camera);
    if (r.ok() && hidden_(T_world_camera)) {
      r.frame.left_bgr.setTo(cv::Scalar::all(0));
      ++hidden_captures;
    }
    return r;
  }
  int hidden_captures = 0;

 private:
  host::nbv::Camera& camera_;
  Hidden hidden_;
};

/// Distance from p to the line through a along the unit direction u.
double distanceToLine(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                      const Eigen::Vector3d& u) {
  return (p - a - (p - a).dot(u) * u).norm();
}

TEST_F(TreeTrial, VisitsEveryClusterOnceAndSkipsOneItCannotReach) {
  const auto world = robot::sim::World::generate(world_config_, kSeed);
  ASSERT_EQ(world.clusters().size(), 3u);
  const int blocked = 2;
  TrialOptions o = options();
  o.out_dir = dir_ / "out";
  Trial trial(o);
  // No view of that cluster at all: nothing within 0.6 m whose optical axis passes near it.
  const Eigen::Vector3d centre = world.clusters()[blocked].center_m;
  ArmWithABlockedRegion arm(trial.simulatedArm(), [centre](const Eigen::Isometry3d& T) {
    return (T.translation() - centre).norm() < 0.6 &&
           distanceToLine(centre, T.translation(), T.linear().col(2)) < 0.02;
  });
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
    // The tag's frame, in which a later visit finds the same fruitlets (docs/season.md).
    EXPECT_TRUE(c.contains("T_world_tag")) << "cluster " << c["index"];
    for (const auto& f : c["sized_fruitlets"]) EXPECT_TRUE(f.contains("center_tag_m"));
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

// Where foliage stands on a cluster's axis (its start view and every view straight back from
// it blocked), the tour reaches it from a view turned 20 degrees about the vertical.
TEST_F(TreeTrial, ReachesAClusterFromATurnedViewWhenItsAxisIsBlocked) {
  const auto world = robot::sim::World::generate(world_config_, kSeed);
  const int blocked = 2;
  const robot::sim::FruitletCluster& cluster = world.clusters()[blocked];
  const Eigen::Vector3d centre = cluster.center_m;
  const Eigen::Vector3d axis = -cluster.T_world_start_camera.linear().col(2);
  TrialOptions o = options();
  o.out_dir = dir_ / "turned";
  Trial trial(o);
  ArmWithABlockedRegion arm(trial.simulatedArm(), [&](const Eigen::Isometry3d& T) {
    return (T.translation() - centre).dot(axis) > 0.1 &&
           distanceToLine(T.translation(), centre, axis) < 0.03;
  });
  const nlohmann::json r = trial.run(trial.simulatedCamera(), arm);
  EXPECT_EQ(r["tour"]["cluster_status"].value("sized", 0), 3);
  for (const auto& c : r["clusters"]) {
    if (c["index"] != blocked) continue;
    EXPECT_EQ(c["status"], "sized");
    EXPECT_EQ(c["approach_yaw_deg"], 20.0);
    EXPECT_NEAR(c["approach_distance_m"].get<double>(),
                (cluster.T_world_start_camera.translation() - centre).norm(), 1e-6);
  }
  // The others from their own axes, as before.
  for (const auto& c : r["clusters"]) {
    if (c["index"] != blocked && c.contains("approach_yaw_deg")) {
      EXPECT_EQ(c["approach_yaw_deg"], 0.0);
    }
  }
}

// A cluster whose tag its start view does not show is mapped from the next approach view
// (5 cm farther out along its axis), not given up.
TEST_F(TreeTrial, TriesTheNextApproachViewWhenTheTagIsNotSeen) {
  const auto world = robot::sim::World::generate(world_config_, kSeed);
  const int hidden = 2;
  const robot::sim::FruitletCluster& cluster = world.clusters()[hidden];
  TrialOptions o = options();
  o.out_dir = dir_ / "hidden";
  Trial trial(o);
  CameraWithAHiddenTag camera(trial.simulatedCamera(), [&](const Eigen::Isometry3d& T) {
    return (T.translation() - cluster.T_world_start_camera.translation()).norm() < 1e-3;
  });
  const nlohmann::json r = trial.run(camera, trial.simulatedArm());
  EXPECT_EQ(camera.hidden_captures, 1);
  EXPECT_EQ(r["tour"]["cluster_status"].value("sized", 0), 3);
  for (const auto& c : r["clusters"]) {
    if (c["index"] != hidden) {
      EXPECT_EQ(c.value("approaches_without_tag", -1), 0);
      continue;
    }
    EXPECT_EQ(c["status"], "sized");
    EXPECT_EQ(c["approaches_without_tag"], 1);
    EXPECT_EQ(c["approach_yaw_deg"], 0.0);
    EXPECT_NEAR(c["approach_distance_m"].get<double>(),
                (cluster.T_world_start_camera.translation() - cluster.center_m).norm() + 0.05,
                1e-6);
    EXPECT_EQ(c["views"], 3) << "the untagged view, then the cluster's two";
  }
}

TEST_F(TreeTrial, RepeatsExactlyWithAFixedClock) {
  const nlohmann::json a = runTrial(options());
  const nlohmann::json b = runTrial(options());
  for (const char* key : {"tour", "views", "sim_time_s", "fruitlets", "detections", "metrics"})
    EXPECT_EQ(a.at(key), b.at(key)) << key;
  EXPECT_EQ(a["tour"]["cluster_status"].value("sized", 0), 3);
}

// The fixed clock charges perception what the stereo pass the trial runs costs: the guided
// kernels' 0.2 s a view, SGBM's whole-range pass (the default) 0.4 s.
TEST_F(TreeTrial, TheFixedClockChargesPerceptionByTheStereoPass) {
  TrialOptions o = options();
  o.world_config.clear();  // one cluster
  o.max_views = 1;
  ASSERT_FALSE(o.guided_stereo) << "SGBM's pass is the default";
  for (const bool guided : {true, false}) {
    o.guided_stereo = guided;
    const nlohmann::json r = runTrial(o);
    const int views = r.at("views").get<int>();
    ASSERT_GE(views, 1);
    EXPECT_NEAR(r["sim_time_by_stage_s"].at("perception_s").get<double>(),
                views * robot::sim::fixedPerceptionTimeS(guided), 1e-9)
        << (guided ? "guided" : "SGBM");
    EXPECT_EQ(r.at("clock_charges"), ExperimentManifest::clockChargesFor(guided));
  }
  EXPECT_DOUBLE_EQ(robot::sim::fixedPerceptionTimeS(true), 0.2);
  EXPECT_DOUBLE_EQ(robot::sim::fixedPerceptionTimeS(false), 0.4);
}

}  // namespace
}  // namespace fvp::trials
