// The simulated arm's driver: "executes" a trajectory instantly by charging its duration to the
// simulated clock as motion and setting the joints to its end. It never refuses or fails.
#pragma once

#include "fvp/robot/sim/sim_clock.h"
#include "fvp/robot/sim/simulated_joint_state.h"
#include "fvp/robot/trajectory_executor.h"

namespace fvp::robot::sim {

class SimulatedTrajectoryExecutor : public TrajectoryExecutor {
 public:
  /// `clock` and `joints` must outlive the executor.
  SimulatedTrajectoryExecutor(SimClock& clock, SimulatedJointState& joints)
      : clock_(clock), joints_(joints) {}

  /// Throws std::invalid_argument for an empty trajectory (PlannedArm never sends one).
  ExecutionResult execute(const Trajectory& trajectory) override;
  /// The same for a trajectory that came from elsewhere as its duration and end (the ROS
  /// bridge's joint trajectory messages): charged as motion, the joints left at `end`.
  void run(double duration_s, const JointVector& end);

 private:
  SimClock& clock_;
  SimulatedJointState& joints_;
};

}  // namespace fvp::robot::sim
