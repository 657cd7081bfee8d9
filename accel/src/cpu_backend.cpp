// The reference backend: plain C++ over host memory, parallel over rays with OpenMP.
// It runs the same kernel bodies (kernels/fvp_dda.h) as the OpenCL backend.
#include <omp.h>

#include <cstring>
#include <string>
#include <vector>

#include "backends.h"

namespace fvp::accel::detail {
namespace {

class CpuBuffer final : public DeviceBuffer {
 public:
  explicit CpuBuffer(std::size_t size_bytes) : DeviceBuffer(size_bytes), bytes_(size_bytes) {}
  std::byte* data() { return bytes_.data(); }
  const std::byte* data() const { return bytes_.data(); }
  template <typename T>
  const T* as() const { return reinterpret_cast<const T*>(bytes_.data()); }
  template <typename T>
  T* as() { return reinterpret_cast<T*>(bytes_.data()); }

 private:
  std::vector<std::byte> bytes_;  // operator new alignment (16) covers every kernel type
};

const CpuBuffer& cpu(const DeviceBuffer& b) { return static_cast<const CpuBuffer&>(b); }
CpuBuffer& cpu(DeviceBuffer& b) { return static_cast<CpuBuffer&>(b); }

class CpuBackend final : public Backend {
 public:
  BackendKind kind() const override { return BackendKind::kCpu; }
  std::string deviceName() const override {
    return "host CPU, " + std::to_string(omp_get_max_threads()) + " OpenMP threads";
  }

  std::unique_ptr<DeviceBuffer> createBuffer(std::size_t size_bytes) override {
    return std::make_unique<CpuBuffer>(size_bytes);
  }

 protected:
  void uploadBytes(DeviceBuffer& buf, const void* src, std::size_t size_bytes,
                   std::size_t offset_bytes) override {
    std::memcpy(cpu(buf).data() + offset_bytes, src, size_bytes);
  }
  void downloadBytes(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                     std::size_t offset_bytes) override {
    std::memcpy(dst, cpu(buf).data() + offset_bytes, size_bytes);
  }

  void dispatchTraverseRays(const TraverseParams& params, const DeviceBuffer& rays,
                            const DeviceBuffer& occupancy, const DeviceBuffer& field,
                            DeviceBuffer& results) override {
    const Ray* ray = cpu(rays).as<Ray>();
    const float* occ = cpu(occupancy).as<float>();
    const float* fld = cpu(field).as<float>();
    RayResult* out = cpu(results).as<RayResult>();
    const auto count = static_cast<std::ptrdiff_t>(params.ray_count);
    // Rays differ a lot in length: small dynamic chunks balance the threads.
#pragma omp parallel for schedule(dynamic, 64)
    for (std::ptrdiff_t i = 0; i < count; ++i) {
      out[i] = fvp_traverse_ray(&params.grid, params.occupied_threshold, ray[i].origin_m,
                                ray[i].end_m, occ, fld);
    }
  }

 public:
  // Three byte planes: free | hit | roi.
  std::size_t scanMarkBytes(std::size_t slot_count) const override { return 3 * slot_count; }

 protected:
  void dispatchScanMark(const ScanParams& params, const DeviceBuffer& points,
                        const DeviceBuffer& brick_table, DeviceBuffer& marks, DeviceBuffer& missing,
                        std::uint32_t slot_count, std::uint32_t brick_count) override {
    const ScanPoint* pts = cpu(points).as<ScanPoint>();
    const int* table = cpu(brick_table).as<int>();
    unsigned char* m = cpu(marks).as<unsigned char>();
    unsigned int* miss = cpu(missing).as<unsigned int>();
    const auto count = static_cast<std::ptrdiff_t>(params.point_count);
#pragma omp parallel for schedule(dynamic, 256)
    for (std::ptrdiff_t i = 0; i < count; ++i) {
      fvp_scan_mark_point(&params, pts[i], table, m, m + slot_count, m + 2 * std::size_t{slot_count},
                          miss, static_cast<int>(brick_count));
    }
  }

