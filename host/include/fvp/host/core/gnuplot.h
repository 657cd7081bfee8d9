// Figures for reports (sizes.png, a trial's camera path) drawn by gnuplot (Debian's
// gnuplot-nox), run as a subprocess on a generated script: a real plotting library, not
// hand-placed pixels, and nothing linked into the library.
#pragma once

#include <filesystem>
#include <string>

namespace fvp::host {

/// Runs gnuplot on `script` (which must set its own terminal and output; `{png}` in the
/// script is replaced by the temporary output path) and renames the result to png_path, so
/// a figure is never half-written. Throws std::runtime_error naming the figure when gnuplot
/// is missing or fails (its messages included).
void plotWithGnuplot(const std::string& script, const std::filesystem::path& png_path,
                     const std::string& what);

}  // namespace fvp::host
