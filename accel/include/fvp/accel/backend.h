// The compute-backend interface. Three implementations: cpu (plain multithreaded C++,
// the reference and test oracle), opencl and vulkan. GPU work is explicit: the caller
// creates device buffers, uploads, dispatches kernels on buffers and downloads; each
// dispatch returns when its results are ready.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "fvp/accel/kernel_types.h"

namespace fvp::accel {

enum class BackendKind { kCpu, kOpenCl, kVulkan };

/// "cpu", "opencl" or "vulkan".
std::string_view toString(BackendKind kind);
/// Parses "cpu" | "opencl" | "vulkan"; nullopt for anything else ("auto" included).
std::optional<BackendKind> parseBackendKind(std::string_view name);

/// A backend call failed: the message names the API call, the source file and line,
/// and for kernel builds the compiler's log.
class BackendError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A backend the user asked for cannot run here (not built in, no driver, no device,
/// missing device feature). Never silently replaced by another backend.
class BackendUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Memory owned by one backend. Not copyable; freed when destroyed.
class DeviceBuffer {
 public:
  virtual ~DeviceBuffer() = default;
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  std::size_t sizeBytes() const { return size_bytes_; }

 protected:
  explicit DeviceBuffer(std::size_t size_bytes) : size_bytes_(size_bytes) {}

 private:
  std::size_t size_bytes_;
};

class Backend {
 public:
  virtual ~Backend() = default;
  Backend(const Backend&) = delete;
  Backend& operator=(const Backend&) = delete;

  virtual BackendKind kind() const = 0;
  /// The device the kernels run on, e.g. "cpu (2 threads)", "pthread-..." (PoCL), "llvmpipe ...".
  virtual std::string deviceName() const = 0;

  virtual std::unique_ptr<DeviceBuffer> createBuffer(std::size_t size_bytes) = 0;
  /// Copies size_bytes from host memory into buf at offset_bytes. Throws std::out_of_range
  /// if the range does not fit the buffer.
  void upload(DeviceBuffer& buf, const void* src, std::size_t size_bytes,
              std::size_t offset_bytes = 0);
  void download(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                std::size_t offset_bytes = 0);

  /// Kernel: batched voxel ray traversal (kernels/fvp_dda.h, fvp_traverse_ray).
  /// rays: params.ray_count Ray; occupancy, field: voxelCount(params.grid) float;
  /// results: params.ray_count RayResult. Throws std::out_of_range for short buffers.
  void traverseRays(const TraverseParams& params, const DeviceBuffer& rays,
                    const DeviceBuffer& occupancy, const DeviceBuffer& field,
                    DeviceBuffer& results);

  // ---- Map kernels over bricked storage (kernels/fvp_map_kernels.h) ----
  // Slots: brick * 512 + local voxel. brick_table: int per brick of the grid (kNoBrick where
  // unallocated); brick_coords: 3 int (brick grid coordinates) per allocated brick.

  /// Bytes of the scan mark buffer for slot_count slots (its layout is the backend's own).
  /// Mark buffers must start zeroed; the update pass leaves them zeroed.
  virtual std::size_t scanMarkBytes(std::size_t slot_count) const = 0;
  /// Mark pass: params.point_count ScanPoint. missing: brick_count + 1 uint; voxels in
  /// unallocated bricks set missing[brick] and missing[brick_count] to 1.
  void scanMark(const ScanParams& params, const DeviceBuffer& points, const DeviceBuffer& brick_table,
                DeviceBuffer& marks, DeviceBuffer& missing, std::uint32_t slot_count,
                std::uint32_t brick_count);
  /// Update pass over params.slot_count slots (a multiple of kBrickVoxels); roi is read and
  /// written only when params.has_roi. Adds the number of updated voxels to updated[0].
  void scanUpdate(const UpdateParams& params, DeviceBuffer& marks, DeviceBuffer& occupancy,
                  DeviceBuffer& roi, DeviceBuffer& updated);
  /// One pass (axis 0, 1, 2) of the ROI distance field. Axis 0 reads roi and writes
  /// sq_out; axis 1 reads sq_in, writes sq_out; axis 2 reads sq_in, writes distance_vox.
  void roiDistancePass(const EdtParams& params, int axis, const DeviceBuffer& brick_coords,
                       const DeviceBuffer& brick_table, const DeviceBuffer& roi,
                       const DeviceBuffer& sq_in, DeviceBuffer& sq_out, DeviceBuffer& distance_vox);
  /// Appends every frontier voxel to out (up to params.capacity entries, in any order);
  /// count[0] receives the total number found (may exceed the capacity).
  void extractFrontiers(const FrontierParams& params, const DeviceBuffer& brick_coords,
                        const DeviceBuffer& brick_table, const DeviceBuffer& occupancy,
                        const DeviceBuffer& roi, DeviceBuffer& out, DeviceBuffer& count);

  // Typed conveniences over upload/download.
  template <typename T>
  std::unique_ptr<DeviceBuffer> createBufferFrom(const std::vector<T>& host) {
    auto buf = createBuffer(host.size() * sizeof(T));
    if (!host.empty()) upload(*buf, host.data(), host.size() * sizeof(T));
    return buf;
  }
  template <typename T>
  std::vector<T> downloadAll(const DeviceBuffer& buf) {
    std::vector<T> host(buf.sizeBytes() / sizeof(T));
    if (!host.empty()) download(buf, host.data(), host.size() * sizeof(T));
    return host;
  }

 protected:
  Backend() = default;
  // Implementations: arguments are validated by the public twins above; size_bytes > 0.
  virtual void uploadBytes(DeviceBuffer& buf, const void* src, std::size_t size_bytes,
                           std::size_t offset_bytes) = 0;
  virtual void downloadBytes(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                             std::size_t offset_bytes) = 0;
  // ray_count > 0.
  virtual void dispatchTraverseRays(const TraverseParams& params, const DeviceBuffer& rays,
                                    const DeviceBuffer& occupancy, const DeviceBuffer& field,
                                    DeviceBuffer& results) = 0;
  // point_count > 0.
  virtual void dispatchScanMark(const ScanParams& params, const DeviceBuffer& points,
                                const DeviceBuffer& brick_table, DeviceBuffer& marks,
                                DeviceBuffer& missing, std::uint32_t slot_count,
                                std::uint32_t brick_count) = 0;
  // slot_count > 0.
  virtual void dispatchScanUpdate(const UpdateParams& params, DeviceBuffer& marks,
                                  DeviceBuffer& occupancy, DeviceBuffer& roi,
                                  DeviceBuffer& updated) = 0;
  virtual void dispatchRoiDistancePass(const EdtParams& params, int axis,
                                       const DeviceBuffer& brick_coords,
                                       const DeviceBuffer& brick_table, const DeviceBuffer& roi,
                                       const DeviceBuffer& sq_in, DeviceBuffer& sq_out,
                                       DeviceBuffer& distance_vox) = 0;
  virtual void dispatchExtractFrontiers(const FrontierParams& params,
                                        const DeviceBuffer& brick_coords,
                                        const DeviceBuffer& brick_table,
                                        const DeviceBuffer& occupancy, const DeviceBuffer& roi,
                                        DeviceBuffer& out, DeviceBuffer& count) = 0;
};

struct BackendInfo {
  BackendKind kind;
  bool available = false;
  bool is_gpu = false;
  std::string device;  ///< device name when available
  std::string reason;  ///< why not, when unavailable
};

/// Tries every backend that was built in (cheap: creates and drops a context).
std::vector<BackendInfo> probeBackends();

/// Creates the named backend or throws BackendUnavailable saying what is missing.
std::unique_ptr<Backend> createBackend(BackendKind kind);

/// "cpu" | "opencl" | "vulkan" | "auto". auto picks a GPU device (OpenCL first, then
/// Vulkan) when one exists, else the CPU reference. Throws std::invalid_argument for an
/// unknown name and BackendUnavailable for an explicitly named backend that cannot run.
std::unique_ptr<Backend> createBackend(std::string_view name);

}  // namespace fvp::accel
