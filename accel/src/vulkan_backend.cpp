// Vulkan backend: GLSL compute shaders from shaders/, compiled to SPIR-V at build time and
// embedded. Prefers a discrete or integrated GPU; falls back to a CPU implementation
// (Mesa lavapipe here). Every dispatch is recorded into a command buffer, submitted and
// waited for with a fence, so results are ready when the call returns; a Sequence records
// all its operations into one command buffer, with a barrier between each two.
#include <dlfcn.h>
#include <link.h>
#include <vulkan/vulkan_raii.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "backends.h"
#include "check.h"

namespace fvp::accel::detail {
namespace {

template <typename F>
auto vkChecked(F&& f, const char* call, const char* file, int line) -> decltype(f()) {
  try {
    return f();
  } catch (const vk::Error& e) {
    throwBackendError("Vulkan", call, e.what(), file, line);
  }
}
#define FVP_VK(expr) vkChecked([&]() { return expr; }, #expr, __FILE__, __LINE__)

constexpr uint32_t kPreferredWorkGroupSize = 64;
// The dispatch header every shader's parameter block starts with (shaders/fvp_kernel.glsl).
constexpr uint32_t kDispatchHeaderBytes = 2 * sizeof(uint32_t);
// Dispatches one submission holds at most: each holds up to two descriptor sets from the
// pool until its fence; a longer sequence is submitted in parts of this many.
constexpr uint32_t kDispatchesPerSubmission = 32;
// Storage-buffer descriptors the pool holds: enough for that many dispatches of kernels
// binding up to 15 buffers each.
constexpr uint32_t kPoolDescriptors = kDispatchesPerSubmission * 16;
// Bytes one submission's transfers may stage: a part ends before a transfer that would pass
// it (a single larger transfer gets a part of its own), so the staging buffers stay bounded.
constexpr std::size_t kStagedBytesPerSubmission = std::size_t{64} << 20;

std::set<std::string> loadedObjects() {
  std::set<std::string> names;
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void* out) {
        if (info->dlpi_name && info->dlpi_name[0])
          static_cast<std::set<std::string>*>(out)->insert(info->dlpi_name);
        return 0;
      },
      &names);
  return names;
}

// The Vulkan loader dlcloses its drivers in vkDestroyInstance. Mesa keeps process-lifetime
// allocations in driver globals (lavapipe's CPU cache topology on AMD CPUs), which
// LeakSanitizer then reports as direct leaks from an <unknown module> that no suppression
// can name. Keeping every object the instance loaded (drivers, layers, libLLVM) mapped for
// the life of the process keeps those allocations reachable. Best effort: never fails.
void pinObjectsLoadedSince(const std::set<std::string>& before) noexcept {
  try {
    for (const auto& name : loadedObjects()) {
      if (before.count(name)) continue;
      // RTLD_NOLOAD only flags what is already loaded; dlclose drops just our reference.
      if (void* handle = dlopen(name.c_str(), RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE))
        dlclose(handle);
    }
  } catch (...) {
  }
}

bool deviceIsGpu(vk::PhysicalDeviceType type) {
  return type == vk::PhysicalDeviceType::eDiscreteGpu ||
         type == vk::PhysicalDeviceType::eIntegratedGpu;
}

int deviceRank(vk::PhysicalDeviceType type) {
  switch (type) {
    case vk::PhysicalDeviceType::eDiscreteGpu:
      return 0;
    case vk::PhysicalDeviceType::eIntegratedGpu:
      return 1;
    case vk::PhysicalDeviceType::eVirtualGpu:
      return 2;
    case vk::PhysicalDeviceType::eCpu:
      return 3;
    default:
      return 4;
  }
}

class VkBuffer final : public DeviceBuffer {
 public:
  VkBuffer(std::size_t size_bytes, vk::raii::Buffer buffer, vk::raii::DeviceMemory memory,
           void* mapped)
      : DeviceBuffer(size_bytes),
        buffer_(std::move(buffer)),
        memory_(std::move(memory)),
        mapped_(static_cast<std::byte*>(mapped)) {}
  ~VkBuffer() override {
    if (mapped_) memory_.unmapMemory();
  }
  vk::Buffer get() const { return *buffer_; }
  std::byte* mapped() const { return mapped_; }  // null when not host visible

 private:
  vk::raii::Buffer buffer_;
  vk::raii::DeviceMemory memory_;
  std::byte* mapped_;
};

const VkBuffer& vkBuf(const DeviceBuffer& b) {
  return static_cast<const VkBuffer&>(b);
}