  void dispatchScanUpdate(const UpdateParams& params, DeviceBuffer& marks, DeviceBuffer& occupancy,
                          DeviceBuffer& roi, DeviceBuffer& updated) override {
    unsigned char* m = cpu(marks).as<unsigned char>();
    const std::size_t slots = params.slot_count;
    float* occ = cpu(occupancy).as<float>();
    float* roi_values = params.has_roi ? cpu(roi).as<float>() : nullptr;
    const auto chunks = static_cast<std::ptrdiff_t>(slots / kUpdateChunkSlots);
    unsigned long long total = 0;
#pragma omp parallel for schedule(static) reduction(+ : total)
    for (std::ptrdiff_t c = 0; c < chunks; ++c) {
      total += fvp_scan_update_slots(&params, static_cast<unsigned>(c * kUpdateChunkSlots),
                                     kUpdateChunkSlots, m, m + slots, m + 2 * slots, occ, roi_values);
    }
    cpu(updated).as<std::uint32_t>()[0] += static_cast<std::uint32_t>(total);
  }

  void dispatchRoiDistancePass(const EdtParams& params, int axis, const DeviceBuffer& brick_coords,
                               const DeviceBuffer& brick_table, const DeviceBuffer& roi,
                               const DeviceBuffer& sq_in, DeviceBuffer& sq_out,
                               DeviceBuffer& distance_vox) override {
    const int* coords = cpu(brick_coords).as<int>();
    const int* table = cpu(brick_table).as<int>();
    const float* roi_values = axis == 0 ? cpu(roi).as<float>() : nullptr;
    const unsigned int* in = axis > 0 ? cpu(sq_in).as<unsigned int>() : nullptr;
    unsigned int* out = axis < 2 ? cpu(sq_out).as<unsigned int>() : nullptr;
    float* dist = axis == 2 ? cpu(distance_vox).as<float>() : nullptr;
    const auto slots = static_cast<std::ptrdiff_t>(params.slot_count);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t s = 0; s < slots; ++s) {
      int x, y, z;
      fvp_slot_voxel(coords, static_cast<unsigned>(s), &x, &y, &z);
      const unsigned best = fvp_edt_pass_voxel(&params, axis, x, y, z, table, roi_values, in);
      if (axis < 2) out[s] = best;
      else dist[s] = fvp_edt_distance_vox(best, params.radius_vox);
    }
  }

  void dispatchExtractFrontiers(const FrontierParams& params, const DeviceBuffer& brick_coords,
                                const DeviceBuffer& brick_table, const DeviceBuffer& occupancy,
                                const DeviceBuffer& roi, DeviceBuffer& out,
                                DeviceBuffer& count) override {
    const int* coords = cpu(brick_coords).as<int>();
    const int* table = cpu(brick_table).as<int>();
    const float* occ = cpu(occupancy).as<float>();
    const float* roi_values = cpu(roi).as<float>();
    Frontier* list = cpu(out).as<Frontier>();
    unsigned int* found = cpu(count).as<unsigned int>();
    const auto slots = static_cast<std::ptrdiff_t>(params.slot_count);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t s = 0; s < slots; ++s) {
      int x, y, z, normal[3];
      fvp_slot_voxel(coords, static_cast<unsigned>(s), &x, &y, &z);
      const unsigned flags = fvp_frontier_voxel(&params, x, y, z, table, occ, roi_values, normal);
      if (!flags) continue;
      const unsigned index = FVP_ATOMIC_INC(found);
      if (index < params.capacity)
        list[index] = Frontier{x, y, z, flags, normal[0], normal[1], normal[2], 0};
    }
  }
};

}  // namespace

std::unique_ptr<Backend> createCpuBackend() { return std::make_unique<CpuBackend>(); }

}  // namespace fvp::accel::detail
