// Figures for reports (sizes.png, a trial's camera path) drawn by gnuplot (Debian's
// gnuplot-nox), run as a subprocess on a generated script: a real plotting library, not
// hand-placed pixels, and nothing linked into the library.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace fvp::host {

/// The one way text enters a gnuplot script as a title or label: `text` in single quotes,
/// when every byte is a letter, a digit, a space or one of ._-+=%/()[]:, and it is at most
/// kGnuplotTextMax bytes. Anything else (quotes, backslashes, backquotes, newlines, @, $, ;,
/// control or non-ASCII bytes) throws std::invalid_argument: inside single quotes gnuplot
/// expands nothing, so a string of these bytes can only be a string, never a command,
/// a macro (@) or a shell call (`...`, system). Callers treat a figure as an optional extra,
/// so a refused title costs the figure, never the data.
std::string gnuplotQuoted(std::string_view text);
/// Whether gnuplotQuoted accepts `text`.
bool isGnuplotSafeText(std::string_view text);
inline constexpr std::size_t kGnuplotTextMax = 200;

/// Runs gnuplot (no shell) on `script`, which sets a PNG terminal and no output, so the PNG
/// comes back on gnuplot's standard output; writes it to png_path atomically (a figure is
/// never half-written). Throws std::runtime_error naming the figure when gnuplot is missing
/// or fails (its messages included). Callers treat a figure as an optional extra.
void plotWithGnuplot(const std::string& script, const std::filesystem::path& png_path,
                     const std::string& what);

}  // namespace fvp::host
