// fvp_kernel.glsl: the dispatch interface every compute shader shares (the GLSL side of
// accel/include/fvp/accel/kernel.h). Include first; then declare the parameter block with
// FVP_KERNEL_PARAMS(Type) and read it as fvp_params.p.
//
// Parameters travel in push constants when {first_item, item_count, params} fits the
// device's maxPushConstantsSize (128 bytes is all Vulkan guarantees), else in a read-only
// storage buffer at set 1, binding 0 (a std430 buffer keeps the C struct layout; a
// uniform block would impose std140's 16-byte struct alignment). The build compiles every
// shader both ways (FVP_PARAMS_IN_BUFFER defined or not); the backend picks per device.
// Kernel buffers are storage buffers at set 0, bindings 0.., in the descriptor's order.
#ifndef FVP_KERNEL_GLSL
#define FVP_KERNEL_GLSL

// Work-group size is chosen by the host from the device's limits (specialisation constant 0).
layout(local_size_x_id = 0) in;

#ifdef FVP_PARAMS_IN_BUFFER
layout(push_constant) uniform FvpDispatch {
  uint first_item;  // dispatches are chunked to stay within maxComputeWorkGroupCount
  uint item_count;
} fvp_dispatch;
#define FVP_KERNEL_PARAMS(Type) \
  layout(std430, set = 1, binding = 0) readonly buffer FvpParams { Type p; } fvp_params;
#define FVP_FIRST_ITEM fvp_dispatch.first_item
#define FVP_ITEM_COUNT fvp_dispatch.item_count
#else
#define FVP_KERNEL_PARAMS(Type)                                                            \
  layout(push_constant) uniform FvpParams { uint first_item; uint item_count; Type p; } \
      fvp_params;
#define FVP_FIRST_ITEM fvp_params.first_item
#define FVP_ITEM_COUNT fvp_params.item_count
#endif

// This invocation's work item.
#define FVP_ITEM_INDEX (FVP_FIRST_ITEM + gl_GlobalInvocationID.x)

#endif  // FVP_KERNEL_GLSL
