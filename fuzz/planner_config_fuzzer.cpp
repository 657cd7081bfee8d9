// fvp::host::planner::PlannerConfig::fromYamlFile (host/src/planner/planner_config.cpp) on a file
// holding the input (fvp::fuzz::fuzzConfigReader: what counts as a finding).
#include "config_checks.h"
#include "fvp/host/planner/planner_config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fvp::fuzz::fuzzConfigReader<fvp::host::planner::PlannerConfig>(data, size, "planner_config.yaml");
  return 0;
}
