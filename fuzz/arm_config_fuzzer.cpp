// fvp::robot::ArmConfig::fromYamlFile (robot/src/arm_config.cpp) on a file holding the input
// (fvp::fuzz::fuzzConfigReader: what counts as a finding).
#include "config_checks.h"
#include "fvp/robot/arm_config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fvp::fuzz::fuzzConfigReader<fvp::robot::ArmConfig>(data, size, "arm_config.yaml");
  return 0;
}
