#include "fvp/accel/backend.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "backends.h"
#include "fvp/accel/sequence.h"

namespace fvp::accel {

std::string_view toString(BackendKind kind) {
  switch (kind) {
    case BackendKind::kCpu:
      return "cpu";
    case BackendKind::kOpenCl:
      return "opencl";
    case BackendKind::kVulkan:
      return "vulkan";
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
  if (!size_bytes) return;
  uploadBytes(buf, src, size_bytes, offset_bytes);
  upload_bytes_ += size_bytes;
  ++uploads_;
}

void Backend::download(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                       std::size_t offset_bytes) {
  checkRange(buf, size_bytes, offset_bytes, "download");
  if (!size_bytes) return;
  downloadBytes(buf, dst, size_bytes, offset_bytes);
  download_bytes_ += size_bytes;
  ++downloads_;
}

void Backend::uploadRanges(DeviceBuffer& buf, const void* src_image,
                           std::span<const ByteRange> ranges) {
  std::vector<ByteRange> nonempty;
  for (const ByteRange& r : ranges) {
    checkRange(buf, r.size_bytes, r.offset_bytes, "uploadRanges");
    if (r.size_bytes) nonempty.push_back(r);
  }
  if (nonempty.empty()) return;
  // Sorted and merged: the backends get disjoint ranges (Vulkan's vkCmdCopyBuffer forbids
  // overlapping destination regions), and the byte count is what is sent.
  std::sort(nonempty.begin(), nonempty.end(),
            [](const ByteRange& a, const ByteRange& b) { return a.offset_bytes < b.offset_bytes; });
  std::vector<ByteRange> disjoint{nonempty.front()};
  for (std::size_t i = 1; i < nonempty.size(); ++i) {
    ByteRange& last = disjoint.back();
    const std::size_t last_end = last.offset_bytes + last.size_bytes;
    if (nonempty[i].offset_bytes <= last_end)
      last.size_bytes =
          std::max(last_end, nonempty[i].offset_bytes + nonempty[i].size_bytes) - last.offset_bytes;
    else
      disjoint.push_back(nonempty[i]);
  }
  std::size_t bytes = 0;
  for (const ByteRange& r : disjoint) bytes += r.size_bytes;
  uploadRangesBytes(buf, src_image, disjoint);
  upload_bytes_ += bytes;
  ++uploads_;
}

void Backend::uploadRangesBytes(DeviceBuffer& buf, const void* src_image,
                                std::span<const ByteRange> ranges) {
  const auto* image = static_cast<const std::uint8_t*>(src_image);
  for (const ByteRange& r : ranges)
    uploadBytes(buf, image + r.offset_bytes, r.size_bytes, r.offset_bytes);
}

TransferCounters Backend::transfers() const {
  return {upload_bytes_.load(), download_bytes_.load(), uploads_.load(), downloads_.load()};
}

void Backend::resetTransfers() {
  upload_bytes_ = download_bytes_ = uploads_ = downloads_ = 0;
}

std::uint32_t Backend::checkDispatch(const KernelDescriptor& kernel, const void* params,
                                     std::size_t params_bytes,
                                     std::span<DeviceBuffer* const> buffers) {
  const std::string name(kernel.name);
  if (params_bytes != kernel.params_bytes)
    throw std::invalid_argument(name + ": parameter block of " + std::to_string(params_bytes) +
                                " bytes, the kernel takes " + std::to_string(kernel.params_bytes));
  if (buffers.size() != kernel.bindings.size())
    throw std::invalid_argument(name + ": " + std::to_string(buffers.size()) +
                                " buffers given, the kernel binds " +
                                std::to_string(kernel.bindings.size()));
  if (kernel.validate) kernel.validate(params);
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    const KernelBinding& binding = kernel.bindings[i];
    const std::size_t needed = binding.required_elements(params);
    const std::string what =
        name + ": binding " + std::to_string(i) + " (" + std::string(binding.name) + ")";
    if (!buffers[i]) {
      if (needed)
        throw std::invalid_argument(what + " is used by this dispatch but no buffer was given");
      continue;
    }
    checkRange(*buffers[i], needed * binding.element_bytes, 0, what.c_str());
  }
  return kernel.item_count(params);
}

void Backend::dispatch(const KernelDescriptor& kernel, const void* params, std::size_t params_bytes,
                       std::span<DeviceBuffer* const> buffers) {
  const std::uint32_t items = checkDispatch(kernel, params, params_bytes, buffers);
  if (items) dispatchKernel(kernel, params, buffers, items);
}

void Backend::evaluate(std::span<const SequenceOp> ops) {
  if (ops.empty()) return;
  runSequence(ops);
  for (const SequenceOp& op : ops) {
    if (op.kind == SequenceOp::Kind::kUpload) upload_bytes_ += op.size_bytes, ++uploads_;
    if (op.kind == SequenceOp::Kind::kDownload) download_bytes_ += op.size_bytes, ++downloads_;
  }
}

void Backend::runSequence(std::span<const SequenceOp> ops) {
  for (const SequenceOp& op : ops) switch (op.kind) {
      case SequenceOp::Kind::kUpload:
        uploadBytes(*op.buffer, op.src, op.size_bytes, op.offset_bytes);
        break;
      case SequenceOp::Kind::kDispatch:
        dispatchKernel(*op.kernel, op.bytes.data(), op.buffers, op.item_count);
        break;
      case SequenceOp::Kind::kDownload:
        downloadBytes(*op.buffer, op.dst, op.size_bytes, op.offset_bytes);
        break;
    }
}

Sequence& Sequence::dispatch(const KernelDescriptor& kernel, const void* params,
                             std::size_t params_bytes, std::span<DeviceBuffer* const> buffers) {
  const std::uint32_t items = backend_.checkDispatch(kernel, params, params_bytes, buffers);
  if (!items) return *this;
  SequenceOp op;
  op.kind = SequenceOp::Kind::kDispatch;
  op.kernel = &kernel;
  op.buffers.assign(buffers.begin(), buffers.end());
  op.item_count = items;
  const auto* bytes = static_cast<const std::byte*>(params);
  op.bytes.assign(bytes, bytes + params_bytes);
  ops_.push_back(std::move(op));
  return *this;
}

Sequence& Sequence::upload(DeviceBuffer& buf, const void* src, std::size_t size_bytes,
                           std::size_t offset_bytes) {
  checkRange(buf, size_bytes, offset_bytes, "Sequence::upload");
  if (!size_bytes) return *this;
  SequenceOp op;
  op.kind = SequenceOp::Kind::kUpload;
  op.buffer = &buf;
  op.offset_bytes = offset_bytes;
  op.size_bytes = size_bytes;
  op.src = src;
  ops_.push_back(std::move(op));
  return *this;
}

Sequence& Sequence::download(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                             std::size_t offset_bytes) {
  checkRange(buf, size_bytes, offset_bytes, "Sequence::download");
  if (!size_bytes) return *this;
  SequenceOp op;
  op.kind = SequenceOp::Kind::kDownload;
  // Downloads only read the buffer; the op's one buffer field is not const for uploads.
  op.buffer = const_cast<DeviceBuffer*>(&buf);
  op.offset_bytes = offset_bytes;
  op.size_bytes = size_bytes;
  op.dst = dst;
  ops_.push_back(std::move(op));
  return *this;
}

void Sequence::eval() {
  std::vector<SequenceOp> ops;
  ops.swap(ops_);  // empty afterwards, also when a backend throws
  backend_.evaluate(ops);
}

std::unique_ptr<Backend> createBackend(BackendKind kind) {
  switch (kind) {
    case BackendKind::kCpu:
      return detail::createCpuBackend();
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

std::unique_ptr<Backend> createBackend(BackendChoice choice) {
  switch (choice) {
    case BackendChoice::kCpu:
      return createBackend(BackendKind::kCpu);
    case BackendChoice::kOpenCl:
      return createBackend(BackendKind::kOpenCl);
    case BackendChoice::kVulkan:
      return createBackend(BackendKind::kVulkan);
    case BackendChoice::kAuto:
      break;
  }
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

std::unique_ptr<Backend> createBackend(std::string_view name) {
  const auto choice = parseBackendChoice(name);
  if (!choice)
    throw std::invalid_argument("unknown backend '" + std::string(name) + "': expected one of " +
                                backendChoiceNames());
  return createBackend(*choice);
}

}  // namespace fvp::accel
