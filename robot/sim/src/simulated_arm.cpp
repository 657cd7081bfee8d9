#include "fvp/robot/sim/simulated_arm.h"

#include "fvp/host/map/map_engine.h"

namespace fvp::robot::sim {
namespace {

host::nbv::MoveStatus toMoveStatus(MotionStatus status) {
  using host::nbv::MoveStatus;
  switch (status) {
    case MotionStatus::kSuccess:
      return MoveStatus::kSuccess;
    case MotionStatus::kNoIk:
      return MoveStatus::kNoIk;
    case MotionStatus::kNoCollisionFreeIk:
      return MoveStatus::kNoCollisionFreeIk;
    case MotionStatus::kStartInvalid:
      return MoveStatus::kStartInvalid;
    case MotionStatus::kNoPath:
      return MoveStatus::kNoPath;
    case MotionStatus::kTimeout:
      return MoveStatus::kTimeout;
  }
  return MoveStatus::kNoPath;
}

}  // namespace

SimulatedArm::SimulatedArm(ArmController& controller, const WorkspaceTree& workspace)
    : controller_(controller), workspace_(workspace) {}

Eigen::Isometry3d SimulatedArm::cameraPose() const {
  return controller_.cameraPose();
}

bool SimulatedArm::reachable(const Eigen::Isometry3d& T_world_camera) const {
  return workspace_.reachable(T_world_camera);
}

host::nbv::MoveResult SimulatedArm::moveTo(const Eigen::Isometry3d& T_world_camera) {
  const MotionPlan plan = controller_.moveToPose(T_world_camera);
  return {toMoveStatus(plan.status), plan.planning_wall_s};
}

std::size_t SimulatedArm::updateObstacles(host::map::MapEngine& map) {
  return controller_.setMap(map.coarseOcTree());
}

}  // namespace fvp::robot::sim
