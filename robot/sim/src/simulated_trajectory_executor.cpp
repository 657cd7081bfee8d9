#include "fvp/robot/sim/simulated_trajectory_executor.h"

#include <stdexcept>

namespace fvp::robot::sim {

ExecutionResult SimulatedTrajectoryExecutor::execute(const Trajectory& trajectory) {
  if (trajectory.empty())
    throw std::invalid_argument("SimulatedTrajectoryExecutor: an empty trajectory");
  run(trajectory.duration_s(), trajectory.waypoints().back());
  return {ExecutionStatus::kDone, {}};
}

void SimulatedTrajectoryExecutor::run(double duration_s, const JointVector& end) {
  clock_.chargeMotion(duration_s);
  joints_.set(end);
}

}  // namespace fvp::robot::sim
