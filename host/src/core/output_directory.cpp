#include "fvp/host/core/output_directory.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <stdexcept>
#include <system_error>

#include "fvp/host/core/atomic_file.h"

namespace fvp::host {
namespace fs = std::filesystem;

void prepareOutputDirectory(const fs::path& dir, const std::string& what) {
  if (dir.empty()) throw std::runtime_error(what + ": expected a directory, got an empty path");
  const std::string where = what + " '" + dir.string() + "'";
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (fs::exists(status) && !fs::is_directory(status))
    throw std::runtime_error(where + ": exists and is not a directory");
  // A dangling link: create_directories would say only "File exists".
  if (!fs::exists(status) && fs::is_symlink(fs::symlink_status(dir, ec)))
    throw std::runtime_error(where + ": a symbolic link to '" + fs::read_symlink(dir, ec).string() +
                             "', which does not exist; create that directory or name another");
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(where + ": cannot create the directory: " + ec.message());
  try {
    writeFileAtomically(dir / ".fvp-write-check", "output directory check", "");
  } catch (const std::exception&) {
    throw std::runtime_error(where + ": cannot write files in it");
  }
  fs::remove(dir / ".fvp-write-check", ec);
}

void removeStaleOutputs(const fs::path& dir, const std::vector<std::string>& outputs,
                        const std::vector<std::string>& numbered_dirs) {
  const auto remove = [](const fs::path& path) {
    std::error_code ec;
    if (fs::is_directory(path)) return;  // never a directory the user made
    fs::remove(path, ec);
    if (ec)
      throw std::runtime_error(path.string() +
                               ": cannot remove the file an earlier run left: " + ec.message());
  };
  for (const std::string& name : outputs) remove(dir / name);
  for (const std::string& sub : numbered_dirs) {
    std::error_code ec;
    if (!fs::is_directory(dir / sub, ec)) continue;
    std::vector<fs::path> stale;
    for (const auto& entry : fs::directory_iterator(dir / sub, ec)) {
      const std::string stem = entry.path().stem().string();
      if ((entry.path().extension() == ".png" || entry.path().extension() == ".jpg") &&
          !stem.empty() &&
          std::all_of(stem.begin(), stem.end(), [](unsigned char c) { return std::isdigit(c); }))
        stale.push_back(entry.path());
    }
    for (const fs::path& path : stale) remove(path);
  }
}

namespace {

/// This process's locks: directory -> the lock file's descriptor and how many hold it.
struct HeldLock {
  int fd = -1;
  int holders = 0;
  fs::path file;
};
std::mutex g_locks_mutex;
std::map<std::string, HeldLock>& heldLocks() {
  static std::map<std::string, HeldLock> locks;
  return locks;
}

/// "pid N: ARGV..." for the lock file: what a second writer's message names.
std::string holderDescription() {
  std::string command;
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::getline(in, command, '\0');
  for (std::string arg; std::getline(in, arg, '\0');) command += " " + arg;
  if (command.size() > 300) command = command.substr(0, 300) + "...";
  for (char& c : command)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return "pid " + std::to_string(::getpid()) + ": " + command;
}

std::string lockHolder(int fd) {
  char text[512] = {};
  const ssize_t n = ::pread(fd, text, sizeof(text) - 1, 0);
  std::string holder = n > 0 ? std::string(text, static_cast<std::size_t>(n)) : "";
  while (!holder.empty() && (holder.back() == '\n' || holder.back() == '\0')) holder.pop_back();
  return holder.empty() ? "another process" : holder;
}

bool processAlive(long pid) {
  return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
}

/// The PID in NAME.tmp-PID-N, or -1 when the name is not an atomic writer's temporary.
long temporaryPid(const std::string& name) {
  const std::size_t at = name.rfind(".tmp-");
  if (at == std::string::npos || at == 0) return -1;
  const std::string rest = name.substr(at + 5);
  const std::size_t dash = rest.find('-');
  if (dash == 0 || dash == std::string::npos || dash + 1 == rest.size() || dash > 9) return -1;
  for (std::size_t i = 0; i < rest.size(); ++i)
    if (i != dash && !std::isdigit(static_cast<unsigned char>(rest[i]))) return -1;
  return std::stol(rest.substr(0, dash));
}

}  // namespace

OutputDirectoryLock::OutputDirectoryLock(const fs::path& dir, const std::string& what) {
  std::error_code ec;
  const fs::path canonical = fs::canonical(dir, ec);
  if (ec) throw std::runtime_error(what + " '" + dir.string() + "': " + ec.message());
  const std::lock_guard<std::mutex> guard(g_locks_mutex);
  HeldLock& held = heldLocks()[canonical.string()];
  if (held.holders == 0) {
    const fs::path file = canonical / kOutputLockFile;
    // The holder removes the file when it is done: a lock taken on a file that was removed
    // meanwhile locks nothing, so check that the path still names the locked file.
    for (int attempt = 0; held.fd < 0; ++attempt) {
      const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
      if (fd < 0) {
        heldLocks().erase(canonical.string());
        throw std::runtime_error(what + " '" + dir.string() + "': cannot create the lock file " +
                                 file.string() + ": " + std::strerror(errno));
      }
      if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        const std::string holder = lockHolder(fd);
        ::close(fd);
        heldLocks().erase(canonical.string());
        throw std::runtime_error(what + " '" + dir.string() + "': in use by another fvp (" +
                                 holder + "); one writer per directory: wait for it to end or " +
                                 "use another directory (lock: " + file.string() + ")");
      }
      struct stat by_fd {
      }, by_path{};
      if (::fstat(fd, &by_fd) == 0 && ::stat(file.c_str(), &by_path) == 0 &&
          by_fd.st_ino == by_path.st_ino && by_fd.st_dev == by_path.st_dev) {
        held.fd = fd;
        held.file = file;
      } else {
        ::close(fd);
        if (attempt > 10) {
          heldLocks().erase(canonical.string());
          throw std::runtime_error(what + " '" + dir.string() + "': cannot take the lock " +
                                   file.string());
        }
      }
    }
    const std::string text = holderDescription() + "\n";
    if (::ftruncate(held.fd, 0) != 0 || ::pwrite(held.fd, text.data(), text.size(), 0) < 0) {
      // The lock holds without the description; a second writer then names no process.
    }
    removeStaleTemporaries(canonical);
  }
  ++held.holders;
  key_ = canonical.string();
}

