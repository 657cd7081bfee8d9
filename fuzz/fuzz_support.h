// What the fuzz harnesses share: a scratch directory per process (made once, reused by every
// input, removed at exit) to hand the readers real files, and the check that a reader fails
// only with its own errors.
//
// A reader may reject any input, with an exception whose message names the file and what was
// expected. Crashes, sanitizer reports, hangs and exceptions of the libraries underneath
// (YAML::Exception, nlohmann::json::exception: their messages name neither file nor field)
// are bugs; reportEscapedException() turns the last kind into a crash libFuzzer records.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>

namespace fvp::fuzz {

/// $TMPDIR/fvp-fuzz-XXXXXX, made on first use; removed when the process exits normally.
inline const std::filesystem::path& scratchDir() {
  // A pointer, never destroyed: the exit handler runs after static destructors would have.
  static const std::filesystem::path* const dir = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "fvp-fuzz-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      std::perror("fvp fuzz: mkdtemp");
      std::abort();
    }
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(scratchDir(), ignored);
    });
    return new std::filesystem::path(pattern);
  }();
  return *dir;
}

/// Writes bytes to path (replacing it); aborts when that fails (the harness, not the input).
inline void writeFile(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fvp fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

inline void writeFile(const std::filesystem::path& path, const std::uint8_t* data,
                      std::size_t size) {
  writeFile(path, std::string_view(reinterpret_cast<const char*>(data), size));
}

inline void removeFile(const std::filesystem::path& path) {
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
}

/// A library's exception left the reader: its message names neither the file nor the field.
[[noreturn]] inline void reportEscapedException(const char* library, const std::exception& e) {
  std::fprintf(stderr, "fvp fuzz: a %s exception escaped the reader: %s\n", library, e.what());
  std::abort();
}

}  // namespace fvp::fuzz
