// Write-to-temporary-then-rename: a reader sees the old file or the whole new one, never a
// half-written file (results, captures, maps).
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <string_view>

namespace fvp::host {

/// Calls write(stream) on a temporary file beside `path`, then renames it to `path`.
/// write returns false on failure. Throws std::runtime_error naming `what` and the file
/// when anything fails; the temporary file is removed then.
void writeFileAtomically(const std::filesystem::path& path, std::string_view what,
                         const std::function<bool(std::ostream&)>& write);

/// The same for a block of bytes.
void writeFileAtomically(const std::filesystem::path& path, std::string_view what,
                         std::string_view bytes);

}  // namespace fvp::host
