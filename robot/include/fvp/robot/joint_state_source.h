// Where a real arm's joints are now (a UR5 driver's joint_states, with the slider's position):
// PlannedArm reads it for the camera pose, as the start of every motion, to free the map where
// the arm stands, and after an execution to check that the arm reached the trajectory's end.
#pragma once

#include "fvp/robot/arm_model.h"

namespace fvp::robot {

class JointStateSource {
 public:
  virtual ~JointStateSource() = default;
  /// The 7 joints in ArmModel's order: q[0] the slider (m), q[1..6] the UR5's base,
  /// shoulder, elbow, wrist 1, wrist 2, wrist 3 (rad, the driver's own angles: not wrapped).
  virtual JointVector jointPositions() const = 0;
};

}  // namespace fvp::robot