// One compute pipeline: storage buffers at bindings 0..n-1 of set 0, push constants,
// work-group size as specialisation constant 0.
// One kernel's compute pipeline: its buffers at set 0, bindings 0..n-1; the dispatch header
// (first item, item count) in push constants, followed there by the parameter block when
// it fits, else the parameters in a storage buffer at set 1, binding 0; work-group size as
// specialisation constant 0.
struct ComputePipeline {
  vk::raii::DescriptorSetLayout set_layout{nullptr};
  vk::raii::DescriptorSetLayout params_set_layout{nullptr};
  vk::raii::PipelineLayout layout{nullptr};
  vk::raii::ShaderModule module{nullptr};
  vk::raii::Pipeline pipeline{nullptr};
  bool params_in_buffer = false;
};

class VulkanBackend final : public Backend {
 public:
  VulkanBackend() {
    vk::ApplicationInfo app("fvp", 1, "fvp", 1, VK_API_VERSION_1_1);
    std::set<std::string> loaded_before;
    try {
      loaded_before = loadedObjects();
    } catch (...) {
    }
    try {
      instance_ = vk::raii::Instance(context_, vk::InstanceCreateInfo({}, &app));
    } catch (const vk::Error& e) {
      throw BackendUnavailable(std::string("vulkan: cannot create an instance (") + e.what() +
                               "); install a driver such as mesa-vulkan-drivers");
    }
    pinObjectsLoadedSince(loaded_before);
    pickDevice();
    createDevice();
    // Every kernel up front: a pipeline that cannot be created fails here.
    for (const KernelDescriptor* kernel : allKernels())
      pipelines_.emplace(kernel, createPipeline(*kernel));
    // Bound where a dispatch does not use a binding: every binding needs a valid buffer.
    unused_ = createBuffer(16);
  }

  BackendKind kind() const override { return BackendKind::kVulkan; }
  std::string deviceName() const override { return device_name_; }
  bool isGpu() const { return is_gpu_; }

  std::unique_ptr<DeviceBuffer> createBuffer(std::size_t size_bytes) override {
    return allocateBuffer(size_bytes, unified_memory_ ? Placement::kUnified : Placement::kDevice);
  }

 protected:
  void uploadBytes(DeviceBuffer& buf, const void* src, std::size_t size_bytes,
                   std::size_t offset_bytes) override {
    const VkBuffer& dst = vkBuf(buf);
    if (dst.mapped()) {
      std::memcpy(dst.mapped() + offset_bytes, src, size_bytes);
      return;
    }
    const VkBuffer& staging = stagingBuffer(staging_upload_, size_bytes, Placement::kStagingUpload);
    std::memcpy(staging.mapped(), src, size_bytes);
    submit([&](const vk::raii::CommandBuffer& cmd) {
      cmd.copyBuffer(staging.get(), dst.get(), vk::BufferCopy(0, offset_bytes, size_bytes));
    });
  }

  // Every range packed into the staging buffer, then one copy command with a region per
  // range and one submission: a submission and fence wait cost ~0.3-0.5 ms on an H100.
  void uploadRangesBytes(DeviceBuffer& buf, const void* src_image,
                         std::span<const ByteRange> ranges) override {
    const VkBuffer& dst = vkBuf(buf);
    const auto* image = static_cast<const std::uint8_t*>(src_image);
    if (dst.mapped()) {
      for (const ByteRange& r : ranges)
        std::memcpy(dst.mapped() + r.offset_bytes, image + r.offset_bytes, r.size_bytes);
      return;
    }
    std::size_t total = 0;
    for (const ByteRange& r : ranges) total += r.size_bytes;
    const VkBuffer& staging = stagingBuffer(staging_upload_, total, Placement::kStagingUpload);
    std::vector<vk::BufferCopy> regions;
    regions.reserve(ranges.size());
    std::size_t packed = 0;
    for (const ByteRange& r : ranges) {
      std::memcpy(staging.mapped() + packed, image + r.offset_bytes, r.size_bytes);
      regions.emplace_back(packed, r.offset_bytes, r.size_bytes);
      packed += r.size_bytes;
    }
    submit([&](const vk::raii::CommandBuffer& cmd) {
      cmd.copyBuffer(staging.get(), dst.get(), regions);
    });
  }

  void downloadBytes(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                     std::size_t offset_bytes) override {
    const VkBuffer& src = vkBuf(buf);
    if (src.mapped()) {
      std::memcpy(dst, src.mapped() + offset_bytes, size_bytes);
      return;
    }
    const VkBuffer& staging =
        stagingBuffer(staging_download_, size_bytes, Placement::kStagingDownload);
    submit([&](const vk::raii::CommandBuffer& cmd) {
      cmd.copyBuffer(src.get(), staging.get(), vk::BufferCopy(offset_bytes, 0, size_bytes));
    });
    std::memcpy(dst, staging.mapped(), size_bytes);
  }

