// Reachability by inverse kinematics (ArmModel::reachableByIk): exact for the arm without a
// map, where the workspace tree is a cached approximation of it; slower (IK along the slider's
// travel per query), and needs no tree. For arms that plan without a viewpoint planner
// (ArmController) or without a tree.
#pragma once

#include "fvp/robot/arm_model.h"
#include "fvp/robot/reachability.h"

namespace fvp::robot {

class IkReachability : public Reachability {
 public:
  /// `arm` must outlive this.
  explicit IkReachability(const ArmModel& arm) : arm_(arm) {}
  bool reachable(const Eigen::Isometry3d& T_world_camera) const override {
    return arm_.reachableByIk(T_world_camera);
  }

 private:
  const ArmModel& arm_;
};

}  // namespace fvp::robot
