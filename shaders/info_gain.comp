#version 450
// Information gain of ray segments over the planner's map snapshot: entry point of
// kernels/info_gain.cl's twin; the body fvp_gain_walk is in fvp_info_gain.glsl.
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_kernel.glsl"
#include "fvp_dda.glsl"
#include "fvp_info_gain.glsl"

FVP_KERNEL_PARAMS(FvpGainParams)
layout(std430, set = 0, binding = 0) readonly buffer Segments { FvpGainSegment segments[]; };
layout(std430, set = 0, binding = 1) readonly buffer FineCodes { uint fine_codes[]; };
layout(std430, set = 0, binding = 2) readonly buffer CoarseOccupied { uint coarse_occupied[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Results { FvpGainResult results[]; };
#define FVP_HAS_FINE_CODES
#define FVP_HAS_COARSE_OCCUPIED
#include "fvp_info_gain.glsl"

void main() {
  uint i = FVP_ITEM_INDEX;
  if (i >= FVP_ITEM_COUNT) return;
  FvpGainSegment s = segments[i];
  results[i] = fvp_gain_walk(fvp_params.p, s.origin_m.xyz, s.entry_m.xyz, s.end_m.xyz,
                             s.origin_m.w != 0.0);
}
