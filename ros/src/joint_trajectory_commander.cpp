#include "fvp/ros/joint_trajectory_commander.h"

#include <ros/time.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>

namespace fvp::ros {
namespace {

trajectory_msgs::JointTrajectory trajectoryMsg(const robot::Trajectory& trajectory,
                                               const std::vector<std::string>& names,
                                               double max_period_s) {
  trajectory_msgs::JointTrajectory message;
  message.joint_names = names;  // header.stamp stays 0: the controller starts it on arrival
  const std::vector<double> times = robot::sampleTimes_s(trajectory, max_period_s);
  for (std::size_t i = 0; i < times.size(); ++i) {
    const bool last = i + 1 == times.size();
    // The last point is the planned goal itself, not the spline evaluated at its end.
    const robot::JointVector q =
        last ? trajectory.waypoints().back() : trajectory.position(times[i]);
    const robot::JointVector v =
        last ? robot::JointVector::Zero().eval() : trajectory.velocity(times[i]);
    trajectory_msgs::JointTrajectoryPoint point;
    point.positions.assign(q.data(), q.data() + q.size());
    point.velocities.assign(v.data(), v.data() + v.size());
    point.time_from_start = ::ros::Duration(times[i]);
    message.points.push_back(std::move(point));
  }
  return message;
}

}  // namespace

void JointTrajectoryCommanderOptions::validate() const {
  if (command_topic.empty()) throw std::invalid_argument("command_topic: expected a topic name");
  if (!(max_point_period_s > 0.0))
    throw std::invalid_argument("max_point_period_s: expected seconds > 0");
  if (!(goal_tolerance > 0.0)) throw std::invalid_argument("goal_tolerance: expected > 0");
  if (!(settle_timeout_s > 0.0)) throw std::invalid_argument("settle_timeout_s: expected > 0");
  if (!(connect_timeout_s >= 0.0))
    throw std::invalid_argument("connect_timeout_s: expected seconds >= 0");
}

JointTrajectoryCommander::JointTrajectoryCommander(::ros::NodeHandle& node,
                                                   const JointStateListener& joints,
                                                   JointTrajectoryCommanderOptions options)
    : joints_(joints), options_(std::move(options)) {
  options_.validate();
  publisher_ = node.advertise<trajectory_msgs::JointTrajectory>(options_.command_topic, 1);
}

robot::ExecutionResult JointTrajectoryCommander::execute(const robot::Trajectory& trajectory) {
  if (trajectory.empty())
    throw std::invalid_argument("JointTrajectoryCommander: an empty trajectory");
  // ROS 1 drops what is published before a subscriber has connected.
  const auto wall_start = std::chrono::steady_clock::now();
  while (publisher_.getNumSubscribers() == 0) {
    if (std::chrono::steady_clock::now() - wall_start >
        std::chrono::duration<double>(options_.connect_timeout_s))
      return {robot::ExecutionStatus::kRefused,
              "no controller subscribes to " + options_.command_topic};
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const ::ros::Time due = ::ros::Time::now() + ::ros::Duration(trajectory.duration_s());
  publisher_.publish(trajectoryMsg(trajectory, joints_.jointNames(), options_.max_point_period_s));
  const robot::JointVector goal = trajectory.waypoints().back();
  const double tolerance = options_.goal_tolerance;
  const bool arrived = joints_.waitUntil(
      [&](const robot::JointVector& q, const ::ros::Time& stamp) {
        return stamp >= due && (q - goal).cwiseAbs().maxCoeff() <= tolerance;
      },
      trajectory.duration_s() + options_.settle_timeout_s);
  if (!arrived)
    return {robot::ExecutionStatus::kFailed,
            "the joints on " + joints_.topic() + " did not reach the trajectory's end within " +
                std::to_string(options_.settle_timeout_s) + " s of its duration"};
  return {robot::ExecutionStatus::kDone, {}};
}

}  // namespace fvp::ros
