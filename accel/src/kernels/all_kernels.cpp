// The list of every kernel, for backends that build them all up front.
#include "fvp/accel/kernels.h"

namespace fvp::accel {

std::span<const KernelDescriptor* const> allKernels() {
  static const KernelDescriptor* const kAll[] = {
      kernels::rayTraverse().descriptor,   kernels::scanMark().descriptor,
      kernels::scanUpdate().descriptor,    kernels::roiDistance().descriptor,
      kernels::frontier().descriptor,      kernels::infoGain().descriptor,
      kernels::tsdfIntegrate().descriptor, kernels::stereoCensus().descriptor,
      kernels::stereoCost().descriptor,    kernels::stereoAggregate().descriptor,
      kernels::stereoSelect().descriptor};
  return kAll;
}

}  // namespace fvp::accel
