// viewer.html: one self-contained page (docs/viewer.md) that draws a ViewerScene with
// three.js, opened from the file system with no network. The page's own files (viewer/) and
// Debian's three.js (libjs-three) are compiled into the library, so the page needs nothing
// at run time.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace fvp::host::report {

/// The page with its style, scripts and the scene inlined.
std::string viewerPageHtml(const nlohmann::json& scene);
/// Writes the page atomically; throws std::runtime_error naming the file on failure.
void writeViewerPage(const nlohmann::json& scene, const std::filesystem::path& html_path);

}  // namespace fvp::host::report
