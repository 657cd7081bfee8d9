#include "fvp/host/core/gnuplot.h"

#include <unistd.h>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace fvp::host {

void plotWithGnuplot(const std::string& script, const std::filesystem::path& png_path,
                     const std::string& what) {
  const std::filesystem::path dir = png_path.parent_path().empty() ? "." : png_path.parent_path();
  // Appended piecewise: GCC 12 warns (-Wrestrict, a false positive) on "." + string.
  std::string stem = ".";
  stem += png_path.filename().string();
  stem += '.';
  stem += std::to_string(getpid());
  const std::filesystem::path tmp_png = dir / (stem + ".tmp.png");
  const std::filesystem::path script_path = dir / (stem + ".gp");
  const std::filesystem::path log_path = dir / (stem + ".log");
  std::string text = script;
  for (std::size_t at = text.find("{png}"); at != std::string::npos; at = text.find("{png}", at))
    text.replace(at, 5, tmp_png.string());
  {
    std::ofstream out(script_path);
    out << text;
    if (!out) throw std::runtime_error(what + ": cannot write " + script_path.string());
  }
  const std::string command =
      "gnuplot '" + script_path.string() + "' > '" + log_path.string() + "' 2>&1";
  const int rc = std::system(command.c_str());
  std::stringstream log;
  log << std::ifstream(log_path).rdbuf();
  std::error_code ignored;
  std::filesystem::remove(script_path, ignored);
  std::filesystem::remove(log_path, ignored);
  if (rc != 0 || !std::filesystem::exists(tmp_png)) {
    std::filesystem::remove(tmp_png, ignored);
    throw std::runtime_error(what + ": gnuplot failed (is gnuplot-nox installed?): " + log.str());
  }
  std::filesystem::rename(tmp_png, png_path);
}

}  // namespace fvp::host
