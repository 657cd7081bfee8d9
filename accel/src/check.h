// Error reporting shared by the backends: every failing API call becomes a BackendError
// whose message names the call, the source file and the line.
#pragma once

#include <sstream>
#include <string>
#include <string_view>

#include "fvp/accel/backend.h"

namespace fvp::accel::detail {

[[noreturn]] inline void throwBackendError(std::string_view api, std::string_view call,
                                           std::string_view detail, const char* file, int line) {
  std::ostringstream msg;
  msg << api << " call failed: " << call << " -> " << detail << " (at " << file << ":" << line
      << ")";
  throw BackendError(msg.str());
}

}  // namespace fvp::accel::detail
