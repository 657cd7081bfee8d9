// The embedded code of one kernel, for its descriptor: FVP_KERNEL_CODE(name) declares the
// OpenCL source (kernels/<name>.cl) and both SPIR-V variants (shaders/<name>.comp) that the
// build generates, FVP_OPENCL_CODE / FVP_SPIRV_CODE fill the descriptor's fields (null where
// the backend is not built).
#pragma once

#include <cstddef>
#include <cstdint>

#include "fvp/accel/kernel.h"

#ifdef FVP_WITH_OPENCL
#define FVP_DECLARE_OPENCL_CODE(name) extern const char kOpenClSource_##name[];
#define FVP_OPENCL_CODE(name, entry) kOpenClSource_##name, entry
#else
#define FVP_DECLARE_OPENCL_CODE(name)
#define FVP_OPENCL_CODE(name, entry) nullptr, nullptr
#endif

#ifdef FVP_WITH_VULKAN
#define FVP_DECLARE_SPIRV_CODE(name)                                    \
  extern const std::uint32_t* const kSpirvWords_##name;                 \
  extern const std::size_t kSpirvBytes_##name;                          \
  extern const std::uint32_t* const kSpirvWords_##name##_params_buffer; \
  extern const std::size_t kSpirvBytes_##name##_params_buffer;
#define FVP_SPIRV_CODE(name)                                                                 \
  ::fvp::accel::SpirvCode{kSpirvWords_##name, kSpirvBytes_##name}, ::fvp::accel::SpirvCode { \
    kSpirvWords_##name##_params_buffer, kSpirvBytes_##name##_params_buffer                   \
  }
#else
#define FVP_DECLARE_SPIRV_CODE(name)
#define FVP_SPIRV_CODE(name) \
  ::fvp::accel::SpirvCode{}, ::fvp::accel::SpirvCode {}
#endif

/// At global scope: declares what the build generates for kernel `name`.
#define FVP_KERNEL_CODE(name)   \
  FVP_DECLARE_OPENCL_CODE(name) \
  FVP_DECLARE_SPIRV_CODE(name)

namespace fvp::accel::detail {

/// Typed view of the parameter block (descriptors' function pointers take void*).
template <typename Params>
const Params& paramsOf(const void* params) {
  return *static_cast<const Params*>(params);
}

}  // namespace fvp::accel::detail
