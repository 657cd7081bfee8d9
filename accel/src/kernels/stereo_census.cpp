// Descriptor of census signatures of a stereo pair's band rows (kernels/stereo_census.cl,
// shaders/stereo_census.comp; kernels/fvp_stereo.h).
#include <cstdint>

#include "fvp/accel/kernels.h"
#include "kernel_code.h"
#include "stereo_common.h"

FVP_KERNEL_CODE(stereo_census)

namespace fvp::accel::kernels {
namespace {

using namespace stereo;

void cpuLoop(const void* p, void* const* buffers, std::uint32_t count) {
  const StereoParams& params = sp(p);
  const auto* grey = static_cast<const unsigned int*>(buffers[0]);
  auto* census = static_cast<unsigned int*>(buffers[1]);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < count; ++i)
    fvp_stereo_census_pixel(&params, grey, static_cast<unsigned>(i), census);
}

constexpr KernelBinding kBindings[] = {
    {"grey", sizeof(std::uint32_t), Access::kRead, greyWords},
    {"census", sizeof(std::uint32_t), Access::kWrite, censusWords},
};

const KernelDescriptor kDescriptor{
    "stereo_census",
    sizeof(StereoParams),
    kBindings,
    [](const void* p) { return static_cast<std::uint32_t>(censusPixels(p)); },
    [](const void* p) { stereo::validate(p, "stereo_census"); },
    cpuLoop,
    FVP_OPENCL_CODE(stereo_census, "fvp_stereo_census"),
    FVP_SPIRV_CODE(stereo_census)};

}  // namespace

Kernel<StereoParams> stereoCensus() {
  return {&kDescriptor};
}

}  // namespace fvp::accel::kernels
