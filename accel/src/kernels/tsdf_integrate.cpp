// Descriptor of projective TSDF integration (kernels/tsdf_integrate.cl,
// shaders/tsdf_integrate.comp).
#include <cstdint>
#include <stdexcept>

#include "fvp/accel/kernels.h"
#include "kernel_code.h"

FVP_KERNEL_CODE(tsdf_integrate)

namespace fvp::accel::kernels {
namespace {

using detail::paramsOf;

const TsdfParams& tp(const void* p) {
  return paramsOf<TsdfParams>(p);
}
std::size_t items(const void* p) {
  return std::size_t{tp(p).update_bricks} * kBrickVoxels;
}
std::uint32_t itemCount(const void* p) {
  return static_cast<std::uint32_t>(items(p));
}
std::size_t slots(const void* p) {
  return std::size_t{tp(p).allocated_bricks} * kBrickVoxels;
}

void validate(const void* p) {
  const TsdfParams& t = tp(p);
  // Items and slots are 32-bit indices on every backend.
  if (t.allocated_bricks >= (1u << 22))
    throw std::invalid_argument("tsdf_integrate: at most 2^22 - 1 bricks");
  if (t.update_bricks > t.allocated_bricks)
    throw std::invalid_argument("tsdf_integrate: more bricks to update than allocated");
  if (t.width_px <= 0 || t.height_px <= 0)
    throw std::invalid_argument("tsdf_integrate: the depth image must not be empty");
  if (!(t.voxel_size_m > 0.0f) || !(t.truncation_m > t.voxel_size_m) || !(t.max_weight > 0.0f))
    throw std::invalid_argument(
        "tsdf_integrate: expected voxel_size_m > 0, truncation_m > voxel_size_m, "
        "max_weight > 0");
}

void cpuLoop(const void* p, void* const* buffers, std::uint32_t count) {
  const TsdfParams& params = tp(p);
  const auto* coords = static_cast<const int*>(buffers[0]);
  const auto* update = static_cast<const unsigned int*>(buffers[1]);
  const auto* depth = static_cast<const float*>(buffers[2]);
  auto* distance = static_cast<float*>(buffers[3]);
  auto* weight = static_cast<float*>(buffers[4]);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < count; ++i)
    fvp_tsdf_update_voxel(&params, coords, update, static_cast<unsigned>(i), depth, distance,
                          weight);
}

constexpr KernelBinding kBindings[] = {
    {"brick_coords", sizeof(int), Access::kRead,
     [](const void* p) { return std::size_t{tp(p).allocated_bricks} * 3; }},
    {"update_bricks", sizeof(std::uint32_t), Access::kRead,
     [](const void* p) -> std::size_t { return tp(p).update_bricks; }},
    {"depth_m", sizeof(float), Access::kRead,
     [](const void* p) { return std::size_t(tp(p).width_px) * std::size_t(tp(p).height_px); }},
    {"tsdf_distance", sizeof(float), Access::kReadWrite, slots},
    {"tsdf_weight", sizeof(float), Access::kReadWrite, slots},
};

const KernelDescriptor kDescriptor{"tsdf_integrate",
                                   sizeof(TsdfParams),
                                   kBindings,
                                   itemCount,
                                   validate,
                                   cpuLoop,
                                   FVP_OPENCL_CODE(tsdf_integrate, "fvp_tsdf_integrate"),
                                   FVP_SPIRV_CODE(tsdf_integrate)};

}  // namespace

Kernel<TsdfParams> tsdfIntegrate() {
  return {&kDescriptor};
}

}  // namespace fvp::accel::kernels
