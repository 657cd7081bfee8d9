// The simulated UR5 on its slider as the next-best-view loop's arm: the real-robot PlannedArm
// (reachability, IK + OMPL against the loop's coarse map) over a simulated driver, whose
// executor charges each trajectory's duration to the simulated clock and sets the joints to
// its end. Planning time is charged as motion_planning after every plan, failed ones too.
#pragma once

#include <optional>

#include "fvp/robot/planned_arm.h"
#include "fvp/robot/sim/sim_clock.h"
#include "fvp/robot/sim/simulated_joint_state.h"
#include "fvp/robot/sim/simulated_trajectory_executor.h"

namespace fvp::robot::sim {

class SimulatedArm : public host::nbv::Arm {
 public:
  /// `arm`, `reachability` and `clock` must outlive the simulated arm; it starts at `start`.
  SimulatedArm(const ArmModel& arm, const Reachability& reachability, SimClock& clock,
               const JointVector& start);
  // The planned arm refers to this object's joint state, executor and planning flag.
  SimulatedArm(const SimulatedArm&) = delete;
  SimulatedArm& operator=(const SimulatedArm&) = delete;

  /// The start configuration for a world's start view: its IK solution nearest the arm's
  /// home configuration that is free of self and static collision; none when unreachable.
  static std::optional<JointVector> startConfiguration(const ArmModel& arm,
                                                       const Eigen::Isometry3d& T_world_camera);

  Eigen::Isometry3d cameraPose() const override { return arm_.cameraPose(); }
  bool reachable(const Eigen::Isometry3d& T_world_camera) const override {
    return arm_.reachable(T_world_camera);
  }
  host::nbv::MoveResult moveTo(const Eigen::Isometry3d& T_world_camera) override {
    return arm_.moveTo(T_world_camera);
  }
  bool checksGoals() const override { return arm_.checksGoals(); }
  host::planner::GoalReach checkGoal(const Eigen::Isometry3d& T_world_camera) const override {
    return arm_.checkGoal(T_world_camera);
  }
  double travelTime_s(const Eigen::Isometry3d& T_world_from_camera,
                      const Eigen::Isometry3d& T_world_to_camera) const override {
    return arm_.travelTime_s(T_world_from_camera, T_world_to_camera);
  }
  /// The collision checker's map becomes the coarse map, with the voxels the arm occupies
  /// where it stands freed (returns how many).
  std::size_t updateObstacles(host::map::MapEngine& map) override {
    return arm_.updateObstacles(map);
  }

  /// Motion planning as MotionPlanner::setReproducible (fvp run --clock fixed): the same
  /// moves on any machine and under any load.
  /// The fixed clock then charges each plan its validity checks' time (SimClock::
  /// chargeMotionPlanning), which only reproducible planning makes the same on any machine.
  void setReproducibleMotionPlanning(std::uint64_t seed) {
    arm_.setReproducibleMotionPlanning(seed);
    reproducible_planning_ = true;
  }
  JointVector joints() const { return joint_state_.jointPositions(); }
  /// A motion the arm's driver was sent from outside the loop (the ROS bridge's joint
  /// trajectories), as its duration and end: charged as motion, the joints left at `end`.
  void runSentMotion(double duration_s, const JointVector& end) { executor_.run(duration_s, end); }
  PlannedArm& planned() { return arm_; }
  const PlannedArm& planned() const { return arm_; }

 private:
  SimulatedJointState joint_state_;
  SimulatedTrajectoryExecutor executor_;
  PlannedArm arm_;
  bool reproducible_planning_ = false;
};

}  // namespace fvp::robot::sim
