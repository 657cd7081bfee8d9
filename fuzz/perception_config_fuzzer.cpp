// fvp::host::PerceptionConfig::fromYamlFile (host/src/perception/perception_config.cpp) on a file
// holding the input (fvp::fuzz::fuzzConfigReader: what counts as a finding).
#include "config_checks.h"
#include "fvp/host/perception/perception_pipeline.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fvp::fuzz::fuzzConfigReader<fvp::host::PerceptionConfig>(data, size, "perception_config.yaml");
  return 0;
}
