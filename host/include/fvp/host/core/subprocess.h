// Runs a helper program (gnuplot) without a shell: the program and its arguments are an
// argument vector, so no path or other user text is ever parsed as a command.
#pragma once

#include <string>
#include <vector>

namespace fvp::host {

struct SubprocessResult {
  int exit_code = -1;       ///< the program's exit status; -1 when a signal ended it
  std::string stdout_text;  ///< everything it wrote to standard output (bytes)
  std::string stderr_text;  ///< everything it wrote to standard error
};

/// Starts argv[0] (looked up on PATH) with argv, writes stdin_text to its standard input,
/// closes it, and collects both output streams until it exits. Throws std::runtime_error
/// when the program cannot be started (e.g. not installed), naming it.
SubprocessResult runProgram(const std::vector<std::string>& argv, const std::string& stdin_text);

}  // namespace fvp::host
