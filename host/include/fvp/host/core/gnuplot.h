// Figures for reports (sizes.png, a trial's camera path) drawn by gnuplot (Debian's
// gnuplot-nox), run as a subprocess on a generated script: a real plotting library, not
// hand-placed pixels, and nothing linked into the library.
#pragma once

#include <filesystem>
#include <string>

namespace fvp::host {

/// Runs gnuplot (no shell) on `script`, which sets a PNG terminal and no output, so the PNG
/// comes back on gnuplot's standard output; writes it to png_path atomically (a figure is
/// never half-written). Throws std::runtime_error naming the figure when gnuplot is missing
/// or fails (its messages included). Callers treat a figure as an optional extra.
void plotWithGnuplot(const std::string& script, const std::filesystem::path& png_path,
                     const std::string& what);

}  // namespace fvp::host
