// Checks the config harnesses make on a config the reader accepted (fuzz_support.h).
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <type_traits>

#include "fuzz_support.h"

namespace fvp::fuzz {

/// A config's toJson() with a null where a number was: JSON has no NaN or infinity, so a
/// non-finite field went through the reader's checks.
inline void requireFiniteJson(const std::string& json_text) {
  const nlohmann::json j = nlohmann::json::parse(json_text);
  for (const auto& [key, value] : j.items()) {
    bool finite = !value.is_null();
    if (value.is_array())
      for (const auto& x : value) finite = finite && !x.is_null();
    if (!finite) {
      std::fprintf(stderr, "fvp fuzz: accepted a non-finite %s: %s\n", key.c_str(),
                   json_text.c_str());
      std::abort();
    }
  }
}

/// One config harness: writes the input to <file_name> in the scratch directory and reads it
/// with Config::fromYamlFile. A rejection is any std::exception but the libraries' own (whose
/// messages name neither file nor key); an accepted config must pass validate() (what a config
/// built in code must pass) and, where it has toJson(), hold only finite numbers.
template <typename Config>
void fuzzConfigReader(const std::uint8_t* data, std::size_t size, const char* file_name) {
  const std::filesystem::path path = scratchDir() / file_name;
  writeFile(path, data, size);
  std::optional<Config> config;
  try {
    config = Config::fromYamlFile(path);
  } catch (const YAML::Exception& e) {
    reportEscapedException("yaml-cpp", e);
  } catch (const nlohmann::json::exception& e) {
    reportEscapedException("nlohmann_json", e);
  } catch (const std::exception&) {
    return;  // rejected: expected for most inputs
  }
  if (!config) return;
  try {
    config->validate();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fvp fuzz: an accepted config fails validate(): %s\n", e.what());
    std::abort();
  }
  if constexpr (requires(const Config& c) { c.toJson(); }) requireFiniteJson(config->toJson());
}

}  // namespace fvp::fuzz
