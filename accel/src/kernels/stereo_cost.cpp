// Descriptor of the guided windows and census costs of a stereo band (kernels/stereo_cost.cl,
// shaders/stereo_cost.comp; kernels/fvp_stereo.h).
#include <cstdint>

#include "fvp/accel/kernels.h"
#include "kernel_code.h"
#include "stereo_common.h"

FVP_KERNEL_CODE(stereo_cost)

namespace fvp::accel::kernels {
namespace {

using namespace stereo;

void cpuLoop(const void* p, void* const* buffers, std::uint32_t count) {
  const StereoParams& params = sp(p);
  const auto* census = static_cast<const unsigned int*>(buffers[0]);
  const auto* coarse = static_cast<const int*>(buffers[1]);
  auto* windows = static_cast<unsigned int*>(buffers[2]);
  auto* costs = static_cast<unsigned int*>(buffers[3]);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < count; ++i)
    fvp_stereo_cost_pixel(&params, census, coarse, static_cast<unsigned>(i), windows, costs);
}

constexpr KernelBinding kBindings[] = {
    {"census", sizeof(std::uint32_t), Access::kRead, censusWords},
    {"coarse_disparity", sizeof(std::int32_t), Access::kRead, coarsePixels},
    {"windows", sizeof(std::uint32_t), Access::kWrite, bandPixels},
    {"costs", sizeof(std::uint32_t), Access::kWrite, costWords},
};

const KernelDescriptor kDescriptor{
    "stereo_cost",
    sizeof(StereoParams),
    kBindings,
    [](const void* p) { return static_cast<std::uint32_t>(bandPixels(p)); },
    [](const void* p) { stereo::validate(p, "stereo_cost"); },
    cpuLoop,
    FVP_OPENCL_CODE(stereo_cost, "fvp_stereo_cost"),
    FVP_SPIRV_CODE(stereo_cost)};

}  // namespace

Kernel<StereoParams> stereoCost() {
  return {&kDescriptor};
}

}  // namespace fvp::accel::kernels
