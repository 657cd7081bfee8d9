#include "fvp/robot/sim/simulated_arm.h"

namespace fvp::robot::sim {

SimulatedArm::SimulatedArm(const ArmModel& arm, const Reachability& reachability, SimClock& clock,
                           const JointVector& start)
    : joint_state_(start),
      executor_(clock, joint_state_),
      arm_(arm, reachability, joint_state_, executor_) {
  // Before the executor charges the motion: the order of the charges is the order of
  // the clock's sums, which fixed-clock runs repeat bit for bit.
  arm_.setPlanningObserver([&clock](const MotionPlan& plan) {
    clock.chargeCompute(ClockStage::kMotionPlanning, plan.planning_wall_s);
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
