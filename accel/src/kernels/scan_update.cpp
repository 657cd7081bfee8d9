// Descriptor of the scan update pass (kernels/scan_update.cl, shaders/scan_update.comp).
#include <stdexcept>

#include "fvp/accel/kernels.h"
#include "kernel_code.h"

FVP_KERNEL_CODE(scan_update)

namespace fvp::accel::kernels {
namespace {

using detail::paramsOf;

std::size_t slots(const void* p) {
  return paramsOf<UpdateParams>(p).slot_count;
}

void validate(const void* p) {
  checkSlotCount(paramsOf<UpdateParams>(p).slot_count, "scan_update");
}

void cpuLoop(const void* p, void* const* buffers, std::uint32_t count) {
  const auto& params = paramsOf<UpdateParams>(p);
  auto* marks = static_cast<unsigned int*>(buffers[0]);
  auto* occupancy = static_cast<float*>(buffers[1]);
  auto* roi = static_cast<float*>(buffers[2]);
  auto* updated = static_cast<unsigned int*>(buffers[3]);
  auto* changed_bricks = static_cast<unsigned int*>(buffers[4]);
#pragma omp parallel for schedule(static)
  for (std::int64_t c = 0; c < count; ++c)
    fvp_scan_update_item(&params, static_cast<unsigned>(c), marks, occupancy, roi, updated,
                         changed_bricks);
}

constexpr KernelBinding kBindings[] = {
    {"marks", sizeof(std::uint32_t), Access::kReadWrite,
     [](const void* p) { return slots(p) / 4; }},
    {"occupancy", sizeof(float), Access::kReadWrite, slots},
    {"roi", sizeof(float), Access::kReadWrite,
     [](const void* p) -> std::size_t { return paramsOf<UpdateParams>(p).has_roi ? slots(p) : 0; }},
    {"updated", sizeof(std::uint32_t), Access::kReadWrite,
     [](const void*) -> std::size_t { return 1; }},
    {"changed_bricks", sizeof(std::uint32_t), Access::kReadWrite,
     [](const void* p) { return slots(p) / kBrickVoxels; }},
};

const KernelDescriptor kDescriptor{
    "scan_update",
    sizeof(UpdateParams),
    kBindings,
    [](const void* p) { return paramsOf<UpdateParams>(p).slot_count / FVP_UPDATE_CHUNK; },
    validate,
    cpuLoop,
    FVP_OPENCL_CODE(scan_update, "fvp_scan_update"),
    FVP_SPIRV_CODE(scan_update)};

}  // namespace

Kernel<UpdateParams> scanUpdate() {
  return {&kDescriptor};
}

}  // namespace fvp::accel::kernels
