// The simulated arm's joints: what a real arm's driver would report, here simply what the
// simulated executor last set.
#pragma once

#include "fvp/robot/joint_state_source.h"

namespace fvp::robot::sim {

class SimulatedJointState : public JointStateSource {
 public:
  explicit SimulatedJointState(const JointVector& q) : q_(q) {}
  JointVector jointPositions() const override { return q_; }
  void set(const JointVector& q) { q_ = q; }

 private:
  JointVector q_;
};

}  // namespace fvp::robot::sim
