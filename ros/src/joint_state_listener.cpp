#include "fvp/ros/joint_state_listener.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <stdexcept>

namespace fvp::ros {

std::vector<std::string> defaultJointNames() {
  return {"slider_joint",  "shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
          "wrist_1_joint", "wrist_2_joint",      "wrist_3_joint"};
}

JointStateListener::JointStateListener(::ros::NodeHandle& node, const std::string& topic,
                                       std::vector<std::string> joint_names)
    : topic_(topic), names_(std::move(joint_names)) {
  if (names_.size() != std::size_t(robot::kArmJoints) ||
      std::set<std::string>(names_.begin(), names_.end()).size() != names_.size())
    throw std::invalid_argument("joint_names: expected " + std::to_string(robot::kArmJoints) +
                                " distinct names (the slider, then the UR5's six)");
  subscriber_ = node.subscribe(topic, 50, &JointStateListener::onJointState, this);
}

void JointStateListener::onJointState(const sensor_msgs::JointState::ConstPtr& message) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::size_t n = std::min(message->name.size(), message->position.size());
    for (std::size_t i = 0; i < n; ++i) {
      const auto it = std::find(names_.begin(), names_.end(), message->name[i]);
      if (it == names_.end()) continue;  // another part of the robot
      if (!std::isfinite(message->position[i])) {
        ++invalid_;
        continue;
      }
      const auto j = std::size_t(it - names_.begin());
      q_[Eigen::Index(j)] = message->position[i];
      seen_[j] = true;
      stamps_[j] = std::max(stamps_[j], message->header.stamp);
    }
  }
  changed_.notify_all();
}

bool JointStateListener::complete() const {
  return std::all_of(seen_.begin(), seen_.end(), [](bool seen) { return seen; });
}

robot::JointVector JointStateListener::jointPositions() const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (std::size_t j = 0; j < seen_.size(); ++j)
    if (!seen_[j])
      throw std::runtime_error(topic_ + ": no position of joint '" + names_[j] + "' yet");
  return q_;
}

bool JointStateListener::waitUntil(
    const std::function<bool(const robot::JointVector&, const ::ros::Time&)>& done,
    double timeout_wall_s) const {
  std::unique_lock<std::mutex> lock(mutex_);
  // A joint's position is as fresh as its own newest message (a slider's driver may publish
  // apart from the arm's): the state's stamp is the oldest of them.
  return changed_.wait_for(lock, std::chrono::duration<double>(timeout_wall_s), [&] {
    return complete() && done(q_, *std::min_element(stamps_.begin(), stamps_.end()));
  });
}

std::size_t JointStateListener::invalidPositions() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return invalid_;
}

}  // namespace fvp::ros
