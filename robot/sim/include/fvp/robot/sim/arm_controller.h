// The simulated arm controller: plans with MotionPlanner and "executes" by advancing the
// simulated clock by the trajectory's duration and setting the joints (and so the camera
// pose) to the trajectory's end. Planning wall time is charged as motion_planning.
#pragma once

#include <Eigen/Geometry>
#include <optional>

#include "fvp/robot/arm_collision_checker.h"
#include "fvp/robot/motion_planner.h"
#include "fvp/robot/sim/sim_clock.h"

namespace fvp::robot::sim {

class ArmController {
 public:
  /// `arm` and `clock` must outlive the controller.
  ArmController(const ArmModel& arm, SimClock& clock, const JointVector& start);

  /// The start configuration for a world's start view: its IK solution nearest the arm's
  /// home configuration that is free of self and static collision; none when unreachable.
  static std::optional<JointVector> startConfiguration(const ArmModel& arm,
                                                       const Eigen::Isometry3d& T_world_camera);

  /// The coarse map planning avoids from now on (copied), less the voxels the arm itself
  /// occupies now (ArmCollisionChecker::setMapFreeAt); returns how many those were.
  std::size_t setMap(const octomap::OcTree& coarse_map) {
    return checker_.setMapFreeAt(coarse_map, joints_);
  }
  /// Plans to the camera pose, charges the planning time, and on success charges and
  /// "executes" the motion. Never throws for planning failures.
  MotionPlan moveToPose(const Eigen::Isometry3d& T_world_camera);

  /// Motion planning as MotionPlanner::setReproducible (fvp run --clock fixed): the same
  /// moves on any machine and under any load.
  void setReproducibleMotionPlanning(std::uint64_t seed) { planner_.setReproducible(seed); }

  const JointVector& joints() const { return joints_; }
  Eigen::Isometry3d cameraPose() const { return arm_.T_world_camera(joints_); }
  const ArmCollisionChecker& checker() const { return checker_; }

 private:
  const ArmModel& arm_;
  SimClock& clock_;
  ArmCollisionChecker checker_;
  MotionPlanner planner_;
  JointVector joints_;
};

}  // namespace fvp::robot::sim