  void dispatchKernel(const KernelDescriptor& kernel, const void* params,
                      std::span<DeviceBuffer* const> buffers, std::uint32_t item_count) override {
    std::unique_ptr<DeviceBuffer> params_buffer;
    if (pipelines_.at(&kernel).params_in_buffer) {
      params_buffer = createBuffer(kernel.params_bytes);
      // Not counted as the caller's upload: a sequence's parameter blocks are not either.
      uploadBytes(*params_buffer, params, kernel.params_bytes, 0);
    }
    BoundDispatch bound = bindDispatch(kernel, params, buffers, item_count, params_buffer.get());
    submit([&](const vk::raii::CommandBuffer& cmd) { recordDispatch(cmd, bound); });
  }

  // Parts of at most kDispatchesPerSubmission dispatches and kStagedBytesPerSubmission
  // transferred bytes, each one submission: uploads and parameter blocks packed into the
  // upload staging buffer and copied by the command buffer, downloads copied into the
  // download staging buffer and read after the fence.
  void runSequence(std::span<const SequenceOp> ops) override {
    std::size_t first = 0;
    while (first < ops.size()) {
      std::size_t end = first, bytes = 0;
      for (uint32_t dispatches = 0; end < ops.size(); ++end) {
        const SequenceOp& op = ops[end];
        if (op.kind == SequenceOp::Kind::kDispatch && dispatches++ == kDispatchesPerSubmission)
          break;
        if (op.kind != SequenceOp::Kind::kDispatch) {
          if (end > first && bytes + op.size_bytes > kStagedBytesPerSubmission) break;
          bytes += op.size_bytes;
        }
      }
      runSequencePart(ops.subspan(first, end - first));
      first = end;
    }
  }

 private:
  enum class Placement {
    kUnified,          // integrated GPUs and CPU devices: device memory the host maps
    kDevice,           // discrete GPUs: device-local, filled through staging copies
    kStagingUpload,    // host-visible, coherent
    kStagingDownload,  // host-visible, coherent, cached when available
  };

  // One staging buffer per direction, kept and grown to the next power of two: allocating
  // one per transfer cost ~0.8 ms each on an H100 (393 transfers made a map step 11x slower
  // than OpenCL's). Transfers are synchronous, so one buffer per direction suffices.
  const VkBuffer& stagingBuffer(std::unique_ptr<DeviceBuffer>& slot, std::size_t size_bytes,
                                Placement placement) {
    if (!slot || slot->sizeBytes() < size_bytes) {
      slot.reset();
      const std::size_t grown = std::bit_ceil(std::max<std::size_t>(size_bytes, 64 * 1024));
      const std::size_t capped = std::min<std::size_t>(grown, max_allocation_bytes_);
      slot = allocateBuffer(std::max(size_bytes, capped), placement);
    }
    return vkBuf(*slot);
  }

  std::unique_ptr<DeviceBuffer> allocateBuffer(std::size_t size_bytes, Placement placement) {
    // Vulkan rejects zero-sized buffers; an empty buffer still owns a few bytes.
    const vk::DeviceSize bytes = std::max<std::size_t>(size_bytes, 4);
    if (bytes > max_allocation_bytes_)
      throw BackendError("vulkan: a buffer of " + std::to_string(bytes) +
                         " bytes exceeds the device's maxMemoryAllocationSize (" +
                         std::to_string(max_allocation_bytes_) + ")");
    const auto usage = vk::BufferUsageFlagBits::eStorageBuffer |
                       vk::BufferUsageFlagBits::eTransferSrc |
                       vk::BufferUsageFlagBits::eTransferDst;
    vk::raii::Buffer buffer =
        FVP_VK(vk::raii::Buffer(device_, vk::BufferCreateInfo({}, bytes, usage)));
    const vk::MemoryRequirements req = buffer.getMemoryRequirements();
    using M = vk::MemoryPropertyFlagBits;
    const vk::MemoryPropertyFlags host = M::eHostVisible | M::eHostCoherent;
    std::optional<uint32_t> type;
    switch (placement) {
      case Placement::kUnified:
        type = findMemoryType(req, host | M::eDeviceLocal);
        if (!type) type = findMemoryType(req, host);
        break;
      case Placement::kDevice:
        type = findMemoryType(req, M::eDeviceLocal);
        break;
      case Placement::kStagingUpload:
        type = findMemoryType(req, host);
        break;
      case Placement::kStagingDownload:
        type = findMemoryType(req, host | M::eHostCached);
        if (!type) type = findMemoryType(req, host);
        break;
    }
    if (!type)
      throw BackendError("vulkan: no suitable memory type for a buffer of " +
                         std::to_string(bytes) + " bytes");
    vk::raii::DeviceMemory memory =
        FVP_VK(vk::raii::DeviceMemory(device_, vk::MemoryAllocateInfo(req.size, *type)));
    FVP_VK(buffer.bindMemory(*memory, 0));
    // Device buffers of discrete GPUs are reached through staging copies only, even where
    // their memory happens to be host-visible.
    void* mapped = nullptr;
    if (placement != Placement::kDevice) mapped = FVP_VK(memory.mapMemory(0, VK_WHOLE_SIZE));
    return std::make_unique<VkBuffer>(size_bytes, std::move(buffer), std::move(memory), mapped);
  }

