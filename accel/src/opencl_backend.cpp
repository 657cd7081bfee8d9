// OpenCL backend: kernels from kernels/*.cl, embedded at build time, built for the first
// GPU device found (else the first device of any type: PoCL's CPU device here).
#define CL_HPP_ENABLE_EXCEPTIONS
// Debian's CL/opencl.hpp fails to compile with a minimum version of 120.
#define CL_HPP_TARGET_OPENCL_VERSION 300
#define CL_HPP_MINIMUM_OPENCL_VERSION 110
#include <CL/opencl.hpp>

#include <algorithm>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "backends.h"
#include "check.h"

extern const char kOpenClSource_ray_traverse[];
extern const char kOpenClSource_scan_integrate[];
extern const char kOpenClSource_roi_distance[];
extern const char kOpenClSource_frontier[];

namespace fvp::accel::detail {
namespace {

const char* clErrorName(cl_int err) {
  switch (err) {
    case CL_DEVICE_NOT_FOUND: return "CL_DEVICE_NOT_FOUND";
    case CL_DEVICE_NOT_AVAILABLE: return "CL_DEVICE_NOT_AVAILABLE";
    case CL_COMPILER_NOT_AVAILABLE: return "CL_COMPILER_NOT_AVAILABLE";
    case CL_MEM_OBJECT_ALLOCATION_FAILURE: return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
    case CL_OUT_OF_RESOURCES: return "CL_OUT_OF_RESOURCES";
    case CL_OUT_OF_HOST_MEMORY: return "CL_OUT_OF_HOST_MEMORY";
    case CL_BUILD_PROGRAM_FAILURE: return "CL_BUILD_PROGRAM_FAILURE";
    case CL_INVALID_VALUE: return "CL_INVALID_VALUE";
    case CL_INVALID_DEVICE: return "CL_INVALID_DEVICE";
    case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
    case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_ARG_SIZE: return "CL_INVALID_ARG_SIZE";
    case CL_INVALID_KERNEL_NAME: return "CL_INVALID_KERNEL_NAME";
    case CL_PLATFORM_NOT_FOUND_KHR: return "CL_PLATFORM_NOT_FOUND_KHR (no OpenCL driver installed)";
    default: return "OpenCL error";
  }
}

// Runs one OpenCL C++-binding call; a cl::Error becomes a BackendError naming the call.
template <typename F>
auto clChecked(F&& f, const char* call, const char* file, int line) -> decltype(f()) {
  try {
    return f();
  } catch (const cl::BuildError& e) {
    std::ostringstream detail;
    detail << e.what() << ": " << clErrorName(e.err()) << " (" << e.err() << ")";
    for (const auto& [device, log] : e.getBuildLog())
      detail << "\nbuild log for " << device.template getInfo<CL_DEVICE_NAME>() << ":\n" << log;
    throwBackendError("OpenCL", call, detail.str(), file, line);
  } catch (const cl::Error& e) {
    std::ostringstream detail;
    detail << e.what() << ": " << clErrorName(e.err()) << " (" << e.err() << ")";
    throwBackendError("OpenCL", call, detail.str(), file, line);
  }
}
#define FVP_CL(expr) clChecked([&]() { return expr; }, #expr, __FILE__, __LINE__)

class ClBuffer final : public DeviceBuffer {
 public:
  ClBuffer(const cl::Context& context, std::size_t size_bytes)
      // OpenCL rejects zero-sized buffers; an empty buffer still owns a few bytes.
      : DeviceBuffer(size_bytes),
        buffer_(FVP_CL(cl::Buffer(context, CL_MEM_READ_WRITE, std::max<std::size_t>(size_bytes, 4)))) {}
  const cl::Buffer& get() const { return buffer_; }

