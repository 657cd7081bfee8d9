// Descriptor of the information-gain kernel (kernels/info_gain.cl, shaders/info_gain.comp).
#include <stdexcept>

#include "fvp/accel/kernels.h"
#include "kernel_code.h"

FVP_KERNEL_CODE(info_gain)

namespace fvp::accel::kernels {
namespace {

using detail::paramsOf;

const GainParams& gp(const void* p) {
  return paramsOf<GainParams>(p);
}
std::size_t segments(const void* p) {
  return gp(p).segment_count;
}

void validate(const void* p) {
  for (const GridParams* g : {&gp(p).fine, &gp(p).coarse})
    if (voxelCount(*g) >= (std::int64_t{1} << 31))
      throw std::invalid_argument("info_gain: dense grids hold fewer than 2^31 voxels");
}

void cpuLoop(const void* p, void* const* buffers, std::uint32_t count) {
  const GainParams& params = gp(p);
  const auto* segs = static_cast<const GainSegment*>(buffers[0]);
  const auto* fine = static_cast<const std::uint32_t*>(buffers[1]);
  const auto* coarse = static_cast<const std::uint32_t*>(buffers[2]);
  auto* results = static_cast<GainResultRaw*>(buffers[3]);
  // Segments differ a lot in length: small dynamic chunks balance the threads.
#pragma omp parallel for schedule(dynamic, 64)
  for (std::int64_t i = 0; i < count; ++i)
    results[i] = fvp_gain_walk(&params, segs[i].origin_m, segs[i].entry_m, segs[i].end_m,
                               segs[i].origin_m[3] != 0.0f, fine, coarse);
}

constexpr KernelBinding kBindings[] = {
    {"segments", sizeof(GainSegment), Access::kRead, segments},
    {"fine_codes", sizeof(std::uint32_t), Access::kRead,
     [](const void* p) { return gainFineWords(gp(p).fine); }},
    {"coarse_occupied", sizeof(std::uint32_t), Access::kRead,
     [](const void* p) { return gainCoarseWords(gp(p).coarse); }},
    {"results", sizeof(GainResultRaw), Access::kWrite, segments},
};

const KernelDescriptor kDescriptor{"info_gain",
                                   sizeof(GainParams),
                                   kBindings,
                                   [](const void* p) { return gp(p).segment_count; },
                                   validate,
                                   cpuLoop,
                                   FVP_OPENCL_CODE(info_gain, "fvp_info_gain"),
                                   FVP_SPIRV_CODE(info_gain)};

}  // namespace

Kernel<GainParams> infoGain() {
  return {&kDescriptor};
}

}  // namespace fvp::accel::kernels
