// Descriptor of the scan mark pass (kernels/scan_mark.cl, shaders/scan_mark.comp).
#include <stdexcept>
#include <string>

#include "fvp/accel/kernels.h"
#include "kernel_code.h"

FVP_KERNEL_CODE(scan_mark)

namespace fvp::accel::kernels {
namespace {

using detail::paramsOf;

void validate(const void* p) {
  const auto& params = paramsOf<ScanParams>(p);
  checkBrickedGrid(params.map, "scan_mark");
  checkSlotCount(params.slot_count, "scan_mark");
  if (params.brick_count < 0 ||
      static_cast<std::size_t>(params.brick_count) != brickCount(params.map))
    throw std::invalid_argument("scan_mark: brick_count differs from the grid's brick dims");
}

void cpuLoop(const void* p, void* const* buffers, std::uint32_t count) {
  const auto& params = paramsOf<ScanParams>(p);
  const auto* points = static_cast<const ScanPoint*>(buffers[0]);
  const auto* table = static_cast<const int*>(buffers[1]);
  auto* marks = static_cast<unsigned int*>(buffers[2]);
  auto* missing = static_cast<unsigned int*>(buffers[3]);
#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t i = 0; i < count; ++i)
    fvp_scan_mark_point(&params, points[i], table, marks, missing);
}

constexpr KernelBinding kBindings[] = {
    {"points", sizeof(ScanPoint), Access::kRead,
     [](const void* p) -> std::size_t { return paramsOf<ScanParams>(p).point_count; }},
    {"brick_table", sizeof(int), Access::kRead,
     [](const void* p) { return brickCount(paramsOf<ScanParams>(p).map); }},
    {"marks", sizeof(std::uint32_t), Access::kReadWrite,
     [](const void* p) -> std::size_t { return paramsOf<ScanParams>(p).slot_count / 4; }},
    {"missing", sizeof(std::uint32_t), Access::kReadWrite,
     [](const void* p) { return brickCount(paramsOf<ScanParams>(p).map) + 1; }},
};

const KernelDescriptor kDescriptor{
    "scan_mark",
    sizeof(ScanParams),
    kBindings,
    [](const void* p) { return paramsOf<ScanParams>(p).point_count; },
    validate,
    cpuLoop,
    FVP_OPENCL_CODE(scan_mark, "fvp_scan_mark"),
    FVP_SPIRV_CODE(scan_mark)};

}  // namespace

Kernel<ScanParams> scanMark() {
  return {&kDescriptor};
}

}  // namespace fvp::accel::kernels
