// The compute-backend interface. Three implementations: cpu (plain multithreaded C++,
// the reference and test oracle), opencl and vulkan. GPU work is explicit: the caller
// creates device buffers, uploads, dispatches kernels on buffers and downloads; each
// dispatch returns when its results are ready, and a Sequence (fvp/accel/sequence.h) runs
// many operations as one submission.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "fvp/accel/backend_choice.h"
#include "fvp/accel/kernel.h"
#include "fvp/accel/kernel_types.h"
#include "fvp/accel/sequence_op.h"

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

/// A contiguous byte range of a buffer (Backend::uploadRanges).
struct ByteRange {
  std::size_t offset_bytes = 0;
  std::size_t size_bytes = 0;
};

/// Bytes and calls between host and device through Backend::upload / download.
struct TransferCounters {
  std::uint64_t upload_bytes = 0, download_bytes = 0;
  std::uint64_t uploads = 0, downloads = 0;
};

class Sequence;

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
  /// Sparse update of a buffer the host mirrors: copies each range of the host image
  /// (src_image + offset) to the same offset of buf, as one transfer (one staging copy and
  /// one submission on Vulkan, one wait on OpenCL) however many ranges there are. Counts as
  /// one upload. Throws std::out_of_range if a range does not fit the buffer.
  void uploadRanges(DeviceBuffer& buf, const void* src_image, std::span<const ByteRange> ranges);
  /// What upload() and download() moved since construction or resetTransfers() (buffer
  /// creation from host data counts as an upload).
  TransferCounters transfers() const;
  void resetTransfers();
  /// Times the host has waited for the device since construction: Vulkan queue submissions
  /// (each waits on its fence), OpenCL blocking transfers and finishes; 0 on the cpu
  /// backend. A Sequence waits once (on Vulkan once per 32 dispatches or 64 MB of
  /// transfers, and not at all where its transfers all go through mapped memory).
  std::uint64_t deviceWaits() const { return device_waits_.load(); }

  /// Runs a kernel (fvp/accel/kernels.h) over the work items its parameters define, with
  /// buffers in the kernel's binding order; returns when its results are ready. A buffer
  /// may be null where the binding is unused for these parameters. Throws
  /// std::invalid_argument for a wrong buffer count, bad parameters or a null buffer that
  /// is used, and std::out_of_range for a buffer too small for its binding.
  template <typename Params>
  void run(Kernel<Params> kernel, const Params& params,
           std::initializer_list<DeviceBuffer*> buffers) {
    dispatch(*kernel.descriptor, &params, sizeof(Params),
             std::span<DeviceBuffer* const>(buffers.begin(), buffers.size()));
  }
  /// The untyped form of run(): params_bytes must equal the descriptor's.
  void dispatch(const KernelDescriptor& kernel, const void* params, std::size_t params_bytes,
                std::span<DeviceBuffer* const> buffers);

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

 private:
  friend class Sequence;
  /// Checks a dispatch's arguments (see run()); returns its work items.
  std::uint32_t checkDispatch(const KernelDescriptor& kernel, const void* params,
                              std::size_t params_bytes, std::span<DeviceBuffer* const> buffers);
  /// Counts a sequence's transfers and runs it (runSequence).
  void evaluate(std::span<const SequenceOp> ops);

  std::atomic<std::uint64_t> upload_bytes_{0}, download_bytes_{0}, uploads_{0}, downloads_{0};
  std::atomic<std::uint64_t> device_waits_{0};

 protected:
  // Implementations: arguments are validated by the public twins above; size_bytes > 0.
  virtual void uploadBytes(DeviceBuffer& buf, const void* src, std::size_t size_bytes,
                           std::size_t offset_bytes) = 0;
  virtual void downloadBytes(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                             std::size_t offset_bytes) = 0;
  /// Ranges are checked and non-empty. The default copies them one by one (uploadBytes).
  virtual void uploadRangesBytes(DeviceBuffer& buf, const void* src_image,
                                 std::span<const ByteRange> ranges);
  /// Runs item_count > 0 work items; arguments are checked (Backend::dispatch). Buffers
  /// unused by this dispatch are null.
  virtual void dispatchKernel(const KernelDescriptor& kernel, const void* params,
                              std::span<DeviceBuffer* const> buffers, std::uint32_t item_count) = 0;
  /// Runs a sequence's operations in order (checked, non-empty) and returns when all are
  /// done. The default runs them one by one through the calls above.
  virtual void runSequence(std::span<const SequenceOp> ops);
  void countDeviceWait() { ++device_waits_; }
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

/// The chosen backend. kAuto picks a GPU device (OpenCL first, then Vulkan) when one exists,
/// else the CPU reference. Throws BackendUnavailable for an explicitly chosen backend that
/// cannot run (never a silent fallback).
std::unique_ptr<Backend> createBackend(BackendChoice choice);

/// createBackend(parseBackendChoice(name)); throws std::invalid_argument for an unknown name.
std::unique_ptr<Backend> createBackend(std::string_view name);

}  // namespace fvp::accel
