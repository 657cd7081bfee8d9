// Vulkan backend: GLSL compute shaders from shaders/, compiled to SPIR-V at build time and
// embedded. Prefers a discrete or integrated GPU; falls back to a CPU implementation
// (Mesa lavapipe here). Every dispatch is recorded into a command buffer, submitted and
// waited for with a fence, so results are ready when the call returns.
#include <vulkan/vulkan_raii.hpp>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "backends.h"
#include "check.h"
#include "embedded/spirv_frontier.h"
#include "embedded/spirv_ray_traverse.h"
#include "embedded/spirv_roi_distance.h"
#include "embedded/spirv_scan_integrate.h"

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

bool deviceIsGpu(vk::PhysicalDeviceType type) {
  return type == vk::PhysicalDeviceType::eDiscreteGpu ||
         type == vk::PhysicalDeviceType::eIntegratedGpu;
}

int deviceRank(vk::PhysicalDeviceType type) {
  switch (type) {
    case vk::PhysicalDeviceType::eDiscreteGpu: return 0;
    case vk::PhysicalDeviceType::eIntegratedGpu: return 1;
    case vk::PhysicalDeviceType::eVirtualGpu: return 2;
    case vk::PhysicalDeviceType::eCpu: return 3;
    default: return 4;
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

const VkBuffer& vkBuf(const DeviceBuffer& b) { return static_cast<const VkBuffer&>(b); }

// One compute pipeline: storage buffers at bindings 0..n-1 of set 0, push constants,
// work-group size as specialisation constant 0.
struct ComputePipeline {
  vk::raii::DescriptorSetLayout set_layout{nullptr};
  vk::raii::PipelineLayout layout{nullptr};
  vk::raii::ShaderModule module{nullptr};
  vk::raii::Pipeline pipeline{nullptr};
  uint32_t buffer_count = 0;
  uint32_t push_constant_bytes = 0;
};

class VulkanBackend final : public Backend {
 public:
  VulkanBackend() {
    vk::ApplicationInfo app("fvp", 1, "fvp", 1, VK_API_VERSION_1_1);
    try {
      instance_ = vk::raii::Instance(context_, vk::InstanceCreateInfo({}, &app));
    } catch (const vk::Error& e) {
      throw BackendUnavailable(std::string("vulkan: cannot create an instance (") + e.what() +
                               "); install a driver such as mesa-vulkan-drivers");
    }
    pickDevice();
    createDevice();
    ray_traverse_ = createPipeline(kSpirv_ray_traverse, sizeof(kSpirv_ray_traverse), 4,
                                   sizeof(TraversePushConstants));
    scan_mark_ = createPipeline(kSpirv_scan_integrate, sizeof(kSpirv_scan_integrate), 7,
                                sizeof(ScanPushConstants), /*mode=*/0);
    scan_update_ = createPipeline(kSpirv_scan_integrate, sizeof(kSpirv_scan_integrate), 7,
                                  sizeof(ScanPushConstants), /*mode=*/1);
    roi_distance_ = createPipeline(kSpirv_roi_distance, sizeof(kSpirv_roi_distance), 6,
                                   sizeof(EdtPushConstants));
    frontier_ = createPipeline(kSpirv_frontier, sizeof(kSpirv_frontier), 6,
                               sizeof(FrontierPushConstants));
    // Bound where a pass does not use a binding: every binding needs a valid buffer.
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
    auto staging = allocateBuffer(size_bytes, Placement::kStagingUpload);
    std::memcpy(vkBuf(*staging).mapped(), src, size_bytes);
    submit([&](const vk::raii::CommandBuffer& cmd) {
      cmd.copyBuffer(vkBuf(*staging).get(), dst.get(), vk::BufferCopy(0, offset_bytes, size_bytes));
    });
  }

  void downloadBytes(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                     std::size_t offset_bytes) override {
    const VkBuffer& src = vkBuf(buf);
    if (src.mapped()) {
      std::memcpy(dst, src.mapped() + offset_bytes, size_bytes);
      return;
    }
    auto staging = allocateBuffer(size_bytes, Placement::kStagingDownload);
    submit([&](const vk::raii::CommandBuffer& cmd) {
      cmd.copyBuffer(src.get(), vkBuf(*staging).get(), vk::BufferCopy(offset_bytes, 0, size_bytes));
    });
    std::memcpy(dst, vkBuf(*staging).mapped(), size_bytes);
  }

  void dispatchTraverseRays(const TraverseParams& params, const DeviceBuffer& rays,
                            const DeviceBuffer& occupancy, const DeviceBuffer& field,
                            DeviceBuffer& results) override {
    TraversePushConstants push{params, 0};
    dispatch1D(ray_traverse_, {&rays, &occupancy, &field, &results}, params.ray_count, push,
               push.first_ray);
  }

 public:
  // Packed marks: a byte lane per slot in uint words (atomicOr), see shaders/fvp_map.glsl.
  std::size_t scanMarkBytes(std::size_t slot_count) const override {
    return (slot_count + 3) / 4 * 4;
  }

 protected:
  void dispatchScanMark(const ScanParams& params, const DeviceBuffer& points,
                        const DeviceBuffer& brick_table, DeviceBuffer& marks, DeviceBuffer& missing,
                        std::uint32_t slot_count, std::uint32_t brick_count) override {
    ScanPushConstants push{};
    push.scan = params;
    push.slot_count = slot_count;
    push.brick_count = static_cast<int32_t>(brick_count);
    dispatch1D(scan_mark_, {&points, &brick_table, &marks, &missing, unused_.get(), unused_.get(), unused_.get()},
               params.point_count, push, push.first_item);
  }

  void dispatchScanUpdate(const UpdateParams& params, DeviceBuffer& marks, DeviceBuffer& occupancy,
                          DeviceBuffer& roi, DeviceBuffer& updated) override {
    ScanPushConstants push{};
    push.update = params;
    push.slot_count = params.slot_count;
    dispatch1D(scan_update_, {unused_.get(), unused_.get(), &marks, unused_.get(), &occupancy,
                              params.has_roi ? &roi : unused_.get(), &updated},
               params.slot_count / kUpdateChunkSlots, push, push.first_item);
  }

  void dispatchRoiDistancePass(const EdtParams& params, int axis, const DeviceBuffer& brick_coords,
                               const DeviceBuffer& brick_table, const DeviceBuffer& roi,
                               const DeviceBuffer& sq_in, DeviceBuffer& sq_out,
                               DeviceBuffer& distance_vox) override {
    EdtPushConstants push{params, axis, 0};
    dispatch1D(roi_distance_,
               {&brick_coords, &brick_table, axis == 0 ? &roi : unused_.get(),
                axis > 0 ? &sq_in : unused_.get(), axis < 2 ? &sq_out : unused_.get(),
                axis == 2 ? &distance_vox : unused_.get()},
               params.slot_count, push, push.first_item);
  }

  void dispatchExtractFrontiers(const FrontierParams& params, const DeviceBuffer& brick_coords,
                                const DeviceBuffer& brick_table, const DeviceBuffer& occupancy,
                                const DeviceBuffer& roi, DeviceBuffer& out,
                                DeviceBuffer& count) override {
    FrontierPushConstants push{params, 0};
    dispatch1D(frontier_, {&brick_coords, &brick_table, &occupancy, &roi, &out, &count},
               params.slot_count, push, push.first_item);
  }

 private:
  enum class Placement {
    kUnified,          // integrated GPUs and CPU devices: device memory the host maps
    kDevice,           // discrete GPUs: device-local, filled through staging copies
    kStagingUpload,    // host-visible, coherent
    kStagingDownload,  // host-visible, coherent, cached when available
  };

  std::unique_ptr<DeviceBuffer> allocateBuffer(std::size_t size_bytes, Placement placement) {
    // Vulkan rejects zero-sized buffers; an empty buffer still owns a few bytes.
    const vk::DeviceSize bytes = std::max<std::size_t>(size_bytes, 4);
    if (bytes > max_allocation_bytes_)
      throw BackendError("vulkan: a buffer of " + std::to_string(bytes) +
                         " bytes exceeds the device's maxMemoryAllocationSize (" +
                         std::to_string(max_allocation_bytes_) + ")");
    const auto usage = vk::BufferUsageFlagBits::eStorageBuffer |
                       vk::BufferUsageFlagBits::eTransferSrc | vk::BufferUsageFlagBits::eTransferDst;
    vk::raii::Buffer buffer = FVP_VK(vk::raii::Buffer(device_, vk::BufferCreateInfo({}, bytes, usage)));
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
    if (!type) throw BackendError("vulkan: no suitable memory type for a buffer of " + std::to_string(bytes) + " bytes");
    vk::raii::DeviceMemory memory =
        FVP_VK(vk::raii::DeviceMemory(device_, vk::MemoryAllocateInfo(req.size, *type)));
    FVP_VK(buffer.bindMemory(*memory, 0));
    // Device buffers of discrete GPUs are reached through staging copies only, even where
    // their memory happens to be host-visible.
    void* mapped = nullptr;
    if (placement != Placement::kDevice) mapped = FVP_VK(memory.mapMemory(0, VK_WHOLE_SIZE));
    return std::make_unique<VkBuffer>(size_bytes, std::move(buffer), std::move(memory), mapped);
  }

  // Push-constant blocks: the kernel parameters plus the first work item of a chunk.
  struct TraversePushConstants {
    TraverseParams params;
    uint32_t first_ray;
  };
  struct ScanPushConstants {
    ScanParams scan;
    UpdateParams update;
    uint32_t slot_count;
    int32_t brick_count;
    uint32_t first_item;
  };
  struct EdtPushConstants {
    EdtParams edt;
    int32_t axis;
    uint32_t first_item;
  };
  struct FrontierPushConstants {
    FrontierParams frontier;
    uint32_t first_item;
  };
  static_assert(sizeof(ScanPushConstants) == 116 && sizeof(EdtPushConstants) == 80 &&
                    sizeof(FrontierPushConstants) == 80,
                "must match the shaders' push-constant blocks");

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
      if (!best || deviceRank(props.deviceType) < deviceRank(devices[*best].getProperties().deviceType))
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
    device_ = FVP_VK(vk::raii::Device(physical_, vk::DeviceCreateInfo({}, queue_info, {}, {}, &features)));
    queue_ = FVP_VK(vk::raii::Queue(device_, queue_family_, 0));
    command_pool_ = FVP_VK(vk::raii::CommandPool(
        device_, vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eResetCommandBuffer,
                                           queue_family_)));
    vk::raii::CommandBuffers buffers = FVP_VK(vk::raii::CommandBuffers(
        device_, vk::CommandBufferAllocateInfo(*command_pool_, vk::CommandBufferLevel::ePrimary, 1)));
    command_buffer_ = std::move(buffers.front());
    fence_ = FVP_VK(vk::raii::Fence(device_, vk::FenceCreateInfo()));
    vk::DescriptorPoolSize pool_size(vk::DescriptorType::eStorageBuffer, 16);
    descriptor_pool_ = FVP_VK(vk::raii::DescriptorPool(
        device_, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 4,
                                              pool_size)));
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

  ComputePipeline createPipeline(const uint32_t* spirv, std::size_t spirv_bytes,
                                 uint32_t buffer_count, uint32_t push_constant_bytes,
                                 int32_t mode = 0) {
    ComputePipeline p;
    p.buffer_count = buffer_count;
    p.push_constant_bytes = push_constant_bytes;
    std::vector<vk::DescriptorSetLayoutBinding> bindings;
    for (uint32_t b = 0; b < buffer_count; ++b)
      bindings.emplace_back(b, vk::DescriptorType::eStorageBuffer, 1,
                            vk::ShaderStageFlagBits::eCompute);
    p.set_layout = FVP_VK(vk::raii::DescriptorSetLayout(
        device_, vk::DescriptorSetLayoutCreateInfo({}, bindings)));
    vk::PushConstantRange push(vk::ShaderStageFlagBits::eCompute, 0, push_constant_bytes);
    vk::DescriptorSetLayout set_layout = *p.set_layout;
    p.layout = FVP_VK(vk::raii::PipelineLayout(
        device_, vk::PipelineLayoutCreateInfo({}, set_layout, push)));
    p.module = FVP_VK(vk::raii::ShaderModule(
        device_, vk::ShaderModuleCreateInfo({}, spirv_bytes, spirv)));
    // Specialisation constants: 0 = work-group size, 1 = kernel mode (shaders with several passes).
    const std::array<uint32_t, 2> spec_values{work_group_size_, static_cast<uint32_t>(mode)};
    const std::array<vk::SpecializationMapEntry, 2> entries{
        vk::SpecializationMapEntry(0, 0, sizeof(uint32_t)),
        vk::SpecializationMapEntry(1, sizeof(uint32_t), sizeof(uint32_t))};
    vk::SpecializationInfo spec(static_cast<uint32_t>(entries.size()), entries.data(),
                                sizeof(spec_values), spec_values.data());
    vk::PipelineShaderStageCreateInfo stage({}, vk::ShaderStageFlagBits::eCompute, *p.module,
                                            "main", &spec);
    p.pipeline = FVP_VK(vk::raii::Pipeline(
        device_, nullptr, vk::ComputePipelineCreateInfo({}, stage, *p.layout)));
    return p;
  }

  template <typename Record>
  void submit(Record&& record) {
    const vk::raii::CommandBuffer& cmd = command_buffer_;
    FVP_VK(cmd.reset());
    FVP_VK(cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit)));
    // Earlier submissions' device writes must be visible to this one's reads and writes:
    // a fence wait only makes them available.
    vk::MemoryBarrier from_before(vk::AccessFlagBits::eShaderWrite | vk::AccessFlagBits::eTransferWrite,
                                  vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite |
                                      vk::AccessFlagBits::eTransferRead | vk::AccessFlagBits::eTransferWrite);
    const auto stages = vk::PipelineStageFlagBits::eComputeShader | vk::PipelineStageFlagBits::eTransfer;
    cmd.pipelineBarrier(stages, stages, {}, from_before, {}, {});
    record(cmd);
    // Make shader and transfer writes visible to the host reads that follow the fence.
    vk::MemoryBarrier to_host(vk::AccessFlagBits::eShaderWrite | vk::AccessFlagBits::eTransferWrite,
                              vk::AccessFlagBits::eHostRead);
    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader | vk::PipelineStageFlagBits::eTransfer,
                        vk::PipelineStageFlagBits::eHost, {}, to_host, {}, {});
    FVP_VK(cmd.end());
    vk::CommandBuffer handle = *cmd;
    FVP_VK(queue_.submit(vk::SubmitInfo({}, {}, handle), *fence_));
    const vk::Result waited = FVP_VK(device_.waitForFences(*fence_, VK_TRUE, UINT64_MAX));
    if (waited != vk::Result::eSuccess)
      throw BackendError("vulkan: waitForFences returned " + vk::to_string(waited));
    FVP_VK(device_.resetFences(*fence_));
  }

  // Records one pipeline over `items` work items, chunked so that no dispatch exceeds
  // the device's work-group count limit; `first` (a member of `push`) is set per chunk.
  template <typename Push>
  void dispatch1D(const ComputePipeline& p, std::initializer_list<const DeviceBuffer*> buffers,
                  uint32_t items, Push& push, uint32_t& first) {
    vk::raii::DescriptorSets sets = FVP_VK(vk::raii::DescriptorSets(
        device_, vk::DescriptorSetAllocateInfo(*descriptor_pool_, *p.set_layout)));
    vk::raii::DescriptorSet& set = sets.front();
    std::vector<vk::DescriptorBufferInfo> infos;
    for (const DeviceBuffer* b : buffers) {
      if (b->sizeBytes() > limits_.maxStorageBufferRange)
        throw BackendError("vulkan: a buffer of " + std::to_string(b->sizeBytes()) +
                           " bytes exceeds the device's maxStorageBufferRange (" +
                           std::to_string(limits_.maxStorageBufferRange) + ")");
      infos.emplace_back(vkBuf(*b).get(), 0, VK_WHOLE_SIZE);
    }
    std::vector<vk::WriteDescriptorSet> writes;
    for (uint32_t i = 0; i < infos.size(); ++i)
      writes.emplace_back(*set, i, 0, 1, vk::DescriptorType::eStorageBuffer, nullptr, &infos[i]);
    device_.updateDescriptorSets(writes, {});

    const uint64_t max_groups = limits_.maxComputeWorkGroupCount[0];
    const uint64_t chunk = max_groups * work_group_size_;
    submit([&](const vk::raii::CommandBuffer& cmd) {
      cmd.bindPipeline(vk::PipelineBindPoint::eCompute, *p.pipeline);
      cmd.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *p.layout, 0, *set, {});
      for (uint64_t start = 0; start < items; start += chunk) {
        const uint64_t n = std::min<uint64_t>(chunk, items - start);
        first = static_cast<uint32_t>(start);
        cmd.pushConstants<Push>(*p.layout, vk::ShaderStageFlagBits::eCompute, 0, push);
        cmd.dispatch(static_cast<uint32_t>((n + work_group_size_ - 1) / work_group_size_), 1, 1);
      }
    });
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
  ComputePipeline ray_traverse_, scan_mark_, scan_update_, roi_distance_, frontier_;
  std::unique_ptr<DeviceBuffer> unused_;
};

}  // namespace

std::unique_ptr<Backend> createVulkanBackend() { return std::make_unique<VulkanBackend>(); }

bool vulkanDeviceIsGpu(const Backend& backend) {
  return static_cast<const VulkanBackend&>(backend).isGpu();
}

}  // namespace fvp::accel::detail
