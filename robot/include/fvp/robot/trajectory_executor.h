// What a real arm's driver does with a planned motion (PlannedArm hands it every trajectory it
// plans): run it from the arm's current joints to its end, blocking, and say how that went.
// A UR5 driver sends it as a joint trajectory (sampleTimes_s gives the time points); the
// simulator charges its duration to the simulated clock. The driver owns the timing of the
// execution: the trajectory's times are what the planner's limits allow, a driver may scale
// them. Refusals and failures are statuses; an exception means the executor is broken.
#pragma once

#include <string>
#include <vector>

#include "fvp/robot/trajectory.h"

namespace fvp::robot {

enum class ExecutionStatus {
  kDone,     ///< the arm ran the trajectory to its end
  kRefused,  ///< the driver or its operator refused it; the arm did not move
  kFailed,   ///< it started and stopped before the end (protective stop, fault, abort)
};

/// "done", "refused", "failed".
const char* toString(ExecutionStatus status);

struct ExecutionResult {
  ExecutionStatus status = ExecutionStatus::kFailed;
  std::string detail;  ///< the driver's words, for the log
  bool done() const { return status == ExecutionStatus::kDone; }
};

class TrajectoryExecutor {
 public:
  virtual ~TrajectoryExecutor() = default;
  /// Runs the trajectory (at least one waypoint; it starts at the joints the arm's
  /// JointStateSource gave when planning began) and returns when the arm is at rest.
  virtual ExecutionResult execute(const Trajectory& trajectory) = 0;
};

/// Time points for sending `trajectory` to a driver: 0, then evenly spaced at most
/// max_period_s apart, the last exactly duration_s() (one point, 0, for a trajectory of
/// no duration). Throws std::invalid_argument for a period that is not positive.
std::vector<double> sampleTimes_s(const Trajectory& trajectory, double max_period_s);

}  // namespace fvp::robot
