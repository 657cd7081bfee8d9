// The fvp node's parts that need no ROS master (docs/ros.md): its parameters, the goal's
// targets, the bridge's cluster table as a goal, and the result of a tour.
#include <fvp_ros/SizeClustersAction.h>
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "fvp/ros/node_settings.h"
#include "fvp/ros/size_clusters_server.h"

namespace {

using XmlRpc::XmlRpcValue;

class Params {
 public:
  Params& set(const std::string& key, XmlRpcValue value) {
    values_[key] = value;
    return *this;
  }
  fvp::ros::ParamLookup lookup() const {
    return [this](const std::string& key, XmlRpcValue& value) {
      const auto it = values_.find(key);
      if (it == values_.end()) return false;
      value = it->second;
      return true;
    };
  }

 private:
  std::map<std::string, XmlRpcValue> values_;
};

std::string errorOf(const Params& params) {
  try {
    fvp::ros::readNodeSettings(params.lookup());
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(NodeSettings, DefaultsAreTheLibrarysAndTheRobotsTopics) {
  const fvp::ros::FvpNodeSettings s = fvp::ros::readNodeSettings(Params().lookup());
  EXPECT_EQ(s.setup.planner, "fvp");
  EXPECT_EQ(s.setup.stop.budget_s, 180.0);
  EXPECT_EQ(s.camera.topics.left_image, "/stereo/left/image_rect_color");
  EXPECT_EQ(s.camera.topics.world_frame, "world");
  EXPECT_EQ(s.joint_names.size(), 7u);
  EXPECT_FALSE(s.reproducible_motion_seed);
}

TEST(NodeSettings, TheRunsSettingsHaveTheLibrarysKeys) {
  Params p;
  p.set("stop", "auto").set("budget_s", 90).set("max_views", 12).set("seed", 7);
  p.set("view_overhead_s", 0.0).set("backend", "cpu").set("stereo_ns", "/cam");
  p.set("reproducible_motion_seed", 7);
  const fvp::ros::FvpNodeSettings s = fvp::ros::readNodeSettings(p.lookup());
  EXPECT_EQ(s.setup.stop.rule, fvp::host::nbv::StopRule::kAuto);
  EXPECT_EQ(s.setup.stop.budget_s, 90.0);  // an integer is a number
  EXPECT_EQ(s.setup.stop.max_views, 12);
  EXPECT_EQ(s.setup.planner_seed, 7u);
  EXPECT_EQ(s.setup.loop.view_overhead_s, 0.0);  // 0 is a choice for this one
  EXPECT_EQ(s.setup.backend, fvp::accel::BackendChoice::kCpu);
  EXPECT_EQ(s.camera.topics.right_info, "/cam/right/camera_info");
  EXPECT_EQ(s.reproducible_motion_seed, 7u);
  // max_views 0 is no limit, as the CLI's.
  EXPECT_FALSE(
      fvp::ros::readNodeSettings(Params().set("max_views", 0).lookup()).setup.stop.max_views);
}

TEST(NodeSettings, ABadParameterIsNamedWithWhatWasExpected) {
  EXPECT_EQ(errorOf(Params().set("budget_s", -1)),
            "parameter '~budget_s': expected a finite number > 0, got -1");
  EXPECT_EQ(errorOf(Params().set("stop", "soon")),
            "parameter '~stop': expected one of budget,auto, got 'soon'");
  EXPECT_EQ(errorOf(Params().set("backend", 3)), "parameter '~backend': expected a string, got 3");
  EXPECT_EQ(errorOf(Params().set("use_mask", "yes")),
            "parameter '~use_mask': expected true or false, got 'yes'");
  XmlRpcValue names;
  names[0] = "a";
  EXPECT_NE(errorOf(Params().set("joint_names", names)).find("joint_names"), std::string::npos);
  EXPECT_NE(errorOf(Params().set("capture_timeout_s", 0.0)).find("capture_timeout_s"),
            std::string::npos);
  EXPECT_NE(errorOf(Params().set("planner", "nbv")).find("planner"), std::string::npos);
}

XmlRpcValue tableRow(int tag, double x) {
  XmlRpcValue row;
  const double values[11] = {double(tag), x, -0.3, 1.0, 0.0, 0.0, 0.0, 1.0, x, 0.0, 1.0};
  for (int i = 0; i < 11; ++i) row[i] = values[i];
  return row;
}

TEST(SizeClustersGoal, TheBridgesTableIsAGoalOfEveryCluster) {
  XmlRpcValue one;
  one[0] = tableRow(0, 0.2);
  fvp_ros::SizeClustersGoal goal = fvp::ros::goalOfClusterTable(one);
  ASSERT_EQ(goal.clusters.size(), 1u);
  EXPECT_FALSE(goal.clusters[0].use_tag_id);  // one cluster: the perception config's tag
  XmlRpcValue two;
  two[0] = tableRow(4, 0.2);
  two[1] = tableRow(5, -0.2);
  goal = fvp::ros::goalOfClusterTable(two);
  ASSERT_EQ(goal.clusters.size(), 2u);
  EXPECT_TRUE(goal.clusters[1].use_tag_id);
  EXPECT_EQ(goal.clusters[1].tag_id, 5);
  EXPECT_EQ(goal.clusters[1].start_camera_pose.position.x, -0.2);
  XmlRpcValue bad;
  bad[0] = 3;
  EXPECT_THROW(fvp::ros::goalOfClusterTable(bad), std::invalid_argument);
}

TEST(SizeClustersGoal, TargetsKeepTheGoalsPosesAndRefuseBadOnes) {
  XmlRpcValue two;
  two[0] = tableRow(4, 0.2);
  two[1] = tableRow(5, -0.2);
  fvp_ros::SizeClustersGoal goal = fvp::ros::goalOfClusterTable(two);
  Eigen::Isometry3d now = Eigen::Isometry3d::Identity();
  now.translation() = Eigen::Vector3d(1, 2, 3);
  auto targets = fvp::ros::targetsOfGoal(goal, now);
  ASSERT_EQ(targets.size(), 2u);
  EXPECT_EQ(targets[1].tag_id, 5);
  EXPECT_TRUE(
      targets[1].T_world_start_camera.translation().isApprox(Eigen::Vector3d(-0.2, -0.3, 1.0)));
  // No start pose (a quaternion of zeros): from where the camera is.
  goal.clusters[1].start_camera_pose = geometry_msgs::Pose();
  targets = fvp::ros::targetsOfGoal(goal, now);
  EXPECT_TRUE(targets[1].T_world_start_camera.isApprox(now));
  goal.clusters[1].start_camera_pose.orientation.w = 0.5;  // not a unit quaternion
  try {
    fvp::ros::targetsOfGoal(goal, now);
    FAIL() << "a quaternion of norm 0.5 was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("clusters[1].start_camera_pose"), std::string::npos);
  }
  EXPECT_THROW(fvp::ros::targetsOfGoal(fvp_ros::SizeClustersGoal(), now), std::invalid_argument);
}

TEST(SizeClustersResult, CountsEveryClusterAndItsFruitlets) {
  fvp::host::nbv::TourResult tour;
  fvp::host::nbv::ClusterVisit sized;
  sized.index = 1;
  sized.status = fvp::host::nbv::VisitStatus::kSized;
  sized.run.emplace();
  sized.run->run.views = 3;
  sized.run->run.stop_reason = "cluster_done";
  sized.run->run.camera_poses.assign(3, Eigen::Isometry3d::Identity());
  fvp::host::sizing::FruitletEstimate f;
  f.size_mm = 12.5;
  f.center_m = Eigen::Vector3d(0.1, 0.2, 0.3);
  sized.run->sizing.fruitlets = {f, f};
  fvp::host::nbv::ClusterVisit skipped;
  skipped.index = 0;
  skipped.status = fvp::host::nbv::VisitStatus::kUnreachable;
  tour.visits.push_back(std::move(sized));
  tour.visits.push_back(skipped);
  const fvp_ros::SizeClustersResult r = fvp::ros::resultOfTour(tour, 3, 42.0);
  EXPECT_EQ(r.views, 3u);
  EXPECT_EQ(r.time_s, 42.0);
  ASSERT_EQ(r.fruitlets.size(), 2u);
  EXPECT_EQ(r.fruitlets[0].cluster_index, 1u);
  EXPECT_EQ(r.fruitlets[0].diameter_mm, 12.5);
  ASSERT_EQ(r.clusters.size(), 3u);
  EXPECT_EQ(r.clusters[0].stop_reason, "cluster_done");
  EXPECT_EQ(r.clusters[0].camera_poses.size(), 3u);
  EXPECT_EQ(r.clusters[1].status, "unreachable");
  EXPECT_EQ(r.clusters[2].cluster_index, 2u);  // a cancel ended the tour before it
  EXPECT_EQ(r.clusters[2].status, "not_visited");
}

}  // namespace
