// The simulated arm without a viewpoint planner's reachability filter, for code that plans
// single moves and wants the plans (fvp plan, tests, benchmarks): a SimulatedArm (PlannedArm
// over the simulated driver: planning time charged as motion_planning, the trajectory's
// duration as motion, the joints set to its end) whose reachability is exact IK.
#pragma once

#include <Eigen/Geometry>
#include <optional>

#include "fvp/robot/ik_reachability.h"
#include "fvp/robot/sim/simulated_arm.h"

namespace fvp::robot::sim {

class ArmController {
 public:
  /// `arm` and `clock` must outlive the controller.
  ArmController(const ArmModel& arm, SimClock& clock, const JointVector& start)
      : reachability_(arm), arm_(arm, reachability_, clock, start) {}

  /// SimulatedArm::startConfiguration.
  static std::optional<JointVector> startConfiguration(const ArmModel& arm,
                                                       const Eigen::Isometry3d& T_world_camera) {
    return SimulatedArm::startConfiguration(arm, T_world_camera);
  }

  /// The coarse map planning avoids from now on (copied), less the voxels the arm itself
  /// occupies now (ArmCollisionChecker::setMapFreeAt); returns how many those were.
  std::size_t setMap(const octomap::OcTree& coarse_map) {
    return arm_.planned().setMap(coarse_map);
  }
  /// Plans to the camera pose, charges the planning time, and on success charges and
  /// "executes" the motion. Never throws for planning failures.
  MotionPlan moveToPose(const Eigen::Isometry3d& T_world_camera) {
    return arm_.planned().moveToPose(T_world_camera).plan;
  }

  void setReproducibleMotionPlanning(std::uint64_t seed) {
    arm_.setReproducibleMotionPlanning(seed);
  }

  JointVector joints() const { return arm_.joints(); }
  Eigen::Isometry3d cameraPose() const { return arm_.cameraPose(); }
  const ArmCollisionChecker& checker() const { return arm_.planned().checker(); }
  SimulatedArm& arm() { return arm_; }

 private:
  IkReachability reachability_;
  SimulatedArm arm_;
};

}  // namespace fvp::robot::sim
