// Descriptor of one family of SGM's paths over a stereo band (kernels/stereo_aggregate.cl,
// shaders/stereo_aggregate.comp; kernels/fvp_stereo.h).
#include <cstdint>

#include "fvp/accel/kernels.h"
#include "kernel_code.h"
#include "stereo_common.h"

FVP_KERNEL_CODE(stereo_aggregate)

namespace fvp::accel::kernels {
namespace {

using namespace stereo;

void cpuLoop(const void* p, void* const* buffers, std::uint32_t count) {
  const StereoParams& params = sp(p);
  const auto* windows = static_cast<const unsigned int*>(buffers[0]);
  const auto* costs = static_cast<const unsigned int*>(buffers[1]);
  auto* sums = static_cast<unsigned int*>(buffers[2]);
#pragma omp parallel for schedule(dynamic, 16)
  for (std::int64_t i = 0; i < count; ++i)
    fvp_stereo_aggregate_line(&params, windows, costs, static_cast<unsigned>(i), sums);
}

constexpr KernelBinding kBindings[] = {
    {"windows", sizeof(std::uint32_t), Access::kRead, bandPixels},
    {"costs", sizeof(std::uint32_t), Access::kRead, costWords},
    {"sums", sizeof(std::uint32_t), Access::kReadWrite, sumWords},
};

const KernelDescriptor kDescriptor{"stereo_aggregate",
                                   sizeof(StereoParams),
                                   kBindings,
                                   [](const void* p) { return fvp_stereo_line_count(&sp(p)); },
                                   [](const void* p) { stereo::validate(p, "stereo_aggregate"); },
                                   cpuLoop,
                                   FVP_OPENCL_CODE(stereo_aggregate, "fvp_stereo_aggregate"),
                                   FVP_SPIRV_CODE(stereo_aggregate)};

}  // namespace

Kernel<StereoParams> stereoAggregate() {
  return {&kDescriptor};
}

}  // namespace fvp::accel::kernels
