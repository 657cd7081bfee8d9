// Shared by the cross-backend tests: which backends must run, and fresh seeds.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>

namespace fvp::testing {

/// In CI (CI=true) or with FVP_REQUIRE_ALL_BACKENDS=1 an unavailable backend fails the test
/// instead of skipping it.
inline bool allBackendsRequired() {
  const char* ci = std::getenv("CI");
  const char* required = std::getenv("FVP_REQUIRE_ALL_BACKENDS");
  return (ci && std::string(ci) == "true") || (required && std::string(required) == "1");
}

/// A fresh random seed for property-style checks, or FVP_TEST_SEED to replay a failure.
inline std::uint64_t freshSeed() {
  if (const char* s = std::getenv("FVP_TEST_SEED")) return std::stoull(s);
  return std::random_device{}();
}

inline std::string replayHint(std::uint64_t seed) {
  return "seed " + std::to_string(seed) + " (rerun with FVP_TEST_SEED=" + std::to_string(seed) +
         ")";
}

}  // namespace fvp::testing
