// The registries' names for the option checks (the parse-only fuzz build uses the experiment
// files' copy instead, fuzz/cli_vocabulary_fixed.cpp, held equal by fvp_experiment_test).
#include "commands.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/planner/planner_registry.h"

namespace fvp::apps {

std::vector<std::string> plannerNames() {
  return host::planner::PlannerRegistry::instance().names();
}

std::vector<std::string> mapEngineNames() {
  return host::map::MapEngineRegistry::instance().names();
}

}  // namespace fvp::apps
