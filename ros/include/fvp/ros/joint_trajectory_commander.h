// The arm's driver over ROS (docs/ros.md): PlannedArm's trajectories sent as
// trajectory_msgs/JointTrajectory to a joint trajectory controller's command topic, the motion
// followed on joint_states. A topic, not control_msgs' FollowJointTrajectory action: Debian 12
// packages no control_msgs, and ros_control's JointTrajectoryController (which Universal Robots'
// driver runs) takes the same trajectory on its `command` topic. C++17, as ROS 1's headers are.
#pragma once

#include <ros/node_handle.h>
#include <ros/publisher.h>

#include <string>

#include "fvp/robot/planned_arm.h"
#include "fvp/robot/trajectory_executor.h"
#include "fvp/ros/joint_state_listener.h"

namespace fvp::ros {

struct JointTrajectoryCommanderOptions {
  std::string command_topic = "/scaled_pos_joint_traj_controller/command";
  /// The largest gap between the points sent (sampleTimes_s): the controller interpolates
  /// between them with cubic splines, which follow the planned motion closely at 10 Hz.
  double max_point_period_s = 0.1;
  /// How far the joints may be from the trajectory's end when the motion is over (rad, m).
  double goal_tolerance = robot::kDefaultGoalTolerance;
  /// Wall seconds the motion may take beyond its duration (a driver scales speed down, e.g.
  /// the UR's speed slider) before it counts as failed.
  double settle_timeout_s = 10.0;
  /// Wall seconds to wait for the controller to subscribe before the move is refused.
  double connect_timeout_s = 5.0;
  void validate() const;  ///< throws std::invalid_argument naming the field
};

class JointTrajectoryCommander : public robot::TrajectoryExecutor {
 public:
  /// `joints` must outlive the commander; its joint names name the trajectory's joints.
  JointTrajectoryCommander(::ros::NodeHandle& node, const JointStateListener& joints,
                           JointTrajectoryCommanderOptions options);

  /// Publishes the trajectory (stamp 0: start now) and waits until joint_states stamped at or
  /// after its end put every joint within goal_tolerance of the last point. kRefused when no
  /// controller listens; kFailed when the joints do not get there in time.
  robot::ExecutionResult execute(const robot::Trajectory& trajectory) override;

 private:
  const JointStateListener& joints_;
  JointTrajectoryCommanderOptions options_;
  ::ros::Publisher publisher_;
};

}  // namespace fvp::ros
