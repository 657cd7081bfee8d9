#include "fvp/host/core/output_directory.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <system_error>

#include "fvp/host/core/atomic_file.h"

namespace fvp::host {
namespace fs = std::filesystem;

void prepareOutputDirectory(const fs::path& dir, const std::string& what) {
  const std::string where = what + " '" + dir.string() + "'";
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (fs::exists(status) && !fs::is_directory(status))
    throw std::runtime_error(where + ": exists and is not a directory");
  // A dangling link: create_directories would say only "File exists".
  if (!fs::exists(status) && fs::is_symlink(fs::symlink_status(dir, ec)))
    throw std::runtime_error(where + ": a symbolic link to '" + fs::read_symlink(dir, ec).string() +
                             "', which does not exist; create that directory or name another");
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(where + ": cannot create the directory: " + ec.message());
  try {
    writeFileAtomically(dir / ".fvp-write-check", "output directory check", "");
  } catch (const std::exception&) {
    throw std::runtime_error(where + ": cannot write files in it");
  }
  fs::remove(dir / ".fvp-write-check", ec);
}

void removeStaleOutputs(const fs::path& dir, const std::vector<std::string>& outputs,
                        const std::vector<std::string>& numbered_dirs) {
  const auto remove = [](const fs::path& path) {
    std::error_code ec;
    if (fs::is_directory(path)) return;  // never a directory the user made
    fs::remove(path, ec);
    if (ec)
      throw std::runtime_error(path.string() +
                               ": cannot remove the file an earlier run left: " + ec.message());
  };
  for (const std::string& name : outputs) remove(dir / name);
  for (const std::string& sub : numbered_dirs) {
    std::error_code ec;
    if (!fs::is_directory(dir / sub, ec)) continue;
    std::vector<fs::path> stale;
    for (const auto& entry : fs::directory_iterator(dir / sub, ec)) {
      const std::string stem = entry.path().stem().string();
      if ((entry.path().extension() == ".png" || entry.path().extension() == ".jpg") &&
          !stem.empty() &&
          std::all_of(stem.begin(), stem.end(), [](unsigned char c) { return std::isdigit(c); }))
        stale.push_back(entry.path());
    }
    for (const fs::path& path : stale) remove(path);
  }
}

std::string numberedFileName(const std::string& dir, int number, const std::string& extension) {
  std::string digits = std::to_string(number);
  if (digits.size() < 3) digits.insert(0, 3 - digits.size(), '0');
  return dir + "/" + digits + "." + extension;
}

}  // namespace fvp::host
