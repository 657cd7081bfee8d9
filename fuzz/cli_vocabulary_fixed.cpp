// The registries' names for the parse-only command-line harness, which links no registry:
// the experiment files' copy (trials/experiment_directory.h), which fvp_experiment_test
// holds equal to the registries.
#include "commands.h"
#include "fvp/trials/experiment_directory.h"

namespace fvp::apps {

std::vector<std::string> plannerNames() {
  return trials::experimentPlanners();
}

std::vector<std::string> mapEngineNames() {
  return trials::experimentEngines();
}

}  // namespace fvp::apps
