// Factories of the concrete backends; only backend.cpp calls them.
#pragma once

#include <memory>

#include "fvp/accel/backend.h"

namespace fvp::accel::detail {

std::unique_ptr<Backend> createCpuBackend();
#ifdef FVP_WITH_OPENCL
/// Throws BackendUnavailable when there is no OpenCL platform or device.
std::unique_ptr<Backend> createOpenClBackend();
bool openClDeviceIsGpu(const Backend& backend);
#endif
#ifdef FVP_WITH_VULKAN
/// Throws BackendUnavailable when there is no Vulkan driver or suitable device.
std::unique_ptr<Backend> createVulkanBackend();
bool vulkanDeviceIsGpu(const Backend& backend);
#endif

}  // namespace fvp::accel::detail
