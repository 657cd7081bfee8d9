// Reading an input file without hanging or running out of memory: only a regular file is
// opened for reading (a FIFO would block the reader forever, /dev/zero never ends), and its
// size is checked against the limit the reader documents before a byte is read (a 30 GB
// sparse file named left.png must fail at once). Header-only: the config readers of every
// library, fuzz targets included, use it.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace fvp::host {

namespace detail {

inline std::string fileKind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

/// An open descriptor of a regular file of at most max_bytes; closes itself.
class RegularFile {
 public:
  RegularFile(const std::filesystem::path& path, const std::string& what, std::uint64_t max_bytes)
      : path_(path) {
    // O_NONBLOCK: opening a FIFO without a writer would block before fstat could refuse it.
    fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd_ < 0)
      throw std::runtime_error(path.string() + ": cannot open the " + what + ": " +
                               std::strerror(errno));
    struct stat st {};
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
      const std::string kind = detail::fileKind(st.st_mode);
      ::close(fd_);
      throw std::runtime_error(path.string() + ": expected a regular file (the " + what +
                               "), got " + kind);
    }
    size_ = static_cast<std::uint64_t>(st.st_size);
    if (size_ > max_bytes) {
      ::close(fd_);
      throw std::runtime_error(path.string() + ": " + std::to_string(size_) +
                               " bytes, more than the " + std::to_string(max_bytes) + " bytes a " +
                               what + " may have");
    }
  }
  ~RegularFile() { ::close(fd_); }
  RegularFile(const RegularFile&) = delete;
  RegularFile& operator=(const RegularFile&) = delete;

  std::uint64_t size() const { return size_; }
  /// Up to n bytes from the start (fewer when the file is shorter).
  std::string read(std::uint64_t n) const {
    std::string bytes(static_cast<std::size_t>(n), '\0');
    std::size_t got = 0;
    while (got < bytes.size()) {
      const ssize_t r = ::pread(fd_, bytes.data() + got, bytes.size() - got, off_t(got));
      if (r < 0 && errno == EINTR) continue;
      if (r < 0)
        throw std::runtime_error(path_.string() + ": cannot read it: " + std::strerror(errno));
      if (r == 0) break;
      got += static_cast<std::size_t>(r);
    }
    bytes.resize(got);
    return bytes;
  }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

}  // namespace detail

/// The whole of path: a regular file of at most max_bytes. Throws std::runtime_error naming
/// the file and `what` ("camera model") when it is anything else (a FIFO, a directory, a
/// device), larger, or unreadable.
inline std::string readRegularFile(const std::filesystem::path& path, const std::string& what,
                                   std::uint64_t max_bytes) {
  const detail::RegularFile file(path, what, max_bytes);
  return file.read(file.size());
}

/// The first `head` bytes of path and its size, with readRegularFile's checks: a reader that
/// must see a header before it knows how much the file may hold.
inline std::string readRegularFileHead(const std::filesystem::path& path, const std::string& what,
                                       std::uint64_t max_bytes, std::uint64_t head,
                                       std::uint64_t* size = nullptr) {
  const detail::RegularFile file(path, what, max_bytes);
  if (size) *size = file.size();
  return file.read(std::min(head, file.size()));
}

/// Checks path as readRegularFile does without reading it (for readers with their own stream).
inline std::uint64_t checkRegularFile(const std::filesystem::path& path, const std::string& what,
                                      std::uint64_t max_bytes) {
  return detail::RegularFile(path, what, max_bytes).size();
}

}  // namespace fvp::host
