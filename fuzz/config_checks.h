// Checks the config harnesses make on a config the reader accepted (fuzz_support.h).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

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

}  // namespace fvp::fuzz
