// The fvp node's action (docs/ros.md, "The size_clusters action"): a goal names one cluster or
// several; the library's NbvSetup sizes them with the node's camera, arm and ROS clock (one
// cluster: its loop; several: the tour, in the order that reaches them soonest). Feedback after
// every view and every cluster; the result holds the sized fruitlets and how each cluster ended.
// A cancel ends the running cluster's loop at its next step (stop reason "cancelled") and visits
// no further cluster. C++17.
#pragma once

#include <actionlib/server/simple_action_server.h>
#include <fvp_ros/SizeClustersAction.h>
#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <memory>
#include <string>
#include <vector>

#include "fvp/host/nbv/nbv_setup.h"
#include "fvp/ros/rviz_publisher.h"

namespace fvp::ros {

/// The goal's clusters as the library's targets. A start pose whose quaternion is all zero is
/// not given: the cluster's first view is where the camera is (T_world_camera_now). Throws
/// std::invalid_argument naming the cluster and field for a goal that cannot be run.
std::vector<host::nbv::ClusterTarget> targetsOfGoal(const fvp_ros::SizeClustersGoal& goal,
                                                    const Eigen::Isometry3d& T_world_camera_now);

/// The simulator bridge's ~clusters table (SimBridge::clusterTable's rows: tag id, start view
/// x y z qx qy qz qw, centre x y z) as a goal of every cluster, each by its tag when there are
/// several (one: the perception config's tag, as a trial of a one-cluster world). Throws
/// std::invalid_argument for a table that is not rows of 11 numbers.
fvp_ros::SizeClustersGoal goalOfClusterTable(XmlRpc::XmlRpcValue& table);

/// The result message of a tour of a goal of goal_clusters clusters: a cluster whose loop a
/// cancel ended is "cancelled", one the tour never reached "not_visited".
fvp_ros::SizeClustersResult resultOfTour(const host::nbv::TourResult& tour,
                                         std::size_t goal_clusters, double time_s);

class SizeClustersServer {
 public:
  /// The camera, the arm and the publisher (may be null) must outlive the server. Checks the
  /// options and builds the backend (NbvSetup) before the action is offered.
  SizeClustersServer(::ros::NodeHandle& node, const std::string& action_name,
                     host::nbv::NbvSetupOptions options, host::nbv::Camera& camera,
                     host::nbv::Arm& arm, RvizPublisher* rviz);

 private:
  void execute(const fvp_ros::SizeClustersGoalConstPtr& goal);

  host::nbv::Camera& camera_;
  host::nbv::Arm& arm_;
  RvizPublisher* rviz_;
  std::unique_ptr<host::nbv::NbvSetup> setup_;
  actionlib::SimpleActionServer<fvp_ros::SizeClustersAction> server_;
};

}  // namespace fvp::ros
