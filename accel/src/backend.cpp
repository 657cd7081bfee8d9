#include "fvp/accel/backend.h"

#include <cmath>
#include <sstream>

#include "backends.h"

namespace fvp::accel {

std::string_view toString(BackendKind kind) {
  switch (kind) {
    case BackendKind::kCpu: return "cpu";
    case BackendKind::kOpenCl: return "opencl";
    case BackendKind::kVulkan: return "vulkan";
  }
  return "unknown";
}

std::optional<BackendKind> parseBackendKind(std::string_view name) {
  if (name == "cpu") return BackendKind::kCpu;
  if (name == "opencl") return BackendKind::kOpenCl;
  if (name == "vulkan") return BackendKind::kVulkan;
  return std::nullopt;
}

GridParams makeGridParams(std::array<int, 3> dims, std::array<float, 3> origin_m,
                          float voxel_size_m) {
  for (int d : dims)
    if (d <= 0) throw std::invalid_argument("grid dimensions must be positive");
  if (!(voxel_size_m > 0.0f) || !std::isfinite(voxel_size_m))
    throw std::invalid_argument("voxel_size_m must be a positive finite number");
  for (int d : dims)
    if (d > 16384) throw std::invalid_argument("grids hold at most 16384 voxels per axis");
  GridParams g{};
  g.dim_x = dims[0];
  g.dim_y = dims[1];
  g.dim_z = dims[2];
  g.origin_x_m = origin_m[0];
  g.origin_y_m = origin_m[1];
  g.origin_z_m = origin_m[2];
  g.voxel_size_m = voxel_size_m;
  g.fixed_per_m = static_cast<float>(static_cast<double>(FVP_DDA_ONE) / voxel_size_m);
  return g;
}

namespace {
void checkRange(const DeviceBuffer& buf, std::size_t size_bytes, std::size_t offset_bytes,
                const char* what) {
  if (offset_bytes > buf.sizeBytes() || size_bytes > buf.sizeBytes() - offset_bytes) {
    std::ostringstream msg;
    msg << what << ": range [" << offset_bytes << ", " << offset_bytes + size_bytes
        << ") lies outside a buffer of " << buf.sizeBytes() << " bytes";
    throw std::out_of_range(msg.str());
  }
}
}  // namespace

void Backend::upload(DeviceBuffer& buf, const void* src, std::size_t size_bytes,
                     std::size_t offset_bytes) {
  checkRange(buf, size_bytes, offset_bytes, "upload");
  if (size_bytes) uploadBytes(buf, src, size_bytes, offset_bytes);
}

void Backend::download(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                       std::size_t offset_bytes) {
  checkRange(buf, size_bytes, offset_bytes, "download");
  if (size_bytes) downloadBytes(buf, dst, size_bytes, offset_bytes);
}

void Backend::traverseRays(const TraverseParams& params, const DeviceBuffer& rays,
                           const DeviceBuffer& occupancy, const DeviceBuffer& field,
                           DeviceBuffer& results) {
  const std::size_t n = params.ray_count;
  const auto voxels = static_cast<std::size_t>(voxelCount(params.grid));
  if (voxelCount(params.grid) >= (std::int64_t{1} << 31))
    throw std::invalid_argument("traverseRays: dense grids hold fewer than 2^31 voxels");
  checkRange(rays, n * sizeof(Ray), 0, "traverseRays: rays");
  checkRange(occupancy, voxels * sizeof(float), 0, "traverseRays: occupancy");
  checkRange(field, voxels * sizeof(float), 0, "traverseRays: field");
  checkRange(results, n * sizeof(RayResult), 0, "traverseRays: results");
  if (n) dispatchTraverseRays(params, rays, occupancy, field, results);
}

namespace {
std::size_t brickCount(const BrickedGridParams& m) {
  return static_cast<std::size_t>(m.bricks_x) * m.bricks_y * m.bricks_z;
}
void checkBrickedGrid(const BrickedGridParams& m, const char* what) {
  if (m.grid.dim_x != m.bricks_x * kBrickEdge || m.grid.dim_y != m.bricks_y * kBrickEdge ||
      m.grid.dim_z != m.bricks_z * kBrickEdge)
    throw std::invalid_argument(std::string(what) + ": grid dims must be 8 x the brick dims");
}
void checkSlots(std::uint32_t slot_count, const char* what) {
  if (slot_count % kBrickVoxels != 0)
    throw std::invalid_argument(std::string(what) + ": slot_count must be a multiple of 512");
}
// The checks every per-slot kernel over bricked storage shares.
void checkSlotKernel(const BrickedGridParams& m, std::uint32_t slot_count,
                     const DeviceBuffer& brick_coords, const DeviceBuffer& brick_table,
                     const std::string& what) {
  checkBrickedGrid(m, what.c_str());
  checkSlots(slot_count, what.c_str());
  checkRange(brick_coords, std::size_t{slot_count} / kBrickVoxels * 3 * sizeof(int), 0,
             (what + ": brick_coords").c_str());
  checkRange(brick_table, brickCount(m) * sizeof(int), 0, (what + ": brick_table").c_str());
}
}  // namespace

void Backend::scanMark(const ScanParams& params, const DeviceBuffer& points,
                       const DeviceBuffer& brick_table, DeviceBuffer& marks, DeviceBuffer& missing,
                       std::uint32_t slot_count, std::uint32_t brick_count) {
  checkBrickedGrid(params.map, "scanMark");
  checkSlots(slot_count, "scanMark");
  if (brick_count != brickCount(params.map))
    throw std::invalid_argument("scanMark: brick_count differs from the grid's brick dims");
  checkRange(points, std::size_t{params.point_count} * sizeof(ScanPoint), 0, "scanMark: points");
  checkRange(brick_table, brickCount(params.map) * sizeof(int), 0, "scanMark: brick_table");
  checkRange(marks, scanMarkBytes(slot_count), 0, "scanMark: marks");
  checkRange(missing, (brickCount(params.map) + 1) * sizeof(std::uint32_t), 0, "scanMark: missing");
  if (params.point_count)
    dispatchScanMark(params, points, brick_table, marks, missing, slot_count, brick_count);
}

void Backend::scanUpdate(const UpdateParams& params, DeviceBuffer& marks, DeviceBuffer& occupancy,
                         DeviceBuffer& roi, DeviceBuffer& updated) {
  checkSlots(params.slot_count, "scanUpdate");
  checkRange(marks, scanMarkBytes(params.slot_count), 0, "scanUpdate: marks");
  checkRange(occupancy, std::size_t{params.slot_count} * sizeof(float), 0, "scanUpdate: occupancy");
  if (params.has_roi)
    checkRange(roi, std::size_t{params.slot_count} * sizeof(float), 0, "scanUpdate: roi");
  checkRange(updated, sizeof(std::uint32_t), 0, "scanUpdate: updated");
  if (params.slot_count) dispatchScanUpdate(params, marks, occupancy, roi, updated);
}

void Backend::roiDistancePass(const EdtParams& params, int axis, const DeviceBuffer& brick_coords,
                              const DeviceBuffer& brick_table, const DeviceBuffer& roi,
                              const DeviceBuffer& sq_in, DeviceBuffer& sq_out,
                              DeviceBuffer& distance_vox) {
  checkSlotKernel(params.map, params.slot_count, brick_coords, brick_table, "roiDistancePass");
  if (axis < 0 || axis > 2) throw std::invalid_argument("roiDistancePass: axis must be 0, 1 or 2");
  if (params.radius_vox < 1 || params.radius_vox > 1000)
    throw std::invalid_argument("roiDistancePass: radius_vox must be in [1, 1000]");
  const std::size_t slots = params.slot_count;
  if (axis == 0) checkRange(roi, slots * sizeof(float), 0, "roiDistancePass: roi");
  if (axis > 0) checkRange(sq_in, slots * sizeof(std::uint32_t), 0, "roiDistancePass: sq_in");
  if (axis < 2) checkRange(sq_out, slots * sizeof(std::uint32_t), 0, "roiDistancePass: sq_out");
  if (axis == 2) checkRange(distance_vox, slots * sizeof(float), 0, "roiDistancePass: distance_vox");
  if (slots) dispatchRoiDistancePass(params, axis, brick_coords, brick_table, roi, sq_in, sq_out, distance_vox);
}

void Backend::extractFrontiers(const FrontierParams& params, const DeviceBuffer& brick_coords,
                               const DeviceBuffer& brick_table, const DeviceBuffer& occupancy,
                               const DeviceBuffer& roi, DeviceBuffer& out, DeviceBuffer& count) {
  checkSlotKernel(params.map, params.slot_count, brick_coords, brick_table, "extractFrontiers");
  const std::size_t slots = params.slot_count;
  checkRange(occupancy, slots * sizeof(float), 0, "extractFrontiers: occupancy");
  checkRange(roi, slots * sizeof(float), 0, "extractFrontiers: roi");
  checkRange(out, std::size_t{params.capacity} * sizeof(Frontier), 0, "extractFrontiers: out");
  checkRange(count, sizeof(std::uint32_t), 0, "extractFrontiers: count");
  if (slots) dispatchExtractFrontiers(params, brick_coords, brick_table, occupancy, roi, out, count);
}

std::unique_ptr<Backend> createBackend(BackendKind kind) {
  switch (kind) {
    case BackendKind::kCpu: return detail::createCpuBackend();
    case BackendKind::kOpenCl:
#ifdef FVP_WITH_OPENCL
      return detail::createOpenClBackend();
#else
      throw BackendUnavailable("opencl: this build has no OpenCL backend (FVP_WITH_OPENCL=OFF)");
#endif
    case BackendKind::kVulkan:
#ifdef FVP_WITH_VULKAN
      return detail::createVulkanBackend();
#else
      throw BackendUnavailable("vulkan: this build has no Vulkan backend (FVP_WITH_VULKAN=OFF)");
#endif
  }
  throw std::invalid_argument("unknown backend kind");
}

namespace {
bool isGpu(const Backend& backend) {
#ifdef FVP_WITH_OPENCL
  if (backend.kind() == BackendKind::kOpenCl) return detail::openClDeviceIsGpu(backend);
#endif
#ifdef FVP_WITH_VULKAN
  if (backend.kind() == BackendKind::kVulkan) return detail::vulkanDeviceIsGpu(backend);
#endif
  return false;
}
}  // namespace

std::vector<BackendInfo> probeBackends() {
  std::vector<BackendInfo> infos;
  for (BackendKind kind : {BackendKind::kCpu, BackendKind::kOpenCl, BackendKind::kVulkan}) {
    BackendInfo info;
    info.kind = kind;
    try {
      auto backend = createBackend(kind);
      info.available = true;
      info.is_gpu = isGpu(*backend);
      info.device = backend->deviceName();
    } catch (const std::exception& e) {
      info.reason = e.what();
    }
    infos.push_back(std::move(info));
  }
  return infos;
}

std::unique_ptr<Backend> createBackend(std::string_view name) {
  if (name == "auto") {
    for (BackendKind kind : {BackendKind::kOpenCl, BackendKind::kVulkan}) {
      try {
        auto backend = createBackend(kind);
        if (isGpu(*backend)) return backend;
      } catch (const BackendUnavailable&) {
        // auto means "best available": an absent GPU backend is expected here.
      }
    }
    return detail::createCpuBackend();
  }
  auto kind = parseBackendKind(name);
  if (!kind) {
    throw std::invalid_argument("unknown backend '" + std::string(name) +
                                "': expected cpu, opencl, vulkan or auto");
  }
  return createBackend(*kind);
}

}  // namespace fvp::accel
