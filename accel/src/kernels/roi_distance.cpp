// Descriptor of the ROI distance-field pass (kernels/roi_distance.cl, shaders/roi_distance.comp).
#include <stdexcept>

#include "fvp/accel/kernels.h"
#include "kernel_code.h"

FVP_KERNEL_CODE(roi_distance)

namespace fvp::accel::kernels {
namespace {

using detail::paramsOf;

// One work item per line of a brick along the pass's axis (fvp_roi_distance_line).
constexpr std::uint32_t kLinesPerBrick = FVP_BRICK_LINES;
static_assert(kLinesPerBrick * kBrickEdge == kBrickVoxels);

const EdtParams& edt(const void* p) {
  return paramsOf<EdtParams>(p);
}
std::size_t slots(const void* p) {
  return edt(p).slot_count;
}

void validate(const void* p) {
  const EdtParams& params = edt(p);
  checkBrickedGrid(params.map, "roi_distance");
  checkSlotCount(params.slot_count, "roi_distance");
  if (params.axis < 0 || params.axis > 2)
    throw std::invalid_argument("roi_distance: axis must be 0, 1 or 2");
  if (std::uint64_t{params.work_brick_count} * kBrickVoxels > params.slot_count)
    throw std::invalid_argument("roi_distance: work_brick_count exceeds the allocated bricks");
  if (params.radius_vox < 1 || params.radius_vox > 1000)
    throw std::invalid_argument("roi_distance: radius_vox must be in [1, 1000]");
}

void cpuLoop(const void* p, void* const* buffers, std::uint32_t count) {
  const EdtParams& params = edt(p);
  const auto* coords = static_cast<const int*>(buffers[0]);
  const auto* table = static_cast<const int*>(buffers[1]);
  const auto* roi = static_cast<const float*>(buffers[2]);
  const auto* sq_in = static_cast<const unsigned int*>(buffers[3]);
  auto* sq_out = static_cast<unsigned int*>(buffers[4]);
  auto* distance = static_cast<float*>(buffers[5]);
  const auto* work_bricks = static_cast<const std::uint32_t*>(buffers[6]);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < count; ++i)
    fvp_roi_distance_line(&params, static_cast<unsigned>(i), coords, table, roi, sq_in, sq_out,
                          distance, work_bricks);
}

constexpr KernelBinding kBindings[] = {
    {"brick_coords", sizeof(int), Access::kRead,
     [](const void* p) { return slots(p) / kBrickVoxels * 3; }},
    {"brick_table", sizeof(int), Access::kRead,
     [](const void* p) { return brickCount(edt(p).map); }},
    {"roi", sizeof(float), Access::kRead,
     [](const void* p) { return edt(p).axis == 0 ? slots(p) : 0; }},
    {"sq_in", sizeof(std::uint32_t), Access::kRead,
     [](const void* p) { return edt(p).axis > 0 ? slots(p) : 0; }},
    {"sq_out", sizeof(std::uint32_t), Access::kWrite,
     [](const void* p) { return edt(p).axis < 2 ? slots(p) : 0; }},
    {"distance_vox", sizeof(float), Access::kWrite,
     [](const void* p) { return edt(p).axis == 2 ? slots(p) : 0; }},
    {"work_bricks", sizeof(std::uint32_t), Access::kRead,
     [](const void* p) { return std::size_t{edt(p).work_brick_count}; }},
};

const KernelDescriptor kDescriptor{
    "roi_distance",
    sizeof(EdtParams),
    kBindings,
    [](const void* p) { return edt(p).work_brick_count * kLinesPerBrick; },
    validate,
    cpuLoop,
    FVP_OPENCL_CODE(roi_distance, "fvp_roi_distance"),
    FVP_SPIRV_CODE(roi_distance)};

}  // namespace

Kernel<EdtParams> roiDistance() {
  return {&kDescriptor};
}

}  // namespace fvp::accel::kernels
