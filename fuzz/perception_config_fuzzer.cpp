// fvp::host::PerceptionConfig::fromYamlFile (host/src/perception/perception_config.cpp) on a file
// holding the input. A config it accepts must pass validate() (what a config built in code must
// pass).
#include <yaml-cpp/yaml.h>

#include <nlohmann/json.hpp>
#include <optional>

#include "config_checks.h"
#include "fuzz_support.h"
#include "fvp/host/perception/perception_pipeline.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fz = fvp::fuzz;
  const std::filesystem::path path = fz::scratchDir() / "perception_config.yaml";
  fz::writeFile(path, data, size);
  std::optional<fvp::host::PerceptionConfig> config;
  try {
    config = fvp::host::PerceptionConfig::fromYamlFile(path);
  } catch (const YAML::Exception& e) {
    fz::reportEscapedException("yaml-cpp", e);
  } catch (const nlohmann::json::exception& e) {
    fz::reportEscapedException("nlohmann_json", e);
  } catch (const std::exception&) {
    // Rejected: expected for most inputs.
  }
  if (config) {
    try {
      config->validate();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "fvp fuzz: an accepted config fails validate(): %s\n", e.what());
      std::abort();
    }
  }
  return 0;
}