  void pickDevice() {
    std::vector<vk::raii::PhysicalDevice> devices;
    try {
      devices = vk::raii::PhysicalDevices(instance_);
    } catch (const vk::Error& e) {
      throw BackendUnavailable(std::string("vulkan: cannot list devices (") + e.what() + ")");
    }
    std::optional<std::size_t> best;
    std::string rejected;
    for (std::size_t i = 0; i < devices.size(); ++i) {
      const auto props = devices[i].getProperties();
      if (props.apiVersion < VK_API_VERSION_1_1) {
        rejected += std::string(" ") + props.deviceName.data() + " (Vulkan 1.0 only; 1.1 needed);";
        continue;
      }
      if (!devices[i].getFeatures().shaderInt64) {
        rejected += std::string(" ") + props.deviceName.data() + " (no shaderInt64);";
        continue;
      }
      if (!computeQueueFamily(devices[i])) {
        rejected += std::string(" ") + props.deviceName.data() + " (no compute queue);";
        continue;
      }
      if (!best ||
          deviceRank(props.deviceType) < deviceRank(devices[*best].getProperties().deviceType))
        best = i;
    }
    if (!best)
      throw BackendUnavailable("vulkan: no usable device among " + std::to_string(devices.size()) +
                               ":" + rejected + " (mesa-vulkan-drivers provides lavapipe)");
    physical_ = std::move(devices[*best]);
    const auto props = physical_.getProperties();
    is_gpu_ = deviceIsGpu(props.deviceType);
    // Integrated GPUs and CPU implementations share memory with the host: map it directly.
    // FVP_VULKAN_STAGING=1 forces the discrete-GPU path (tests run it on any device).
    const char* force_staging = std::getenv("FVP_VULKAN_STAGING");
    unified_memory_ = props.deviceType != vk::PhysicalDeviceType::eDiscreteGpu &&
                      !(force_staging && std::string(force_staging) == "1");
    max_allocation_bytes_ = physical_
                                .getProperties2<vk::PhysicalDeviceProperties2,
                                                vk::PhysicalDeviceMaintenance3Properties>()
                                .get<vk::PhysicalDeviceMaintenance3Properties>()
                                .maxMemoryAllocationSize;
    device_name_ = std::string(props.deviceName.data()) + " (Vulkan " +
                   std::to_string(VK_API_VERSION_MAJOR(props.apiVersion)) + "." +
                   std::to_string(VK_API_VERSION_MINOR(props.apiVersion)) + ")";
    limits_ = props.limits;
    memory_props_ = physical_.getMemoryProperties();
    queue_family_ = *computeQueueFamily(physical_);
  }

  static std::optional<uint32_t> computeQueueFamily(const vk::raii::PhysicalDevice& device) {
    const auto families = device.getQueueFamilyProperties();
    for (uint32_t i = 0; i < families.size(); ++i)
      if (families[i].queueFlags & vk::QueueFlagBits::eCompute) return i;
    return std::nullopt;
  }

