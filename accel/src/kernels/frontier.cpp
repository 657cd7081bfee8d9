// Descriptor of frontier extraction (kernels/frontier.cl, shaders/frontier.comp).
#include <stdexcept>

#include "fvp/accel/kernels.h"
#include "kernel_code.h"

FVP_KERNEL_CODE(frontier)

namespace fvp::accel::kernels {
namespace {

using detail::paramsOf;

const FrontierParams& fp(const void* p) {
  return paramsOf<FrontierParams>(p);
}
std::size_t slots(const void* p) {
  return fp(p).slot_count;
}

void validate(const void* p) {
  checkBrickedGrid(fp(p).map, "frontier");
  checkSlotCount(fp(p).slot_count, "frontier");
}

void cpuLoop(const void* p, void* const* buffers, std::uint32_t count) {
  const FrontierParams& params = fp(p);
  const auto* coords = static_cast<const int*>(buffers[0]);
  const auto* table = static_cast<const int*>(buffers[1]);
  const auto* occupancy = static_cast<const float*>(buffers[2]);
  const auto* roi = static_cast<const float*>(buffers[3]);
  auto* frontiers = static_cast<Frontier*>(buffers[4]);
  auto* found = static_cast<unsigned int*>(buffers[5]);
#pragma omp parallel for schedule(static)
  for (std::int64_t s = 0; s < count; ++s) {
    int x, y, z;
    fvp_slot_voxel(coords, static_cast<unsigned>(s), &x, &y, &z);
    fvp_frontier_append(&params, x, y, z, table, occupancy, roi, frontiers, found);
  }
}

constexpr KernelBinding kBindings[] = {
    {"brick_coords", sizeof(int), Access::kRead,
     [](const void* p) { return slots(p) / kBrickVoxels * 3; }},
    {"brick_table", sizeof(int), Access::kRead,
     [](const void* p) { return brickCount(fp(p).map); }},
    {"occupancy", sizeof(float), Access::kRead, slots},
    {"roi", sizeof(float), Access::kRead, slots},
    {"frontiers", sizeof(Frontier), Access::kWrite,
     [](const void* p) -> std::size_t { return fp(p).capacity; }},
    {"count", sizeof(std::uint32_t), Access::kReadWrite,
     [](const void*) -> std::size_t { return 1; }},
};

const KernelDescriptor kDescriptor{"frontier",
                                   sizeof(FrontierParams),
                                   kBindings,
                                   [](const void* p) { return fp(p).slot_count; },
                                   validate,
                                   cpuLoop,
                                   FVP_OPENCL_CODE(frontier, "fvp_extract_frontiers"),
                                   FVP_SPIRV_CODE(frontier)};

}  // namespace

Kernel<FrontierParams> frontier() {
  return {&kDescriptor};
}

}  // namespace fvp::accel::kernels
