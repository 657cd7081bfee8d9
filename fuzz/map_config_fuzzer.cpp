// fvp::host::map::MapConfig::fromYamlFile (host/src/map/map_config.cpp) on a file holding the input
// (fvp::fuzz::fuzzConfigReader: what counts as a finding).
#include "config_checks.h"
#include "fvp/host/map/map_config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fvp::fuzz::fuzzConfigReader<fvp::host::map::MapConfig>(data, size, "map_config.yaml");
  return 0;
}
