// The registries' names for the parse-only command-line harness, which links no registry: the
// built-in entries (a planner added later is parsed as an unknown name here, which the
// harness's inputs exercise anyway).
#include "commands.h"

namespace fvp::apps {

std::vector<std::string> plannerNames() {
  return {"fvp", "rvp"};
}

std::vector<std::string> mapEngineNames() {
  return {"grid", "octomap"};
}

}  // namespace fvp::apps
