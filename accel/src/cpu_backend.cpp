// The reference backend: plain C++ over host memory. It runs each kernel descriptor's CPU
// loop (accel/src/kernels/), which calls the same bodies (kernels/*.h) as the OpenCL kernels
// and is parallel with OpenMP.
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
  const T* as() const {
    return reinterpret_cast<const T*>(bytes_.data());
  }
  template <typename T>
  T* as() {
    return reinterpret_cast<T*>(bytes_.data());
  }

 private:
  std::vector<std::byte> bytes_;  // operator new alignment (16) covers every kernel type
};

const CpuBuffer& cpu(const DeviceBuffer& b) {
  return static_cast<const CpuBuffer&>(b);
}
CpuBuffer& cpu(DeviceBuffer& b) {
  return static_cast<CpuBuffer&>(b);
}

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

  void dispatchKernel(const KernelDescriptor& kernel, const void* params,
                      std::span<DeviceBuffer* const> buffers, std::uint32_t item_count) override {
    std::vector<void*> memory(buffers.size(), nullptr);
    for (std::size_t i = 0; i < buffers.size(); ++i)
      if (buffers[i]) memory[i] = cpu(*buffers[i]).data();
    kernel.cpu(params, memory.data(), item_count);
  }
};

}  // namespace

std::unique_ptr<Backend> createCpuBackend() {
  return std::make_unique<CpuBackend>();
}

}  // namespace fvp::accel::detail
