// The simulator as a robot over ROS (docs/ros.md): a simulated world, its stereo camera and the
// UR5 on its slider (trials::SimulatedRobot) behind the topics a real robot offers. It publishes
// /clock, joint_states and the camera's pose on tf; it renders and publishes a stereo pair on each
// trigger and runs each joint trajectory the controller topic receives on the simulated arm.
//
// Its clock is the simulator's: a capture costs the camera's capture time and a trajectory its
// duration (jumps, as in a trial); between those, time runs with the wall clock, so the fvp
// node's own compute counts as on a robot. Rendering is the simulator's cost: the clock stands
// still while a pair renders. C++17.
#pragma once

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <ros/subscriber.h>
#include <std_msgs/Header.h>
#include <tf2_ros/transform_broadcaster.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <chrono>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "fvp/robot/arm_model.h"
#include "fvp/ros/stereo_bag.h"
#include "fvp/trials/simulated_robot.h"

namespace fvp::ros {

struct SimBridgeOptions {
  trials::SimulatedRobotOptions robot;  ///< the world's seed and configs
  StereoBagTopics topics;               ///< where the pairs go, and the world frame
  std::string camera_frame = "stereo_left_optical";
  std::string trigger_topic = "/stereo/trigger";
  std::string command_topic = "/scaled_pos_joint_traj_controller/command";
  std::string joint_states_topic = "/joint_states";
  std::vector<std::string> joint_names;  ///< empty: defaultJointNames()
  double publish_rate_hz = 50.0;         ///< /clock, joint_states and tf between events
  void validate() const;                 ///< throws std::invalid_argument naming the field
};

/// What the bridge did, counted.
struct SimBridgeStats {
  std::size_t captures = 0, trajectories = 0;
  std::size_t rejected_trajectories = 0;  ///< not the arm's joints, not finite, off limits
};

class SimBridge {
 public:
  /// Builds the world and the robot (throws for bad options or files) and advertises.
  SimBridge(::ros::NodeHandle& node, SimBridgeOptions options);
  ~SimBridge();

  /// The simulated time now (frozen during an event).
  ::ros::Time now() const;
  /// Publishes /clock, then joint_states and the camera's pose stamped now (only /clock while
  /// an event runs). The bridge node's main loop calls it at publish_rate_hz.
  void publishState();
  /// The world's clusters, as an fvp node's goal would name them: per cluster its tag id, the
  /// start view (x y z qx qy qz qw, the left optical frame in the world) and its centre.
  std::vector<std::vector<double>> clusterTable() const;
  SimBridgeStats stats() const;
  trials::SimulatedRobot& robot() { return *robot_; }

 private:
  void onTrigger(const std_msgs::Header::ConstPtr& trigger);
  /// Renders the pair at the arm's pose and publishes it stamped `stamp`, pose first.
  void capture(const ::ros::Time& stamp);
  /// Publishes /clock now, never older than the last; returns the time sent.
  ::ros::Time publishClock();
  void onTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& trajectory);
  /// Why a trajectory cannot be run on the arm, or empty (fills duration_s and end).
  std::string check(const trajectory_msgs::JointTrajectory& t, double& duration_s,
                    robot::JointVector& end) const;
  /// Stops the clock for an event; returns the time it stopped at.
  ::ros::Time freeze();
  /// Runs the clock on from the stop plus the simulated seconds the event charged.
  void thaw(double charged_s);
  void publishStateAt(const ::ros::Time& stamp);

  SimBridgeOptions options_;
  std::unique_ptr<trials::SimulatedRobot> robot_;
  std::mutex event_mutex_;        ///< held by an event, and by publishState when none runs
  ::ros::Time last_state_stamp_;  ///< of the newest joint state and tf published
  std::mutex publish_mutex_;      ///< /clock's read-and-send
  ::ros::Time last_clock_;
  mutable std::mutex clock_mutex_;
  double base_s_ = 0.0;  ///< simulated seconds at wall_mark_
  std::chrono::steady_clock::time_point wall_mark_;
  bool frozen_ = false;
  mutable std::mutex stats_mutex_;
  SimBridgeStats stats_;
  ::ros::Publisher clock_, joint_states_, left_, right_, left_info_, right_info_, mask_, disparity_;
  tf2_ros::TransformBroadcaster tf_;
  ::ros::Subscriber trigger_, command_;
};

}  // namespace fvp::ros
