// fvp::robot::sim::WorldConfig::fromYamlFile (robot/sim/src/world_config.cpp) on a file holding the
// input (fvp::fuzz::fuzzConfigReader: what counts as a finding).
#include "config_checks.h"
#include "fvp/robot/sim/world_config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fvp::fuzz::fuzzConfigReader<fvp::robot::sim::WorldConfig>(data, size, "world_config.yaml");
  return 0;
}
