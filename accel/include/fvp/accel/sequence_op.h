// One operation of a recorded Sequence (fvp/accel/sequence.h), as the backends receive it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "fvp/accel/kernel.h"

namespace fvp::accel {

class DeviceBuffer;

struct SequenceOp {
  enum class Kind { kUpload, kDispatch, kDownload };
  Kind kind = Kind::kDispatch;
  /// kDispatch: the kernel, its parameter block (bytes), its buffers in binding order (null
  /// where unused) and its work items (> 0).
  const KernelDescriptor* kernel = nullptr;
  std::vector<DeviceBuffer*> buffers;
  std::uint32_t item_count = 0;
  /// kDispatch: the parameter block, copied when recorded.
  std::vector<std::byte> bytes;
  /// kUpload: the caller's data, read when the sequence runs.
  const void* src = nullptr;
  /// kUpload / kDownload: the device buffer and its byte range (size > 0, checked).
  DeviceBuffer* buffer = nullptr;
  std::size_t offset_bytes = 0, size_bytes = 0;
  /// kDownload: where the bytes go once the sequence has run.
  void* dst = nullptr;
};

}  // namespace fvp::accel
