// The arm's joints from a ROS topic (sensor_msgs/JointState, docs/ros.md): what PlannedArm reads
// for the camera pose and as the start of every motion. Messages may carry any subset of joints
// (a UR driver publishes its six, the slider's driver its one); each joint keeps its newest
// finite position. C++17, as ROS 1's headers are.
#pragma once

#include <ros/node_handle.h>
#include <ros/subscriber.h>
#include <sensor_msgs/JointState.h>

#include <array>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "fvp/robot/joint_state_source.h"

namespace fvp::ros {

/// The joint names of a UR5 on a linear slider in ArmModel's order: the slider, then the names
/// Universal Robots' ROS driver gives its six joints.
std::vector<std::string> defaultJointNames();

class JointStateListener : public robot::JointStateSource {
 public:
  /// Subscribes to `topic`; joint_names are the 7 joints in ArmModel's order. Throws
  /// std::invalid_argument for a list that is not 7 distinct names.
  JointStateListener(::ros::NodeHandle& node, const std::string& topic,
                     std::vector<std::string> joint_names);

  /// The newest position of every joint. Throws std::runtime_error naming the topic and the
  /// first joint no message has given yet.
  robot::JointVector jointPositions() const override;
  /// Waits until `done(joints, stamp)` holds for the newest state (every joint known; stamp the
  /// oldest of the joints' newest messages), at most timeout_wall_s of wall time. Returns
  /// whether it did.
  bool waitUntil(const std::function<bool(const robot::JointVector&, const ::ros::Time&)>& done,
                 double timeout_wall_s) const;
  /// Positions that were not finite, ignored (a driver's glitch: expected, counted).
  std::size_t invalidPositions() const;
  const std::vector<std::string>& jointNames() const { return names_; }
  const std::string& topic() const { return topic_; }

 private:
  void onJointState(const sensor_msgs::JointState::ConstPtr& message);
  bool complete() const;  // with mutex_ held

  std::string topic_;
  std::vector<std::string> names_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  robot::JointVector q_ = robot::JointVector::Zero();
  std::array<bool, robot::kArmJoints> seen_{};
  std::array<::ros::Time, robot::kArmJoints> stamps_{};
  std::size_t invalid_ = 0;
  ::ros::Subscriber subscriber_;
};

}  // namespace fvp::ros