 private:
  cl::Buffer buffer_;
};

const cl::Buffer& clBuf(const DeviceBuffer& b) { return static_cast<const ClBuffer&>(b).get(); }

struct Selected {
  cl::Platform platform;
  cl::Device device;
};

Selected selectDevice() {
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error& e) {
    throw BackendUnavailable(std::string("opencl: no OpenCL platform (") + clErrorName(e.err()) +
                             "); install an ICD such as pocl-opencl-icd");
  }
  std::optional<Selected> fallback;
  for (const auto& platform : platforms) {
    std::vector<cl::Device> devices;
    try {
      platform.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;  // a platform without devices is not an error while others remain
    }
    for (const auto& device : devices) {
      try {
        if (!device.getInfo<CL_DEVICE_AVAILABLE>() || !device.getInfo<CL_DEVICE_COMPILER_AVAILABLE>())
          continue;
        if (device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_GPU) return {platform, device};
      } catch (const cl::Error&) {
        continue;  // a device that cannot describe itself is not usable
      }
      if (!fallback) fallback = Selected{platform, device};
    }
  }
  if (!fallback)
    throw BackendUnavailable("opencl: no available OpenCL device with a compiler on " +
                             std::to_string(platforms.size()) + " platform(s)");
  return *fallback;
}

class OpenClBackend final : public Backend {
 public:
  OpenClBackend() {
    Selected s = selectDevice();
    device_ = s.device;
    is_gpu_ = (FVP_CL(device_.getInfo<CL_DEVICE_TYPE>()) & CL_DEVICE_TYPE_GPU) != 0;
    device_name_ = FVP_CL(device_.getInfo<CL_DEVICE_NAME>()) + " (" +
                   FVP_CL(s.platform.getInfo<CL_PLATFORM_NAME>()) + ")";
    context_ = FVP_CL(cl::Context(device_));
    queue_ = FVP_CL(cl::CommandQueue(context_, device_));
    ray_traverse_ = buildKernel(kOpenClSource_ray_traverse, "fvp_ray_traverse");
    scan_mark_ = buildKernel(kOpenClSource_scan_integrate, "fvp_scan_mark");
    scan_update_ = buildKernel(kOpenClSource_scan_integrate, "fvp_scan_update");
    roi_distance_ = buildKernel(kOpenClSource_roi_distance, "fvp_roi_distance_pass");
    frontier_ = buildKernel(kOpenClSource_frontier, "fvp_extract_frontiers");
  }

  BackendKind kind() const override { return BackendKind::kOpenCl; }
  std::string deviceName() const override { return device_name_; }
  bool isGpu() const { return is_gpu_; }

  std::unique_ptr<DeviceBuffer> createBuffer(std::size_t size_bytes) override {
    return std::make_unique<ClBuffer>(context_, size_bytes);
  }

 protected:
  void uploadBytes(DeviceBuffer& buf, const void* src, std::size_t size_bytes,
                   std::size_t offset_bytes) override {
    FVP_CL(queue_.enqueueWriteBuffer(clBuf(buf), CL_TRUE, offset_bytes, size_bytes, src));
  }
  void downloadBytes(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                     std::size_t offset_bytes) override {
    FVP_CL(queue_.enqueueReadBuffer(clBuf(buf), CL_TRUE, offset_bytes, size_bytes, dst));
  }

  void dispatchTraverseRays(const TraverseParams& params, const DeviceBuffer& rays,
                            const DeviceBuffer& occupancy, const DeviceBuffer& field,
                            DeviceBuffer& results) override {
    run(ray_traverse_, params.ray_count, params, clBuf(rays), clBuf(occupancy), clBuf(field),
        clBuf(results));
  }

 public:
  // Three byte planes: free | hit | roi (plain byte stores; see fvp_map_kernels.h).
  std::size_t scanMarkBytes(std::size_t slot_count) const override { return 3 * slot_count; }

 protected:
  void dispatchScanMark(const ScanParams& params, const DeviceBuffer& points,
                        const DeviceBuffer& brick_table, DeviceBuffer& marks, DeviceBuffer& missing,
                        std::uint32_t slot_count, std::uint32_t brick_count) override {
    run(scan_mark_, params.point_count, params, clBuf(points), clBuf(brick_table), clBuf(marks),
        clBuf(missing), cl_uint{slot_count}, static_cast<cl_int>(brick_count));
  }

