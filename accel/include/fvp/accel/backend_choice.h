// The compute backend a user asks for: one by name, or auto (the best available). Parsed once
// at the edges (command line, Python, manifests); nothing after parsing compares names.
// Header-only: the command line's parse-only fuzz build links no backend.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

namespace fvp::accel {

enum class BackendChoice { kAuto, kCpu, kOpenCl, kVulkan };

inline constexpr std::array<BackendChoice, 4> kBackendChoices = {
    BackendChoice::kAuto, BackendChoice::kCpu, BackendChoice::kOpenCl, BackendChoice::kVulkan};

/// "auto", "cpu", "opencl" or "vulkan".
inline std::string_view toString(BackendChoice choice) {
  switch (choice) {
    case BackendChoice::kAuto:
      return "auto";
    case BackendChoice::kCpu:
      return "cpu";
    case BackendChoice::kOpenCl:
      return "opencl";
    case BackendChoice::kVulkan:
      return "vulkan";
  }
  return "unknown";
}

/// The choice named `name`; none for anything else.
inline std::optional<BackendChoice> parseBackendChoice(std::string_view name) {
  for (const BackendChoice choice : kBackendChoices)
    if (toString(choice) == name) return choice;
  return std::nullopt;
}

/// "auto, cpu, opencl, vulkan" (for messages).
inline std::string backendChoiceNames() {
  std::string names;
  for (const BackendChoice choice : kBackendChoices)
    names += (names.empty() ? "" : ", ") + std::string(toString(choice));
  return names;
}

}  // namespace fvp::accel
