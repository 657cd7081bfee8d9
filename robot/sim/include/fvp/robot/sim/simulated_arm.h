// The simulated UR5 on its slider as the next-best-view loop's arm: reachability from the
// workspace tree, moves by IK + OMPL + instant execution charged to the simulated clock,
// obstacles from the loop's coarse map.
#pragma once

#include "fvp/host/nbv/arm.h"
#include "fvp/robot/sim/arm_controller.h"
#include "fvp/robot/workspace_tree.h"

namespace fvp::robot::sim {

class SimulatedArm : public host::nbv::Arm {
 public:
  /// controller and workspace must outlive the arm.
  SimulatedArm(ArmController& controller, const WorkspaceTree& workspace);

  Eigen::Isometry3d cameraPose() const override;
  bool reachable(const Eigen::Isometry3d& T_world_camera) const override;
  host::nbv::MoveResult moveTo(const Eigen::Isometry3d& T_world_camera) override;
  /// The collision checker's map becomes the coarse map, with the voxels the arm occupies
  /// where it stands freed (returns how many).
  std::size_t updateObstacles(host::map::MapEngine& map) override;

 private:
  ArmController& controller_;
  const WorkspaceTree& workspace_;
};

}  // namespace fvp::robot::sim