OutputDirectoryLock::OutputDirectoryLock(OutputDirectoryLock&& other) noexcept
    : key_(std::move(other.key_)) {
  other.key_.clear();
}

OutputDirectoryLock::~OutputDirectoryLock() {
  if (key_.empty()) return;
  const std::lock_guard<std::mutex> guard(g_locks_mutex);
  const auto it = heldLocks().find(key_);
  if (it == heldLocks().end() || --it->second.holders > 0) return;
  ::unlink(it->second.file.c_str());  // while still locked: see the constructor
  ::close(it->second.fd);
  heldLocks().erase(it);
}

void checkOutputPaths(const fs::path& dir, const std::string& what,
                      const std::vector<std::string>& files,
                      const std::vector<std::string>& subdirs) {
  std::error_code ec;
  for (const std::string& name : files)
    if (fs::is_directory(dir / name, ec))
      throw std::runtime_error(what + " '" + dir.string() + "': " + (dir / name).string() +
                               " is a directory; the run writes a file there (move it away)");
  for (const std::string& name : subdirs) {
    const fs::path sub = dir / name;
    const fs::file_status status = fs::status(sub, ec);
    if (!fs::exists(status)) continue;
    if (!fs::is_directory(status))
      throw std::runtime_error(what + " '" + dir.string() + "': " + sub.string() +
                               " exists and is not a directory; the run writes files into it "
                               "(move it away)");
    try {
      writeFileAtomically(sub / ".fvp-write-check", "output directory check", "");
    } catch (const std::exception& e) {
      throw std::runtime_error(what + " '" + dir.string() + "': cannot write files in " +
                               sub.string() + ": " + e.what());
    }
    fs::remove(sub / ".fvp-write-check", ec);
  }
}

std::size_t removeStaleTemporaries(const fs::path& dir, int depth) {
  std::size_t removed = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it.depth() >= depth) it.disable_recursion_pending();
    if (!it->is_regular_file(ec)) continue;
    const long pid = temporaryPid(it->path().filename().string());
    if (pid < 0 || pid == ::getpid() || processAlive(pid)) continue;
    std::error_code ignored;
    removed += fs::remove(it->path(), ignored);
  }
  return removed;
}

std::string numberedFileName(const std::string& dir, int number, const std::string& extension) {
  std::string digits = std::to_string(number);
  if (digits.size() < 3) digits.insert(0, 3 - digits.size(), '0');
  return dir + "/" + digits + "." + extension;
}

}  // namespace fvp::host
