// Checked Embree calls: every rtc* call goes through FVP_RTC, so a failure throws
// accel::BackendError with the call's text, file, line, Embree's error code and the message
// its error callback reported (install detail::embreeErrorCallback on each device).
// Header-only: users link Embree themselves.
#pragma once

#include <embree3/rtcore.h>

#include <string>
#include <type_traits>

#include "fvp/accel/backend.h"

namespace fvp::accel::detail {

/// The last message Embree's error callback reported on this thread.
inline thread_local std::string embree_last_message;

inline void embreeErrorCallback(void* /*user*/, RTCError /*code*/, const char* message) {
  embree_last_message = message != nullptr ? message : "";
}

inline const char* embreeErrorName(RTCError error) {
  switch (error) {
    case RTC_ERROR_NONE:
      return "RTC_ERROR_NONE";
    case RTC_ERROR_UNKNOWN:
      return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION:
      return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED:
      return "RTC_ERROR_CANCELLED";
  }
  return "unknown RTCError";
}

/// Throws when `device` (null: device creation) recorded an error on this thread.
inline void checkEmbree(RTCDevice device, const char* call, const char* file, int line) {
  const RTCError error = rtcGetDeviceError(device);
  if (error == RTC_ERROR_NONE) return;
  std::string message =
      std::string("Embree call failed: ") + call + " -> " + embreeErrorName(error);
  if (!embree_last_message.empty()) message += " (" + embree_last_message + ")";
  message += std::string(" (at ") + file + ":" + std::to_string(line) + ")";
  embree_last_message.clear();
  throw BackendError(message);
}

template <typename Call>
auto checkedEmbreeCall(RTCDevice device, const char* text, const char* file, int line,
                       Call&& call) {
  if constexpr (std::is_void_v<decltype(call())>) {
    call();
    checkEmbree(device, text, file, line);
  } else {
    auto result = call();
    checkEmbree(device, text, file, line);
    return result;
  }
}

}  // namespace fvp::accel::detail

/// FVP_RTC(device, rtcSomething(...)): runs the call, then checks device's error state.
#define FVP_RTC(device, ...)                                                          \
  ::fvp::accel::detail::checkedEmbreeCall((device), #__VA_ARGS__, __FILE__, __LINE__, \
                                          [&] { return __VA_ARGS__; })
