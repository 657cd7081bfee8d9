// The one function of robot/sim/src/trial_parts.cpp that experiment.cpp calls, for the
// standalone fuzz build of readTrials (trial_parts.cpp needs the whole trial: maps, planners,
// perception). Same definition; the trials harness does not reach it. Goes away when
// readTrials moves to experiment_directory.cpp (fuzz/CMakeLists.txt, FVP_FUZZ_TRIALS_SOURCES).
#include <string>

namespace fvp::robot::sim {

std::string defaultEngine(const std::string& planner) {
  return planner == "rvp" ? "octomap" : "grid";
}

}  // namespace fvp::robot::sim
