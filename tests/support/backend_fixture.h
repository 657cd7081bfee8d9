// The fixture of every cross-backend test: one instance per compute backend (cpu, opencl,
// vulkan), each with that backend and a cpu reference. An unavailable backend skips the
// test, or fails it where every backend is required (CI=true, FVP_REQUIRE_ALL_BACKENDS=1).
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "backend_test_support.h"
#include "fvp/accel/backend.h"

namespace fvp::testing {

class BackendFixture : public ::testing::TestWithParam<accel::BackendKind> {
 protected:
  void SetUp() override {
    try {
      backend_ = accel::createBackend(GetParam());
    } catch (const accel::BackendUnavailable& e) {
      if (allBackendsRequired()) FAIL() << "required backend unavailable: " << e.what();
      GTEST_SKIP() << e.what();
    }
    cpu_ = accel::createBackend(accel::BackendKind::kCpu);
  }

  std::unique_ptr<accel::Backend> backend_;  ///< the backend under test
  std::unique_ptr<accel::Backend> cpu_;      ///< the reference
};

/// Test names end in the backend's name (".../opencl").
inline std::string backendParamName(const ::testing::TestParamInfo<accel::BackendKind>& info) {
  return std::string(accel::toString(info.param));
}

}  // namespace fvp::testing

/// Instantiates a BackendFixture suite once per backend.
#define FVP_INSTANTIATE_FOR_ALL_BACKENDS(Suite)                                              \
  INSTANTIATE_TEST_SUITE_P(                                                                  \
      AllBackends, Suite,                                                                    \
      ::testing::Values(::fvp::accel::BackendKind::kCpu, ::fvp::accel::BackendKind::kOpenCl, \
                        ::fvp::accel::BackendKind::kVulkan),                                 \
      ::fvp::testing::backendParamName)
