// A compute kernel as data (the model is Kompute's Algorithm + OpAlgoDispatch): its name,
// buffer bindings with element types, parameter block, the CPU reference loop, the OpenCL
// source and the SPIR-V. Every backend dispatches any descriptor through one generic path
// (Backend::run), which checks the buffers against the bindings in one place.
//
// The contract a kernel's three implementations share:
// - parameters: one plain struct from kernels/*.h (the OpenCL kernel's first argument, the
//   GLSL block declared with FVP_KERNEL_PARAMS in shaders/fvp_kernel.glsl);
// - then the work-item count (OpenCL: second argument; GLSL: FVP_ITEM_COUNT);
// - then the buffers, in binding order (OpenCL: arguments 2.., whose names the OpenCL
//   backend checks against the binding names; GLSL: set 0, bindings 0..).
// Adding a kernel: docs/kernels.md, "Adding a kernel".
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace fvp::accel {

enum class Access { kRead, kWrite, kReadWrite };

struct KernelBinding {
  std::string_view name;      ///< the OpenCL argument's and the GLSL buffer array's name
  std::size_t element_bytes;  ///< sizeof the element type
  Access access;
  /// Elements the buffer must hold for these parameters; 0 when this dispatch does not use
  /// the binding (the caller may then pass nullptr).
  std::size_t (*required_elements)(const void* params);
};

struct SpirvCode {
  const std::uint32_t* words = nullptr;
  std::size_t bytes = 0;
};

struct KernelDescriptor {
  std::string_view name;  ///< e.g. "scan_mark"; also the .cl / .comp file's name
  std::size_t params_bytes;
  std::span<const KernelBinding> bindings;
  /// Work items of a dispatch with these parameters.
  std::uint32_t (*item_count)(const void* params);
  /// Throws std::invalid_argument for parameters no backend may run; may be null.
  void (*validate)(const void* params);
  /// The CPU reference: runs work items [0, item_count) over host memory (buffers in
  /// binding order; nullptr where a binding is unused).
  void (*cpu)(const void* params, void* const* buffers, std::uint32_t item_count);
  const char* opencl_source = nullptr;  ///< null when built without OpenCL
  const char* opencl_entry = nullptr;
  SpirvCode spirv_push_constants;  ///< parameters in push constants
  SpirvCode spirv_params_buffer;   ///< parameters in a storage buffer (set 1, binding 0)
};

/// A descriptor typed by its parameter struct, so Backend::run checks the type at compile time.
template <typename Params>
struct Kernel {
  const KernelDescriptor* descriptor;
};

/// Every kernel of the library (backends build them all up front, so a broken kernel
/// fails at backend creation).
std::span<const KernelDescriptor* const> allKernels();

}  // namespace fvp::accel
