// The command line itself: the input is an argument vector (one argument a line) given to
// `fvp` in parse-only mode (apps/cli.cpp, runFvp with CliMode::kParseOnly: every option and
// its checks, no subcommand's work). Whatever the arguments, fvp must end with exit code 0, 1
// or 2 and its message; an exception that escapes runFvp, a crash or a sanitizer report is a
// bug, and so is a file written (the harness runs in an empty scratch directory, which must
// stay empty).
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "commands.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool entered = [] {
    // Relative paths in the arguments land in the scratch directory, never the source tree.
    if (::chdir(fvp::fuzz::scratchDir().c_str()) != 0) std::abort();
    return true;
  }();
  (void)entered;
  std::vector<std::string> args{"fvp"};
  std::string current;
  for (std::size_t i = 0; i < size; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\n') {
      args.push_back(current);
      current.clear();
    } else if (c != '\0') {  // a real argv cannot hold a NUL byte
      current += c;
    }
  }
  if (!current.empty()) args.push_back(current);
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  argv.push_back(nullptr);
  const int code =
      fvp::apps::runFvp(static_cast<int>(args.size()), argv.data(), fvp::apps::CliMode::kParseOnly);
  if (code < 0 || code > 2) {
    std::fprintf(stderr, "fvp fuzz: the command line ended with exit code %d\n", code);
    std::abort();
  }
  if (!std::filesystem::is_empty(fvp::fuzz::scratchDir())) {
    std::fprintf(stderr, "fvp fuzz: parsing the command line wrote a file\n");
    std::abort();
  }
  return 0;
}
