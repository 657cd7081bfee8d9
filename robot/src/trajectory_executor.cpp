#include "fvp/robot/trajectory_executor.h"

#include <cmath>
#include <stdexcept>

namespace fvp::robot {

const char* toString(ExecutionStatus status) {
  switch (status) {
    case ExecutionStatus::kDone:
      return "done";
    case ExecutionStatus::kRefused:
      return "refused";
    case ExecutionStatus::kFailed:
      return "failed";
  }
  return "unknown";
}

std::vector<double> sampleTimes_s(const Trajectory& trajectory, double max_period_s) {
  if (!(max_period_s > 0.0) || !std::isfinite(max_period_s))
    throw std::invalid_argument("sampleTimes_s: the period must be positive and finite");
  const double duration_s = trajectory.duration_s();
  const auto intervals = static_cast<std::size_t>(std::ceil(duration_s / max_period_s));
  std::vector<double> times_s{0.0};
  for (std::size_t i = 1; i <= intervals; ++i)
    times_s.push_back(i == intervals
                          ? duration_s
                          : duration_s * static_cast<double>(i) / static_cast<double>(intervals));
  return times_s;
}

}  // namespace fvp::robot
