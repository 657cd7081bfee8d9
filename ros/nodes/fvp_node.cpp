// The fvp node (docs/ros.md): the library's next-best-view sizing behind a ROS action. It
// assembles the robot from topics, tf and the arm's model (StereoTopicCamera, PlannedArm over
// JointStateListener and JointTrajectoryCommander, RosLoopClock) and offers ~size_clusters.
#include <ros/ros.h>
#include <tf2_ros/transform_listener.h>

#include <iostream>
#include <sstream>

#include "fvp/robot/arm_model.h"
#include "fvp/robot/planned_arm.h"
#include "fvp/robot/workspace_tree.h"
#include "fvp/ros/joint_state_listener.h"
#include "fvp/ros/joint_trajectory_commander.h"
#include "fvp/ros/node_settings.h"
#include "fvp/ros/rviz_publisher.h"
#include "fvp/ros/size_clusters_server.h"
#include "fvp/ros/stereo_topic_camera.h"

namespace {

/// The arm's workspace tree from its cache (built once per arm config, minutes).
fvp::robot::WorkspaceTree workspaceOf(const fvp::robot::ArmModel& arm) {
  std::ostringstream log;
  fvp::robot::WorkspaceTree tree = fvp::robot::WorkspaceTree::loadOrBuild(arm, log);
  std::istringstream lines(log.str());
  for (std::string line; std::getline(lines, line);) ROS_INFO_STREAM(line);
  return tree;
}

int run() {
  ros::NodeHandle node, private_node("~");
  const fvp::ros::FvpNodeSettings settings = fvp::ros::readNodeSettings(private_node);
  fvp::robot::ArmConfig arm_config = settings.arm_config.empty()
                                         ? fvp::robot::ArmConfig{}
                                         : fvp::robot::ArmConfig::fromYamlFile(settings.arm_config);
  if (arm_config.workspace_cache_dir.empty())
    arm_config.workspace_cache_dir = fvp::robot::defaultCacheDir();
  const fvp::robot::ArmModel arm(arm_config);
  const fvp::robot::WorkspaceTree workspace = workspaceOf(arm);
  tf2_ros::Buffer tf;
  tf2_ros::TransformListener tf_listener(tf);
  fvp::ros::JointStateListener joints(node, settings.joint_states_topic, settings.joint_names);
  fvp::ros::JointTrajectoryCommander commander(node, joints, settings.commander);
  fvp::robot::PlannedArm planned(arm, workspace, joints, commander,
                                 settings.commander.goal_tolerance);
  if (settings.reproducible_motion_seed)
    planned.setReproducibleMotionPlanning(*settings.reproducible_motion_seed);
  fvp::ros::StereoTopicCamera camera(node, tf, settings.camera);
  fvp::ros::RvizPublisher rviz(private_node, settings.camera.topics.world_frame);
  ros::AsyncSpinner spinner(4);  // topics keep arriving while a goal's loop runs
  spinner.start();
  ros::Time::waitForValid();  // with use_sim_time: the first /clock, so goals start on it
  fvp::ros::SizeClustersServer server(private_node, "size_clusters", settings.setup, camera,
                                      planned, &rviz);
  ROS_INFO_STREAM("fvp: offering " << private_node.resolveName("size_clusters"));
  ros::waitForShutdown();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "fvp");
  try {
    return run();
  } catch (const std::exception& e) {  // misconfiguration: a parameter, a config file
    ROS_FATAL_STREAM("fvp: " << e.what());
    std::cerr << "fvp: " << e.what() << "\n";
    return 2;
  }
}
