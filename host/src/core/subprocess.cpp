#include "fvp/host/core/subprocess.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

extern char** environ;

namespace fvp::host {
namespace {

struct Pipe {
  int read_fd = -1, write_fd = -1;
  Pipe() {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0)
      throw std::runtime_error(std::string("cannot create a pipe: ") + std::strerror(errno));
    read_fd = fds[0];
    write_fd = fds[1];
  }
  ~Pipe() {
    closeRead();
    closeWrite();
  }
  void closeRead() {
    if (read_fd >= 0) ::close(read_fd);
    read_fd = -1;
  }
  void closeWrite() {
    if (write_fd >= 0) ::close(write_fd);
    write_fd = -1;
  }
};

/// Blocks SIGPIPE in this thread while it writes to a child that may exit early (the write
/// then fails with EPIPE instead of killing the process), and discards a pending SIGPIPE.
class SigpipeBlock {
 public:
  SigpipeBlock() {
    sigemptyset(&pipe_set_);
    sigaddset(&pipe_set_, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipe_set_, &old_);
  }
  ~SigpipeBlock() {
    const timespec zero{0, 0};
    while (sigtimedwait(&pipe_set_, nullptr, &zero) > 0) {
    }
    pthread_sigmask(SIG_SETMASK, &old_, nullptr);
  }
  const sigset_t& previous() const { return old_; }

 private:
  sigset_t pipe_set_, old_;
};

}  // namespace

SubprocessResult runProgram(const std::vector<std::string>& argv, const std::string& stdin_text) {
  if (argv.empty()) throw std::invalid_argument("runProgram: empty argument vector");
  const SigpipeBlock sigpipe_block;
  Pipe in, out, err;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in.read_fd, STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, out.write_fd, STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, err.write_fd, STDERR_FILENO);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  // The child gets the caller's signal mask, not the SIGPIPE block.
  posix_spawnattr_setsigmask(&attr, &sigpipe_block.previous());
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = -1;
  const int spawn_error =
      posix_spawnp(&pid, argv[0].c_str(), &actions, &attr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (spawn_error != 0)
    throw std::runtime_error("cannot start '" + argv[0] + "': " + std::strerror(spawn_error));
  in.closeRead();
  out.closeWrite();
  err.closeWrite();
  // Our ends never block: a blocking write of a large input would wait for the program,
  // which waits for us to read its output.
  for (const int fd : {in.write_fd, out.read_fd, err.read_fd})
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);

  SubprocessResult result;
  std::size_t written = 0;
  if (stdin_text.empty()) in.closeWrite();
  std::array<char, 65536> buffer;
  while (in.write_fd >= 0 || out.read_fd >= 0 || err.read_fd >= 0) {
    std::array<pollfd, 3> fds{};
    nfds_t n = 0;
    if (in.write_fd >= 0) fds[n++] = {in.write_fd, POLLOUT, 0};
    if (out.read_fd >= 0) fds[n++] = {out.read_fd, POLLIN, 0};
    if (err.read_fd >= 0) fds[n++] = {err.read_fd, POLLIN, 0};
    if (::poll(fds.data(), n, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (nfds_t i = 0; i < n; ++i) {
      if (fds[i].revents == 0) continue;
      if (fds[i].fd == in.write_fd) {
        const ssize_t w =
            ::write(in.write_fd, stdin_text.data() + written, stdin_text.size() - written);
        if (w > 0) written += std::size_t(w);
        if ((w < 0 && errno != EINTR && errno != EAGAIN) || written == stdin_text.size())
          in.closeWrite();  // done, or the program stopped reading (EPIPE)
        continue;
      }
      const bool is_out = fds[i].fd == out.read_fd;
      const ssize_t r = ::read(fds[i].fd, buffer.data(), buffer.size());
      if (r > 0) {
        (is_out ? result.stdout_text : result.stderr_text).append(buffer.data(), std::size_t(r));
      } else if (r == 0 || (errno != EINTR && errno != EAGAIN)) {
        (is_out ? out : err).closeRead();
      }
    }
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace fvp::host
