#include "fvp/host/core/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <streambuf>
#include <string>
#include <system_error>

#include "fvp/host/core/interrupt.h"

namespace fvp::host {
namespace {

/// An ostream buffer on a file descriptor that keeps the errno of the first failed write, so
/// a failure can name its cause ("No space left on device") where std::ofstream only says
/// that it failed. A signal that asks the run to stop fails the next write.
class FdBuf : public std::streambuf {
 public:
  explicit FdBuf(int fd) : fd_(fd) { setp(buffer_, buffer_ + sizeof(buffer_)); }
  int error() const { return error_; }
  bool interrupted() const { return interrupted_; }

 protected:
  int_type overflow(int_type c) override {
    if (!flushBuffer()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return flushBuffer() ? 0 : -1; }

 private:
  bool flushBuffer() {
    if (error_ != 0 || interrupted_) return false;
    if (interruptSignal() != 0) {
      interrupted_ = true;
      return false;
    }
    const char* p = pbase();
    while (p < pptr()) {
      const ssize_t n = ::write(fd_, p, static_cast<std::size_t>(pptr() - p));
      if (n < 0 && errno == EINTR) {
        if (interruptSignal() != 0) {
          interrupted_ = true;
          return false;
        }
        continue;
      }
      if (n <= 0) {
        error_ = n < 0 ? errno : ENOSPC;
        return false;
      }
      p += n;
    }
    setp(buffer_, buffer_ + sizeof(buffer_));
    return true;
  }

  int fd_;
  int error_ = 0;
  bool interrupted_ = false;
  char buffer_[1 << 16];
};

}  // namespace

void writeFileAtomically(const std::filesystem::path& path, std::string_view what,
                         const std::function<bool(std::ostream&)>& write) {
  throwIfInterrupted();
  // Unique per process and call, so concurrent writers never share a temporary; the PID in
  // the name lets a later run tell a dead process's leftover (removeStaleTemporaries).
  static std::atomic<unsigned> counter{0};
  std::filesystem::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  const std::string prefix = "writing " + std::string(what) + " " + path.string() + ": ";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0)
    throw std::runtime_error(prefix + "cannot create " + tmp.string() + ": " +
                             std::strerror(errno));
  const RegisteredTemporary registered(tmp.string());
  auto fail = [&](const std::string& why) {
    ::close(fd);
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    if (interruptSignal() != 0) throwIfInterrupted();
    throw std::runtime_error(prefix + why);
  };
  FdBuf buf(fd);
  std::ostream out(&buf);
  bool ok = false;
  try {
    ok = write(out);
  } catch (...) {
    ::close(fd);
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
  out.flush();
  if (buf.error() != 0) fail(std::strerror(buf.error()));
  if (!ok || !out) fail(buf.interrupted() ? "interrupted" : "the writer reported an error");
  if (::close(fd) != 0) {
    const int e = errno;
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error(prefix + std::strerror(e));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(prefix + "rename failed: " + ec.message());
  }
}

void writeFileAtomically(const std::filesystem::path& path, std::string_view what,
                         std::string_view bytes) {
  writeFileAtomically(path, what, [&](std::ostream& out) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return static_cast<bool>(out);
  });
}

}  // namespace fvp::host
