#include "fvp/host/core/gnuplot.h"

#include <stdexcept>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/subprocess.h"

namespace fvp::host {

bool isGnuplotSafeText(std::string_view text) {
  if (text.size() > kGnuplotTextMax) return false;
  for (const char c : text) {
    const bool alnum = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    if (!alnum && std::string_view(" ._-+=%/()[]:,").find(c) == std::string_view::npos)
      return false;
  }
  return true;
}

std::string gnuplotQuoted(std::string_view text) {
  if (!isGnuplotSafeText(text)) {
    // The refused text is shown with its unsafe bytes as \xNN, so the message itself is safe.
    std::string shown;
    for (const unsigned char c : text.substr(0, 60)) {
      if (c >= 0x20 && c < 0x7f && c != '\\') {
        shown += char(c);
      } else {
        static const char* hex = "0123456789abcdef";
        shown += std::string("\\x") + hex[c >> 4] + hex[c & 15];
      }
    }
    throw std::invalid_argument("figure text '" + shown + (text.size() > 60 ? "..." : "") +
                                "' refused: a title or label holds only letters, digits, spaces "
                                "and ._-+=%/()[]:, (at most " +
                                std::to_string(kGnuplotTextMax) + " characters)");
  }
  std::string quoted;
  quoted.reserve(text.size() + 2);
  quoted.append(1, '\'').append(text).append(1, '\'');
  return quoted;
}

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
