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

namespace fvp::accel::detail {
namespace {

const char* clErrorName(cl_int err) {
  switch (err) {
    case CL_DEVICE_NOT_FOUND:
      return "CL_DEVICE_NOT_FOUND";
    case CL_DEVICE_NOT_AVAILABLE:
      return "CL_DEVICE_NOT_AVAILABLE";
    case CL_COMPILER_NOT_AVAILABLE:
      return "CL_COMPILER_NOT_AVAILABLE";
    case CL_MEM_OBJECT_ALLOCATION_FAILURE:
      return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
    case CL_OUT_OF_RESOURCES:
      return "CL_OUT_OF_RESOURCES";
    case CL_OUT_OF_HOST_MEMORY:
      return "CL_OUT_OF_HOST_MEMORY";
    case CL_BUILD_PROGRAM_FAILURE:
      return "CL_BUILD_PROGRAM_FAILURE";
    case CL_INVALID_VALUE:
      return "CL_INVALID_VALUE";
    case CL_INVALID_DEVICE:
      return "CL_INVALID_DEVICE";
    case CL_INVALID_BUFFER_SIZE:
      return "CL_INVALID_BUFFER_SIZE";
    case CL_INVALID_KERNEL_ARGS:
      return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_WORK_GROUP_SIZE:
      return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_ARG_SIZE:
      return "CL_INVALID_ARG_SIZE";
    case CL_INVALID_KERNEL_NAME:
      return "CL_INVALID_KERNEL_NAME";
    case CL_PLATFORM_NOT_FOUND_KHR:
      return "CL_PLATFORM_NOT_FOUND_KHR (no OpenCL driver installed)";
    default:
      return "OpenCL error";
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
        buffer_(
            FVP_CL(cl::Buffer(context, CL_MEM_READ_WRITE, std::max<std::size_t>(size_bytes, 4)))) {}
  const cl::Buffer& get() const { return buffer_; }

 private:
  cl::Buffer buffer_;
};

const cl::Buffer& clBuf(const DeviceBuffer& b) {
  return static_cast<const ClBuffer&>(b).get();
}

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
        if (!device.getInfo<CL_DEVICE_AVAILABLE>() ||
            !device.getInfo<CL_DEVICE_COMPILER_AVAILABLE>())
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
    // Every kernel up front: a kernel that does not build fails here, naming itself.
    for (const KernelDescriptor* kernel : allKernels())
      kernels_.emplace(kernel, buildKernel(*kernel));
    // Bound where a dispatch does not use a binding: every argument needs a valid buffer.
    unused_ = std::make_unique<ClBuffer>(context_, 16);
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
    countDeviceWait();
    FVP_CL(queue_.enqueueWriteBuffer(clBuf(buf), CL_TRUE, offset_bytes, size_bytes, src));
  }
  void downloadBytes(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                     std::size_t offset_bytes) override {
    countDeviceWait();
    FVP_CL(queue_.enqueueReadBuffer(clBuf(buf), CL_TRUE, offset_bytes, size_bytes, dst));
  }
  // Non-blocking writes on the in-order queue and one wait: the host image stays alive
  // until finish() returns.
  void uploadRangesBytes(DeviceBuffer& buf, const void* src_image,
                         std::span<const ByteRange> ranges) override {
    const auto* image = static_cast<const std::uint8_t*>(src_image);
    try {
      for (const ByteRange& r : ranges)
        FVP_CL(queue_.enqueueWriteBuffer(clBuf(buf), CL_FALSE, r.offset_bytes, r.size_bytes,
                                         image + r.offset_bytes));
    } catch (...) {
      queue_.finish();  // writes already queued read the caller's image: wait before it goes
      throw;
    }
    countDeviceWait();
    FVP_CL(queue_.finish());
  }

  void dispatchKernel(const KernelDescriptor& kernel, const void* params,
                      std::span<DeviceBuffer* const> buffers, std::uint32_t item_count) override {
    enqueueKernel(kernel, params, buffers, item_count);
    countDeviceWait();
    FVP_CL(queue_.finish());
  }

