#include "fvp/host/core/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace fvp::host {

void writeFileAtomically(const std::filesystem::path& path, std::string_view what,
                         const std::function<bool(std::ostream&)>& write) {
  // Unique per process and call, so concurrent writers never share a temporary.
  static std::atomic<unsigned> counter{0};
  std::filesystem::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  auto fail = [&](const std::string& why) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error("writing " + std::string(what) + " " + path.string() + ": " + why);
  };
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) fail("cannot create " + tmp.string());
    if (!write(out)) fail("the writer reported an error");
    out.flush();
    if (!out) fail("write error");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) fail("rename failed: " + ec.message());
}

void writeFileAtomically(const std::filesystem::path& path, std::string_view what,
                         std::string_view bytes) {
  writeFileAtomically(path, what, [&](std::ostream& out) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return static_cast<bool>(out);
  });
}

}  // namespace fvp::host
