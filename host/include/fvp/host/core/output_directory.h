// An output directory is checked before the work that fills it starts (a long trial must not
// fail at its end because --out names a file), and files an earlier run left there are
// removed first, so every file in it belongs to this run.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace fvp::host {

/// Creates dir (and its parents) when missing and checks that a file can be created in it.
/// Throws std::runtime_error naming `what` (e.g. "--out") and the path when dir is empty
/// (`--out ""` would write nowhere, or into the working directory), exists as something other
/// than a directory, cannot be created or is not writable.
void prepareOutputDirectory(const std::filesystem::path& dir, const std::string& what);

/// One writer per output directory: an advisory lock (flock) on dir/.fvp.lock, held while
/// the object lives, the file holding the holder's PID and command line so that a second
/// writer's message can name it. A second lock of the same directory in the same process
/// (an experiment's CLI and its runner) shares the first. On taking the lock, temporaries
/// (*.tmp-PID-N) that dead processes left in dir and its subdirectories are removed. The
/// lock file is removed when the last holder releases it.
class OutputDirectoryLock {
 public:
  /// Throws std::runtime_error naming `what`, the directory and the other process when
  /// another process holds the lock. dir must exist (prepareOutputDirectory).
  OutputDirectoryLock(const std::filesystem::path& dir, const std::string& what);
  ~OutputDirectoryLock();
  OutputDirectoryLock(OutputDirectoryLock&& other) noexcept;
  OutputDirectoryLock& operator=(OutputDirectoryLock&&) = delete;
  OutputDirectoryLock(const OutputDirectoryLock&) = delete;
  OutputDirectoryLock& operator=(const OutputDirectoryLock&) = delete;

 private:
  std::string key_;  ///< the canonical directory; empty once moved from
};

/// The lock file's name inside a locked directory (not an output: listings ignore it).
inline constexpr const char* kOutputLockFile = ".fvp.lock";

/// Checks, before the work, the paths a run will write under dir: each of `files` (relative
/// paths) must be absent or a file, and each of `subdirs` absent or a writable directory
/// (created when missing). Throws std::runtime_error naming `what` and the path, so a
/// `views` that is a plain file fails before a trial runs rather than after it.
void checkOutputPaths(const std::filesystem::path& dir, const std::string& what,
                      const std::vector<std::string>& files,
                      const std::vector<std::string>& subdirs);

/// Removes files named like NAME.tmp-PID-N (the atomic writer's temporaries) whose process
/// PID is no longer running, in dir and up to `depth` levels of subdirectories. Returns how
/// many were removed.
std::size_t removeStaleTemporaries(const std::filesystem::path& dir, int depth = 3);

/// Removes, where present, the files named in `outputs` (paths relative to dir) and, for
/// each directory in `numbered_dirs`, the files in it named like NNN.png or NNN.jpg (digits only):
/// what an earlier run into the same directory wrote. Nothing else is touched.
void removeStaleOutputs(const std::filesystem::path& dir, const std::vector<std::string>& outputs,
                        const std::vector<std::string>& numbered_dirs = {});

/// A numbered file's name, as removeStaleOutputs recognises it: dir/NNN.extension (at least
/// three digits, zero-padded; extension without its dot), e.g. "views/007.png".
std::string numberedFileName(const std::string& dir, int number, const std::string& extension);

}  // namespace fvp::host
