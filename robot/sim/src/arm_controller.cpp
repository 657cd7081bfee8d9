#include "fvp/robot/sim/arm_controller.h"

namespace fvp::robot::sim {

ArmController::ArmController(const ArmModel& arm, SimClock& clock, const JointVector& start)
    : arm_(arm), clock_(clock), checker_(arm), planner_(checker_), joints_(start) {}

std::optional<JointVector> ArmController::startConfiguration(
    const ArmModel& arm, const Eigen::Isometry3d& T_world_camera) {
  for (const JointVector& q : arm.inverse(T_world_camera, arm.homeConfiguration())) {
    if (!arm.selfOrStaticCollision(arm.linkCapsules(q))) return q;
  }
  return std::nullopt;
}

MotionPlan ArmController::moveToPose(const Eigen::Isometry3d& T_world_camera) {
  MotionPlan plan = planner_.moveToPose(joints_, T_world_camera);
  clock_.chargeCompute(ClockStage::kMotionPlanning, plan.planning_wall_s);
  if (plan.ok()) {
    clock_.chargeMotion(plan.trajectory.duration_s());
    joints_ = plan.trajectory.waypoints().back();
  }
  return plan;
}

}  // namespace fvp::robot::sim
