// GPU work as explicit recorded operations, run as one submission (Kompute's Sequence):
// uploads, kernel dispatches and downloads are recorded in order, then eval() runs them and
// returns when every result is ready. On Vulkan that is one command buffer with a barrier
// between operations and one fence wait (per 32 dispatches or 64 MB of transfers); on
// OpenCL, non-blocking commands on the in-order queue and one finish; on the cpu backend,
// the operations one after another. A submission
// and its wait cost ~0.3-0.5 ms on an H100, so a view's dozens of operations pay it once
// per sequence instead of once per operation.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <span>
#include <vector>

#include "fvp/accel/backend.h"
#include "fvp/accel/sequence_op.h"

namespace fvp::accel {

class Sequence {
 public:
  explicit Sequence(Backend& backend) : backend_(backend) {}

  /// Records a kernel dispatch: checked now as Backend::run checks it (the same exceptions);
  /// the parameters are copied. A dispatch of no work items records nothing.
  template <typename Params>
  Sequence& run(Kernel<Params> kernel, const Params& params,
                std::initializer_list<DeviceBuffer*> buffers) {
    return dispatch(*kernel.descriptor, &params, sizeof(Params),
                    std::span<DeviceBuffer* const>(buffers.begin(), buffers.size()));
  }
  Sequence& dispatch(const KernelDescriptor& kernel, const void* params, std::size_t params_bytes,
                     std::span<DeviceBuffer* const> buffers);
  /// Records a copy of size_bytes of src into buf at offset_bytes. src is read when the
  /// sequence runs (not copied: uploads are a view's largest transfers), so it must stay
  /// valid and unchanged until eval() returns. Throws std::out_of_range if the range does
  /// not fit the buffer.
  Sequence& upload(DeviceBuffer& buf, const void* src, std::size_t size_bytes,
                   std::size_t offset_bytes = 0);
  /// Records a copy of buf's range into dst, which must stay valid until eval() returns and
  /// holds the bytes as the buffer is after the operations recorded before it.
  Sequence& download(const DeviceBuffer& buf, void* dst, std::size_t size_bytes,
                     std::size_t offset_bytes = 0);

  /// Operations recorded and not yet run.
  std::size_t size() const { return ops_.size(); }
  /// Runs the recorded operations in order and returns when all are done; the sequence is
  /// then empty and may record again. Buffers must outlive the call. If it throws, the
  /// buffers' contents are unspecified (operations before the failure may have run).
  void eval();

 private:
  Backend& backend_;
  std::vector<SequenceOp> ops_;
};

}  // namespace fvp::accel
