// rostest (tests/ros/rostest/*.test): the simulator bridge and the fvp node size a world over ROS
// as the library sizes it (docs/ros.md, "Tests"). The test node sends the bridge's clusters as
// one size_clusters goal and compares the result with the library's run of the same seed, world
// and stop: the same views, the same fruitlets (centres within a millimetre) and sizes within
// ~size_tolerance_mm. The library's run is either the result.json `fvp run` wrote (~expected, a
// CTest fixture), or, with ~library_tour, the library's tour run here on the simulated robot
// with the goal's own targets: a goal carries its start views as quaternions, and a tour's
// views can depend on the last bit of a start pose (docs/ros.md, "Tests").
#include <actionlib/client/simple_action_client.h>
#include <fvp_ros/SizeClustersAction.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <Eigen/Core>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "fvp/host/nbv/nbv_setup.h"
#include "fvp/robot/sim/simulated_camera.h"
#include "fvp/ros/size_clusters_server.h"
#include "fvp/trials/simulated_robot.h"

namespace {

struct Sized {
  std::size_t cluster = 0;
  Eigen::Vector3d center_m;
  double size_mm = 0.0;
};

Eigen::Vector3d vec3(const nlohmann::json& v) {
  return {v.at(0).get<double>(), v.at(1).get<double>(), v.at(2).get<double>()};
}

/// The trial's sized fruitlets: a tour's per cluster, one cluster's at the top.
std::vector<Sized> trialFruitlets(const nlohmann::json& result) {
  std::vector<Sized> out;
  if (result.contains("clusters")) {
    for (const auto& c : result["clusters"])
      for (const auto& f : c.value("sized_fruitlets", nlohmann::json::array()))
        out.push_back({c.at("index").get<std::size_t>(), vec3(f.at("center_m")),
                       f.at("size_mm").get<double>()});
  } else {
    for (const auto& f : result.at("sized_fruitlets"))
      out.push_back({0, vec3(f.at("center_m")), f.at("size_mm").get<double>()});
  }
  return out;
}

/// The library's tour of the goal on the simulated robot, as `fvp run --clock fixed --stop auto
/// --backend cpu` assembles it: the sized fruitlets per cluster, and the views.
std::vector<Sized> libraryTour(const fvp_ros::SizeClustersGoal& goal, int seed,
                               const std::string& world_config, int max_views, int& views) {
  fvp::trials::SimulatedRobotOptions robot_options;
  robot_options.seed = std::uint64_t(seed);
  robot_options.world_config = world_config;
  robot_options.clock = fvp::robot::sim::SimClock::Mode::kFixed;
  fvp::trials::SimulatedRobot robot(robot_options);
  fvp::host::nbv::NbvSetupOptions options;
  options.planner_seed = std::uint64_t(seed);
  options.backend = fvp::accel::BackendChoice::kCpu;
  options.stop.rule = fvp::host::nbv::StopRule::kAuto;
  options.stop.budget_s = 1000.0;  // as the node's: the automatic stop ends each cluster
  if (max_views > 0) options.stop.max_views = max_views;
  fvp::host::nbv::NbvSetup setup(options);
  const fvp::host::nbv::TourResult tour =
      setup.runTour({robot.camera(), robot.arm(), robot.loopClock()},
                    fvp::ros::targetsOfGoal(goal, robot.arm().cameraPose()));
  std::vector<Sized> out;
  views = 0;
  for (const fvp::host::nbv::ClusterVisit& visit : tour.visits) {
    if (!visit.run) continue;
    views += visit.run->run.views;
    for (const auto& f : visit.run->sizing.fruitlets)
      out.push_back({visit.index, f.center_m, f.size_mm});
  }
  return out;
}

TEST(SimulatorOverRos, SizesAsTheLibrary) {
  ros::NodeHandle node, private_node("~");
  std::string expected_path, bridge = "/fvp_sim_bridge", action = "/fvp/size_clusters", world;
  double tolerance_mm = 0.05, timeout_s = 900.0;
  bool library_tour = false;
  int seed = 1, max_views = 0;
  private_node.getParam("expected", expected_path);
  private_node.getParam("library_tour", library_tour);
  private_node.getParam("seed", seed);
  private_node.getParam("world_config", world);
  private_node.getParam("max_views", max_views);
  ASSERT_NE(expected_path.empty(), !library_tour)
      << "give ~expected (a result.json) or ~library_tour";
  private_node.getParam("bridge", bridge);
  private_node.getParam("action", action);
  private_node.getParam("size_tolerance_mm", tolerance_mm);
  private_node.getParam("timeout_s", timeout_s);

  XmlRpc::XmlRpcValue table;
  // The bridge sets it once its world is built (its workspace tree from the cache: seconds).
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(timeout_s);
  bool have_table = false;
  while (!(have_table = node.getParam(bridge + "/clusters", table)) &&
         ros::WallTime::now() < give_up)
    ros::WallDuration(0.1).sleep();
  ASSERT_TRUE(have_table) << bridge << "/clusters: the bridge did not start";
  const fvp_ros::SizeClustersGoal goal = fvp::ros::goalOfClusterTable(table);
  actionlib::SimpleActionClient<fvp_ros::SizeClustersAction> client(action, true);
  ASSERT_TRUE(client.waitForServer(ros::Duration(120.0))) << action;
  client.sendGoal(goal);
  ASSERT_TRUE(client.waitForResult(ros::Duration(timeout_s)))
      << "no result in " << timeout_s << " s";
  ASSERT_EQ(client.getState(), actionlib::SimpleClientGoalState::SUCCEEDED)
      << client.getState().getText();
  const fvp_ros::SizeClustersResult result = *client.getResult();

  int views = 0;
  std::vector<Sized> expected;
  if (library_tour) {
    expected = libraryTour(goal, seed, world, max_views, views);
  } else {
    std::ifstream file(expected_path);
    ASSERT_TRUE(file) << expected_path;
    const nlohmann::json trial = nlohmann::json::parse(file);
    expected = trialFruitlets(trial);
    views = trial.at("views").get<int>();
  }
  EXPECT_EQ(int(result.views), views);
  EXPECT_EQ(result.dropped_frames, 0u);
  ASSERT_EQ(result.clusters.size(), goal.clusters.size());
  for (const auto& c : result.clusters)
    EXPECT_EQ(c.status, "sized") << "cluster " << c.cluster_index;
  ASSERT_EQ(result.fruitlets.size(), expected.size());
  std::vector<bool> used(result.fruitlets.size(), false);
  for (const Sized& e : expected) {
    std::size_t best = result.fruitlets.size();
    double best_m = 1e-3;  // the same fruitlet: its centre within a millimetre
    for (std::size_t i = 0; i < result.fruitlets.size(); ++i) {
      const auto& f = result.fruitlets[i];
      const double d = (Eigen::Vector3d(f.center.x, f.center.y, f.center.z) - e.center_m).norm();
      if (!used[i] && f.cluster_index == e.cluster && d < best_m) best = i, best_m = d;
    }
    ASSERT_LT(best, result.fruitlets.size())
        << "the trial's fruitlet of " << e.size_mm << " mm in cluster " << e.cluster
        << " has no counterpart over ROS";
    used[best] = true;
    EXPECT_NEAR(result.fruitlets[best].diameter_mm, e.size_mm, tolerance_mm);
    std::printf("cluster %zu  library %7.3f mm  over ROS %7.3f mm  centres %.3f mm apart\n",
                e.cluster, e.size_mm, result.fruitlets[best].diameter_mm, best_m * 1e3);
  }
  std::printf("views %u, ROS time %.1f s\n", result.views, result.time_s);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "fvp_sim_agreement_test");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
