#include "fvp/robot/sim/simulated_trajectory_executor.h"

#include <stdexcept>

namespace fvp::robot::sim {

ExecutionResult SimulatedTrajectoryExecutor::execute(const Trajectory& trajectory) {
  if (trajectory.empty())
    throw std::invalid_argument("SimulatedTrajectoryExecutor: an empty trajectory");
  clock_.chargeMotion(trajectory.duration_s());
  joints_.set(trajectory.waypoints().back());
  return {ExecutionStatus::kDone, {}};
}

}  // namespace fvp::robot::sim