  // The in-order queue runs the commands in order, each after the last has finished (its
  // writes visible to the next); the host waits once. Kernel arguments are captured when a
  // command is enqueued, so one cl::Kernel serves several of them.
  void runSequence(std::span<const SequenceOp> ops) override {
    try {
      for (const SequenceOp& op : ops) switch (op.kind) {
          case SequenceOp::Kind::kUpload:
            FVP_CL(queue_.enqueueWriteBuffer(clBuf(*op.buffer), CL_FALSE, op.offset_bytes,
                                             op.size_bytes, op.src));
            break;
          case SequenceOp::Kind::kDispatch:
            enqueueKernel(*op.kernel, op.bytes.data(), op.buffers, op.item_count);
            break;
          case SequenceOp::Kind::kDownload:
            FVP_CL(queue_.enqueueReadBuffer(clBuf(*op.buffer), CL_FALSE, op.offset_bytes,
                                            op.size_bytes, op.dst));
            break;
        }
    } catch (...) {
      queue_.finish();  // queued commands read and write the callers' memory
      throw;
    }
    countDeviceWait();
    FVP_CL(queue_.finish());
  }

 private:
  void enqueueKernel(const KernelDescriptor& kernel, const void* params,
                     std::span<DeviceBuffer* const> buffers, std::uint32_t item_count) {
    Kernel& k = kernels_.at(&kernel);
    FVP_CL(k.kernel.setArg(0, kernel.params_bytes, params));
    FVP_CL(k.kernel.setArg(1, cl_uint{item_count}));
    for (std::size_t i = 0; i < buffers.size(); ++i)
      FVP_CL(
          k.kernel.setArg(static_cast<cl_uint>(2 + i), clBuf(buffers[i] ? *buffers[i] : *unused_)));
    const std::size_t global = (std::size_t{item_count} + k.local - 1) / k.local * k.local;
    FVP_CL(queue_.enqueueNDRangeKernel(k.kernel, cl::NullRange, cl::NDRange(global),
                                       cl::NDRange(k.local)));
  }

  struct Kernel {
    cl::Kernel kernel;
    std::size_t local = 1;
  };

  // Builds a descriptor's source and checks its arguments against the descriptor: the
  // parameter block, the item count, then one buffer per binding with the binding's name.
  Kernel buildKernel(const KernelDescriptor& descriptor) {
    const std::string name(descriptor.name);
    if (!descriptor.opencl_source)
      throw BackendError("opencl: kernel " + name + " has no OpenCL source in this build");
    cl::Program program = FVP_CL(cl::Program(context_, std::string(descriptor.opencl_source)));
    FVP_CL(program.build(std::vector<cl::Device>{device_}, "-cl-std=CL1.2 -cl-kernel-arg-info"));
    Kernel k;
    k.kernel = FVP_CL(cl::Kernel(program, descriptor.opencl_entry));
    const cl_uint args = FVP_CL(k.kernel.getInfo<CL_KERNEL_NUM_ARGS>());
    if (args != descriptor.bindings.size() + 2)
      throw BackendError("opencl: kernel " + name + " takes " + std::to_string(args) +
                         " arguments; its descriptor has " +
                         std::to_string(descriptor.bindings.size()) +
                         " bindings after the parameters and the item count");
    for (std::size_t i = 0; i < descriptor.bindings.size(); ++i) {
      std::string arg_name;
      // Argument names are optional in OpenCL 1.2 (CL_KERNEL_ARG_INFO_NOT_AVAILABLE).
      if (k.kernel.getArgInfo(static_cast<cl_uint>(2 + i), CL_KERNEL_ARG_NAME, &arg_name) !=
          CL_SUCCESS)
        break;
      arg_name = arg_name.c_str();  // some drivers count the terminating NUL
      if (arg_name != descriptor.bindings[i].name)
        throw BackendError("opencl: kernel " + name + " argument " + std::to_string(2 + i) +
                           " is '" + arg_name + "', its descriptor's binding " + std::to_string(i) +
                           " is '" + std::string(descriptor.bindings[i].name) + "'");
    }
    k.local = workGroupSize(k.kernel);
    return k;
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

  cl::Device device_;
  bool is_gpu_ = false;
  std::string device_name_;
  cl::Context context_;
  cl::CommandQueue queue_;
  std::map<const KernelDescriptor*, Kernel> kernels_;
  std::unique_ptr<ClBuffer> unused_;
};

}  // namespace

std::unique_ptr<Backend> createOpenClBackend() {
  return std::make_unique<OpenClBackend>();
}

bool openClDeviceIsGpu(const Backend& backend) {
  return static_cast<const OpenClBackend&>(backend).isGpu();
}

}  // namespace fvp::accel::detail
