#include "fvp/host/core/gnuplot.h"

#include <stdexcept>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/subprocess.h"

namespace fvp::host {

void plotWithGnuplot(const std::string& script, const std::filesystem::path& png_path,
                     const std::string& what) {
  // The script goes to gnuplot's standard input and the PNG comes back on its standard
  // output: no path (which may hold quotes) is ever written into the script or a command.
  SubprocessResult run;
  try {
    run = runProgram({"gnuplot"}, script);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(what + ": " + e.what() + " (is gnuplot-nox installed?)");
  }
  static constexpr char kPngSignature[] = "\x89PNG\r\n\x1a\n";
  if (run.exit_code != 0 || run.stdout_text.compare(0, 8, kPngSignature) != 0)
    throw std::runtime_error(what + ": gnuplot failed (exit " + std::to_string(run.exit_code) +
                             "): " + run.stderr_text);
  writeFileAtomically(png_path, what, run.stdout_text);
}

}  // namespace fvp::host
