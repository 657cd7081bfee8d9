#include "fvp/robot/sim/simulated_arm.h"

namespace fvp::robot::sim {

SimulatedArm::SimulatedArm(const ArmModel& arm, const Reachability& reachability, SimClock& clock,
                           const JointVector& start)
    : joint_state_(start),
      executor_(clock, joint_state_),
      arm_(arm, reachability, joint_state_, executor_) {
  // Before the executor charges the motion: the order of the charges is the order of
  // the clock's sums, which fixed-clock runs repeat bit for bit.
  // The reference computer's rate: the reproducible budgets are planning_time_s worth of checks.
  const double checks_per_s =
      static_cast<double>(arm.config().reproducible_planning_checks) / arm.config().planning_time_s;
  // A time-limited planner's checks depend on the machine: its plans get the stage's constant.
  arm_.setPlanningObserver([this, &clock, checks_per_s](const MotionPlan& plan) {
    clock.chargeMotionPlanning(
        plan.planning_wall_s,
        reproducible_planning_ ? static_cast<double>(plan.validity_checks) / checks_per_s : 0.0);
  });
}

std::optional<JointVector> SimulatedArm::startConfiguration(
    const ArmModel& arm, const Eigen::Isometry3d& T_world_camera) {
  for (const JointVector& q : arm.inverse(T_world_camera, arm.homeConfiguration())) {
    if (!arm.selfOrStaticCollision(arm.linkCapsules(q))) return q;
  }
  return std::nullopt;
}

}  // namespace fvp::robot::sim