  void createDevice() {
    const float priority = 1.0f;
    vk::DeviceQueueCreateInfo queue_info({}, queue_family_, 1, &priority);
    vk::PhysicalDeviceFeatures features;
    features.shaderInt64 = VK_TRUE;  // the exact DDA walks in 64-bit integers
    device_ = FVP_VK(
        vk::raii::Device(physical_, vk::DeviceCreateInfo({}, queue_info, {}, {}, &features)));
    queue_ = FVP_VK(vk::raii::Queue(device_, queue_family_, 0));
    command_pool_ = FVP_VK(vk::raii::CommandPool(
        device_, vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eResetCommandBuffer,
                                           queue_family_)));
    vk::raii::CommandBuffers buffers = FVP_VK(vk::raii::CommandBuffers(
        device_,
        vk::CommandBufferAllocateInfo(*command_pool_, vk::CommandBufferLevel::ePrimary, 1)));
    command_buffer_ = std::move(buffers.front());
    fence_ = FVP_VK(vk::raii::Fence(device_, vk::FenceCreateInfo()));
    // A submission's dispatches: each its buffers' set and its parameter buffer's set.
    vk::DescriptorPoolSize pool_size(vk::DescriptorType::eStorageBuffer, kPoolDescriptors);
    descriptor_pool_ = FVP_VK(vk::raii::DescriptorPool(
        device_, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet,
                                              2 * kDispatchesPerSubmission, pool_size)));
    work_group_size_ = std::min({kPreferredWorkGroupSize, limits_.maxComputeWorkGroupSize[0],
                                 limits_.maxComputeWorkGroupInvocations});
  }

  std::optional<uint32_t> findMemoryType(const vk::MemoryRequirements& req,
                                         vk::MemoryPropertyFlags wanted) const {
    for (uint32_t i = 0; i < memory_props_.memoryTypeCount; ++i)
      if ((req.memoryTypeBits & (1u << i)) &&
          (memory_props_.memoryTypes[i].propertyFlags & wanted) == wanted)
        return i;
    return std::nullopt;
  }

  ComputePipeline createPipeline(const KernelDescriptor& kernel) {
    ComputePipeline p;
    // FVP_VULKAN_PARAMS_IN_BUFFER=1 forces the path of devices with little push-constant
    // space (tests run it on any device).
    const char* force_buffer = std::getenv("FVP_VULKAN_PARAMS_IN_BUFFER");
    p.params_in_buffer =
        kDispatchHeaderBytes + kernel.params_bytes > limits_.maxPushConstantsSize ||
        (force_buffer && std::string(force_buffer) == "1");
    const SpirvCode& code =
        p.params_in_buffer ? kernel.spirv_params_buffer : kernel.spirv_push_constants;
    if (!code.words)
      throw BackendError("vulkan: kernel " + std::string(kernel.name) +
                         " has no SPIR-V in this build");
    if (kernel.bindings.size() >= kPoolDescriptors / kDispatchesPerSubmission)
      throw BackendError("vulkan: kernel " + std::string(kernel.name) + " binds " +
                         std::to_string(kernel.bindings.size()) +
                         " buffers; the descriptor pool allows 15 a dispatch");
    std::vector<vk::DescriptorSetLayoutBinding> bindings;
    for (uint32_t b = 0; b < kernel.bindings.size(); ++b)
      bindings.emplace_back(b, vk::DescriptorType::eStorageBuffer, 1,
                            vk::ShaderStageFlagBits::eCompute);
    p.set_layout = FVP_VK(
        vk::raii::DescriptorSetLayout(device_, vk::DescriptorSetLayoutCreateInfo({}, bindings)));
    std::vector<vk::DescriptorSetLayout> set_layouts{*p.set_layout};
    if (p.params_in_buffer) {
      vk::DescriptorSetLayoutBinding params_binding(0, vk::DescriptorType::eStorageBuffer, 1,
                                                    vk::ShaderStageFlagBits::eCompute);
      p.params_set_layout = FVP_VK(vk::raii::DescriptorSetLayout(
          device_, vk::DescriptorSetLayoutCreateInfo({}, params_binding)));
      set_layouts.push_back(*p.params_set_layout);
    }
    const uint32_t push_bytes =
        kDispatchHeaderBytes +
        (p.params_in_buffer ? 0 : static_cast<uint32_t>(kernel.params_bytes));
    vk::PushConstantRange push(vk::ShaderStageFlagBits::eCompute, 0, push_bytes);
    p.layout = FVP_VK(
        vk::raii::PipelineLayout(device_, vk::PipelineLayoutCreateInfo({}, set_layouts, push)));
    p.module = FVP_VK(
        vk::raii::ShaderModule(device_, vk::ShaderModuleCreateInfo({}, code.bytes, code.words)));
    vk::SpecializationMapEntry entry(0, 0, sizeof(uint32_t));
    vk::SpecializationInfo spec(1, &entry, sizeof(work_group_size_), &work_group_size_);
    vk::PipelineShaderStageCreateInfo stage({}, vk::ShaderStageFlagBits::eCompute, *p.module,
                                            "main", &spec);
    p.pipeline = FVP_VK(
        vk::raii::Pipeline(device_, nullptr, vk::ComputePipelineCreateInfo({}, stage, *p.layout)));
    return p;
  }

  template <typename Record>
  void submit(Record&& record) {
    const vk::raii::CommandBuffer& cmd = command_buffer_;
    FVP_VK(cmd.reset());
    FVP_VK(cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit)));
    // Earlier submissions' device writes must be visible to this one's reads and writes:
    // a fence wait only makes them available.
    vk::MemoryBarrier from_before(
        vk::AccessFlagBits::eShaderWrite | vk::AccessFlagBits::eTransferWrite,
        vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite |
            vk::AccessFlagBits::eTransferRead | vk::AccessFlagBits::eTransferWrite);
    const auto stages =
        vk::PipelineStageFlagBits::eComputeShader | vk::PipelineStageFlagBits::eTransfer;
    cmd.pipelineBarrier(stages, stages, {}, from_before, {}, {});
    record(cmd);
    // Make shader and transfer writes visible to the host reads that follow the fence.
    vk::MemoryBarrier to_host(vk::AccessFlagBits::eShaderWrite | vk::AccessFlagBits::eTransferWrite,
                              vk::AccessFlagBits::eHostRead);
    cmd.pipelineBarrier(
        vk::PipelineStageFlagBits::eComputeShader | vk::PipelineStageFlagBits::eTransfer,
        vk::PipelineStageFlagBits::eHost, {}, to_host, {}, {});
    FVP_VK(cmd.end());
    vk::CommandBuffer handle = *cmd;
    countDeviceWait();
    FVP_VK(queue_.submit(vk::SubmitInfo({}, {}, handle), *fence_));
    const vk::Result waited = FVP_VK(device_.waitForFences(*fence_, VK_TRUE, UINT64_MAX));
    if (waited != vk::Result::eSuccess)
      throw BackendError("vulkan: waitForFences returned " + vk::to_string(waited));
    FVP_VK(device_.resetFences(*fence_));
  }

  vk::DescriptorBufferInfo bufferInfo(const DeviceBuffer& b) const {
    if (b.sizeBytes() > limits_.maxStorageBufferRange)
      throw BackendError("vulkan: a buffer of " + std::to_string(b.sizeBytes()) +
                         " bytes exceeds the device's maxStorageBufferRange (" +
                         std::to_string(limits_.maxStorageBufferRange) + ")");
    return vk::DescriptorBufferInfo(vkBuf(b).get(), 0, VK_WHOLE_SIZE);
  }

  // A dispatch ready to record: its pipeline, descriptor sets (held until the fence) and
  // push constants ({first_item, item_count} then, when they fit, the parameters).
  struct BoundDispatch {
    const ComputePipeline* pipeline = nullptr;
    vk::raii::DescriptorSets sets{nullptr};
    std::vector<vk::DescriptorSet> set_handles;
    std::vector<std::byte> push;
    uint32_t items = 0;
  };

  BoundDispatch bindDispatch(const KernelDescriptor& kernel, const void* params,
                             std::span<DeviceBuffer* const> buffers, uint32_t items,
                             const DeviceBuffer* params_buffer) {
    BoundDispatch d;
    const ComputePipeline& p = pipelines_.at(&kernel);
    d.pipeline = &p;
    d.items = items;
    std::vector<vk::DescriptorSetLayout> layouts{*p.set_layout};
    if (p.params_in_buffer) layouts.push_back(*p.params_set_layout);
    d.sets = FVP_VK(vk::raii::DescriptorSets(
        device_, vk::DescriptorSetAllocateInfo(*descriptor_pool_, layouts)));
    std::vector<vk::DescriptorBufferInfo> infos;
    for (const DeviceBuffer* b : buffers) infos.push_back(bufferInfo(b ? *b : *unused_));
    if (p.params_in_buffer) infos.push_back(bufferInfo(*params_buffer));
    std::vector<vk::WriteDescriptorSet> writes;
    for (uint32_t i = 0; i < buffers.size(); ++i)
      writes.emplace_back(*d.sets[0], i, 0, 1, vk::DescriptorType::eStorageBuffer, nullptr,
                          &infos[i]);
    if (p.params_in_buffer)
      writes.emplace_back(*d.sets[1], 0, 0, 1, vk::DescriptorType::eStorageBuffer, nullptr,
                          &infos.back());
    device_.updateDescriptorSets(writes, {});
    for (const auto& set : d.sets) d.set_handles.push_back(*set);
    d.push.resize(kDispatchHeaderBytes + (p.params_in_buffer ? 0 : kernel.params_bytes));
    std::memcpy(d.push.data() + sizeof(uint32_t), &items, sizeof(uint32_t));
    if (!p.params_in_buffer)
      std::memcpy(d.push.data() + kDispatchHeaderBytes, params, kernel.params_bytes);
    return d;
  }

  // Records one pipeline over its work items, chunked so that no dispatch exceeds the
  // device's work-group count limit; the push constants carry each chunk's first item.
  void recordDispatch(const vk::raii::CommandBuffer& cmd, BoundDispatch& d) {
    const ComputePipeline& p = *d.pipeline;
    const uint64_t chunk = uint64_t{limits_.maxComputeWorkGroupCount[0]} * work_group_size_;
    cmd.bindPipeline(vk::PipelineBindPoint::eCompute, *p.pipeline);
    cmd.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *p.layout, 0, d.set_handles, {});
    for (uint64_t start = 0; start < d.items; start += chunk) {
      const uint64_t n = std::min<uint64_t>(chunk, d.items - start);
      const auto first = static_cast<uint32_t>(start);
      std::memcpy(d.push.data(), &first, sizeof(uint32_t));
      cmd.pushConstants<std::byte>(*p.layout, vk::ShaderStageFlagBits::eCompute, 0, d.push);
      cmd.dispatch(static_cast<uint32_t>((n + work_group_size_ - 1) / work_group_size_), 1, 1);
    }
  }

  // Every operation's earlier device writes visible to the next one's reads and writes.
  static void recordOrderBarrier(const vk::raii::CommandBuffer& cmd) {
    const auto access = vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite |
                        vk::AccessFlagBits::eTransferRead | vk::AccessFlagBits::eTransferWrite;
    const auto stages =
        vk::PipelineStageFlagBits::eComputeShader | vk::PipelineStageFlagBits::eTransfer;
    cmd.pipelineBarrier(stages, stages, {}, vk::MemoryBarrier(access, access), {}, {});
  }

  static bool references(const SequenceOp& op, const DeviceBuffer* buf) {
    return op.buffer == buf ||
           std::find(op.buffers.begin(), op.buffers.end(), buf) != op.buffers.end();
  }
  static bool writes(const SequenceOp& op, const DeviceBuffer* buf) {
    if (op.kind == SequenceOp::Kind::kUpload) return op.buffer == buf;
    if (op.kind != SequenceOp::Kind::kDispatch) return false;
    for (std::size_t b = 0; b < op.buffers.size(); ++b)
      if (op.buffers[b] == buf && op.kernel->bindings[b].access != Access::kRead) return true;
    return false;
  }

  // Which transfers of a part go straight through mapped memory (unified memory), skipping
  // the staging copy: an upload to a buffer no earlier operation of the part touches (the
  // host writes it before the submission), a download from a buffer no later operation
  // writes (the host reads it after the fence).
  std::vector<char> directTransfers(std::span<const SequenceOp> ops) const {
    std::vector<char> direct(ops.size(), 0);
    for (std::size_t i = 0; i < ops.size(); ++i) {
      const SequenceOp& op = ops[i];
      if (op.kind == SequenceOp::Kind::kDispatch || !vkBuf(*op.buffer).mapped()) continue;
      if (op.kind == SequenceOp::Kind::kUpload)
        direct[i] = std::none_of(ops.begin(), ops.begin() + i,
                                 [&](const SequenceOp& o) { return references(o, op.buffer); });
      else
        direct[i] = std::none_of(ops.begin() + i + 1, ops.end(),
                                 [&](const SequenceOp& o) { return writes(o, op.buffer); });
    }
    return direct;
  }

  void runSequencePart(std::span<const SequenceOp> ops) {
    const std::vector<char> direct = directTransfers(ops);
    // Only mapped copies (unified memory): no command to submit, nothing to wait for.
    if (std::all_of(ops.begin(), ops.end(), [&](const SequenceOp& op) {
          return direct[std::size_t(&op - ops.data())] != 0;
        })) {
      for (const SequenceOp& op : ops) {
        std::byte* mapped = vkBuf(*op.buffer).mapped() + op.offset_bytes;
        if (op.kind == SequenceOp::Kind::kUpload)
          std::memcpy(mapped, op.src, op.size_bytes);
        else
          std::memcpy(op.dst, mapped, op.size_bytes);
      }
      return;
    }
    std::size_t up_bytes = 0, down_bytes = 0;
    for (std::size_t i = 0; i < ops.size(); ++i) {
      const SequenceOp& op = ops[i];
      if (op.kind == SequenceOp::Kind::kUpload && !direct[i]) up_bytes += op.size_bytes;
      if (op.kind == SequenceOp::Kind::kDownload && !direct[i]) down_bytes += op.size_bytes;
      if (op.kind == SequenceOp::Kind::kDispatch && pipelines_.at(op.kernel).params_in_buffer)
        up_bytes += op.kernel->params_bytes;
    }
    const VkBuffer* up =
        up_bytes ? &stagingBuffer(staging_upload_, up_bytes, Placement::kStagingUpload) : nullptr;
    const VkBuffer* down =
        down_bytes ? &stagingBuffer(staging_download_, down_bytes, Placement::kStagingDownload)
                   : nullptr;
    std::vector<std::unique_ptr<DeviceBuffer>> params_buffers;
    std::vector<BoundDispatch> bound;
    bound.reserve(ops.size());
    // Downloads read after the fence: their source (mapped buffer or staging) and offset.
    std::vector<std::tuple<const std::byte*, const SequenceOp*>> downloads;
    submit([&](const vk::raii::CommandBuffer& cmd) {
      std::size_t up_at = 0, down_at = 0;
      auto stage_upload = [&](const VkBuffer& dst, const void* src, std::size_t n, std::size_t at) {
        std::memcpy(up->mapped() + up_at, src, n);
        cmd.copyBuffer(up->get(), dst.get(), vk::BufferCopy(up_at, at, n));
        up_at += n;
      };
      for (std::size_t i = 0; i < ops.size(); ++i) {
        const SequenceOp& op = ops[i];
        if (i > 0) recordOrderBarrier(cmd);
        if (direct[i] && op.kind == SequenceOp::Kind::kUpload) {
          std::memcpy(vkBuf(*op.buffer).mapped() + op.offset_bytes, op.src, op.size_bytes);
        } else if (direct[i]) {
          downloads.emplace_back(vkBuf(*op.buffer).mapped() + op.offset_bytes, &op);
        } else if (op.kind == SequenceOp::Kind::kUpload) {
          stage_upload(vkBuf(*op.buffer), op.src, op.size_bytes, op.offset_bytes);
        } else if (op.kind == SequenceOp::Kind::kDownload) {
          cmd.copyBuffer(vkBuf(*op.buffer).get(), down->get(),
                         vk::BufferCopy(op.offset_bytes, down_at, op.size_bytes));
          downloads.emplace_back(down->mapped() + down_at, &op);
          down_at += op.size_bytes;
        } else {
          const DeviceBuffer* params_buffer = nullptr;
          if (pipelines_.at(op.kernel).params_in_buffer) {
            params_buffers.push_back(createBuffer(op.kernel->params_bytes));
            params_buffer = params_buffers.back().get();
            stage_upload(vkBuf(*params_buffer), op.bytes.data(), op.bytes.size(), 0);
            recordOrderBarrier(cmd);
          }
          bound.push_back(
              bindDispatch(*op.kernel, op.bytes.data(), op.buffers, op.item_count, params_buffer));
          recordDispatch(cmd, bound.back());
        }
      }
    });
    for (const auto& [from, op] : downloads) std::memcpy(op->dst, from, op->size_bytes);
  }

  vk::raii::Context context_;
  vk::raii::Instance instance_{nullptr};
  vk::raii::PhysicalDevice physical_{nullptr};
  vk::PhysicalDeviceLimits limits_;
  vk::PhysicalDeviceMemoryProperties memory_props_;
  uint32_t queue_family_ = 0;
  bool is_gpu_ = false;
  bool unified_memory_ = false;
  vk::DeviceSize max_allocation_bytes_ = 0;
  std::string device_name_;
  vk::raii::Device device_{nullptr};
  vk::raii::Queue queue_{nullptr};
  vk::raii::CommandPool command_pool_{nullptr};
  vk::raii::CommandBuffer command_buffer_{nullptr};
  vk::raii::Fence fence_{nullptr};
  vk::raii::DescriptorPool descriptor_pool_{nullptr};
  uint32_t work_group_size_ = 1;
  std::map<const KernelDescriptor*, ComputePipeline> pipelines_;
  std::unique_ptr<DeviceBuffer> unused_;
  std::unique_ptr<DeviceBuffer> staging_upload_, staging_download_;
};

}  // namespace

std::unique_ptr<Backend> createVulkanBackend() {
  return std::make_unique<VulkanBackend>();
}

bool vulkanDeviceIsGpu(const Backend& backend) {
  return static_cast<const VulkanBackend&>(backend).isGpu();
}

}  // namespace fvp::accel::detail