  void dispatchScanUpdate(const UpdateParams& params, DeviceBuffer& marks, DeviceBuffer& occupancy,
                          DeviceBuffer& roi, DeviceBuffer& updated) override {
    run(scan_update_, params.slot_count / kUpdateChunkSlots, params, clBuf(marks), clBuf(occupancy),
        clBuf(roi), clBuf(updated));
  }

  void dispatchRoiDistancePass(const EdtParams& params, int axis, const DeviceBuffer& brick_coords,
                               const DeviceBuffer& brick_table, const DeviceBuffer& roi,
                               const DeviceBuffer& sq_in, DeviceBuffer& sq_out,
                               DeviceBuffer& distance_vox) override {
    run(roi_distance_, params.slot_count, params, cl_int{axis}, clBuf(brick_coords),
        clBuf(brick_table), clBuf(roi), clBuf(sq_in), clBuf(sq_out), clBuf(distance_vox));
  }

  void dispatchExtractFrontiers(const FrontierParams& params, const DeviceBuffer& brick_coords,
                                const DeviceBuffer& brick_table, const DeviceBuffer& occupancy,
                                const DeviceBuffer& roi, DeviceBuffer& out,
                                DeviceBuffer& count) override {
    run(frontier_, params.slot_count, params, clBuf(brick_coords), clBuf(brick_table),
        clBuf(occupancy), clBuf(roi), clBuf(out), clBuf(count));
  }

 private:
  struct Kernel {
    cl::Kernel kernel;
    std::size_t local = 1;
  };

  // Builds one embedded source (programs are cached per source) and takes one kernel.
  Kernel buildKernel(const char* source, const char* name) {
    auto it = programs_.find(source);
    if (it == programs_.end()) {
      cl::Program program = FVP_CL(cl::Program(context_, std::string(source)));
      FVP_CL(program.build(std::vector<cl::Device>{device_}, "-cl-std=CL1.2"));
      it = programs_.emplace(source, std::move(program)).first;
    }
    Kernel k;
    k.kernel = FVP_CL(cl::Kernel(it->second, name));
    k.local = workGroupSize(k.kernel);
    return k;
  }

  // Sets the arguments in order and runs the kernel over `items` work items.
  template <typename... Args>
  void run(Kernel& k, std::size_t items, const Args&... args) {
    cl_uint index = 0;
    (FVP_CL(k.kernel.setArg(index++, args)), ...);
    enqueue1D(k.kernel, items, k.local);
  }

  // Largest multiple of the preferred multiple not above 64 and the kernel's limit:
  // queried per kernel and device, never assumed.
  std::size_t workGroupSize(const cl::Kernel& kernel) const {
    const std::size_t max_size =
        FVP_CL(kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device_));
    const std::size_t multiple =
        FVP_CL(kernel.getWorkGroupInfo<CL_KERNEL_PREFERRED_WORK_GROUP_SIZE_MULTIPLE>(device_));
    std::size_t local = std::min<std::size_t>(64, max_size);
    if (multiple > 0 && multiple <= local) local -= local % multiple;
    return std::max<std::size_t>(local, 1);
  }

  void enqueue1D(const cl::Kernel& kernel, std::size_t items, std::size_t local) {
    const std::size_t global = (items + local - 1) / local * local;
    FVP_CL(queue_.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(global),
                                       cl::NDRange(local)));
    FVP_CL(queue_.finish());
  }

  cl::Device device_;
  bool is_gpu_ = false;
  std::string device_name_;
  cl::Context context_;
  cl::CommandQueue queue_;
  std::map<const char*, cl::Program> programs_;
  Kernel ray_traverse_, scan_mark_, scan_update_, roi_distance_, frontier_;
};

}  // namespace

std::unique_ptr<Backend> createOpenClBackend() { return std::make_unique<OpenClBackend>(); }

bool openClDeviceIsGpu(const Backend& backend) {
  return static_cast<const OpenClBackend&>(backend).isGpu();
}

}  // namespace fvp::accel::detail
