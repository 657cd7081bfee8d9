// Descriptor of the ray-traversal kernel (kernels/ray_traverse.cl, shaders/ray_traverse.comp).
#include <stdexcept>

#include "fvp/accel/kernels.h"
#include "kernel_code.h"

FVP_KERNEL_CODE(ray_traverse)

namespace fvp::accel::kernels {
namespace {

using detail::paramsOf;

std::size_t rayCount(const void* p) {
  return paramsOf<TraverseParams>(p).ray_count;
}
std::size_t gridVoxels(const void* p) {
  return static_cast<std::size_t>(voxelCount(paramsOf<TraverseParams>(p).grid));
}

void validate(const void* p) {
  if (voxelCount(paramsOf<TraverseParams>(p).grid) >= (std::int64_t{1} << 31))
    throw std::invalid_argument("ray_traverse: dense grids hold fewer than 2^31 voxels");
}

void cpuLoop(const void* p, void* const* buffers, std::uint32_t count) {
  const auto& params = paramsOf<TraverseParams>(p);
  const auto* rays = static_cast<const Ray*>(buffers[0]);
  const auto* occupancy = static_cast<const float*>(buffers[1]);
  const auto* field = static_cast<const float*>(buffers[2]);
  auto* results = static_cast<RayResult*>(buffers[3]);
  // Rays differ a lot in length: small dynamic chunks balance the threads.
#pragma omp parallel for schedule(dynamic, 64)
  for (std::int64_t i = 0; i < count; ++i)
    results[i] = fvp_traverse_ray(&params.grid, params.occupied_threshold, rays[i].origin_m,
                                  rays[i].end_m, occupancy, field);
}

constexpr KernelBinding kBindings[] = {
    {"rays", sizeof(Ray), Access::kRead, rayCount},
    {"occupancy", sizeof(float), Access::kRead, gridVoxels},
    {"field", sizeof(float), Access::kRead, gridVoxels},
    {"results", sizeof(RayResult), Access::kWrite, rayCount},
};

const KernelDescriptor kDescriptor{
    "ray_traverse",
    sizeof(TraverseParams),
    kBindings,
    [](const void* p) { return paramsOf<TraverseParams>(p).ray_count; },
    validate,
    cpuLoop,
    FVP_OPENCL_CODE(ray_traverse, "fvp_ray_traverse"),
    FVP_SPIRV_CODE(ray_traverse)};

}  // namespace

Kernel<TraverseParams> rayTraverse() {
  return {&kDescriptor};
}

}  // namespace fvp::accel::kernels
