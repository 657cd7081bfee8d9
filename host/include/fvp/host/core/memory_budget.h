// A setting that asks for more memory than the machine has must fail before the work, naming
// the setting, not end as a bare std::bad_alloc hours later (docs/reliability.md, "Memory
// bounds"). Header-only, like regular_file.h.
#pragma once

#include <sys/resource.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace fvp::host {

/// The memory this process can still get: the kernel's MemAvailable, less where an address
/// space limit (ulimit -v) is lower. Unknown (no /proc): the largest value.
inline std::uint64_t availableMemoryBytes() {
  std::uint64_t available = UINT64_MAX;
  std::ifstream meminfo("/proc/meminfo");
  for (std::string line; std::getline(meminfo, line);) {
    std::istringstream fields(line);
    std::string key;
    std::uint64_t kib = 0;
    if (fields >> key >> kib && key == "MemAvailable:") available = kib * 1024;
  }
  struct rlimit limit {};
  if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
      limit.rlim_cur < available)
    available = limit.rlim_cur;
  return available;
}

/// "1.5 GiB"
inline std::string gibText(std::uint64_t bytes) {
  std::ostringstream s;
  s.precision(bytes >= (std::uint64_t{10} << 30) ? 0 : 1);
  s << std::fixed << double(bytes) / double(std::uint64_t{1} << 30) << " GiB";
  return s.str();
}

/// Throws std::runtime_error "WHAT: needs about N GiB of memory, more than the M GiB
/// available" when bytes exceed what availableMemoryBytes() reports.
inline void checkMemoryFor(std::uint64_t bytes, const std::string& what) {
  const std::uint64_t available = availableMemoryBytes();
  if (bytes > available)
    throw std::runtime_error(what + ": needs about " + gibText(bytes) +
                             " of memory, more than the " + gibText(available) +
                             " available; ask for less or run it on a larger machine");
}

}  // namespace fvp::host
