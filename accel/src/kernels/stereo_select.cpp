// Descriptor of the winners of a stereo band and their left-right check (kernels/stereo_select.cl,
// shaders/stereo_select.comp; kernels/fvp_stereo.h).
#include <cstdint>

#include "fvp/accel/kernels.h"
#include "kernel_code.h"
#include "stereo_common.h"

FVP_KERNEL_CODE(stereo_select)

namespace fvp::accel::kernels {
namespace {

using namespace stereo;

void cpuLoop(const void* p, void* const* buffers, std::uint32_t count) {
  const StereoParams& params = sp(p);
  const auto* windows = static_cast<const unsigned int*>(buffers[0]);
  const auto* sums = static_cast<const unsigned int*>(buffers[1]);
  auto* right_best = static_cast<unsigned int*>(buffers[2]);
  auto* disparity = static_cast<int*>(buffers[3]);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < count; ++i)
    fvp_stereo_select_row(&params, windows, sums, static_cast<unsigned>(i), right_best, disparity);
}

constexpr KernelBinding kBindings[] = {
    {"windows", sizeof(std::uint32_t), Access::kRead, bandPixels},
    {"sums", sizeof(std::uint32_t), Access::kRead, sumWords},
    {"right_best", sizeof(std::uint32_t), Access::kWrite, rightBestWords},
    {"disparity", sizeof(std::int32_t), Access::kWrite, bandPixels},
};

const KernelDescriptor kDescriptor{
    "stereo_select",
    sizeof(StereoParams),
    kBindings,
    [](const void* p) { return static_cast<std::uint32_t>(sp(p).band_height_px); },
    [](const void* p) { stereo::validate(p, "stereo_select"); },
    cpuLoop,
    FVP_OPENCL_CODE(stereo_select, "fvp_stereo_select"),
    FVP_SPIRV_CODE(stereo_select)};

}  // namespace

Kernel<StereoParams> stereoSelect() {
  return {&kDescriptor};
}

}  // namespace fvp::accel::kernels
