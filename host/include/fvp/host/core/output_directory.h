// An output directory is checked before the work that fills it starts (a long trial must not
// fail at its end because --out names a file), and files an earlier run left there are
// removed first, so every file in it belongs to this run.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace fvp::host {

/// Creates dir (and its parents) when missing and checks that a file can be created in it.
/// Throws std::runtime_error naming `what` (e.g. "--out") and the path when dir exists as
/// something other than a directory, cannot be created or is not writable.
void prepareOutputDirectory(const std::filesystem::path& dir, const std::string& what);

/// Removes, where present, the files named in `outputs` (paths relative to dir) and, for
/// each directory in `numbered_dirs`, the files in it named like NNN.png or NNN.jpg (digits only):
/// what an earlier run into the same directory wrote. Nothing else is touched.
void removeStaleOutputs(const std::filesystem::path& dir, const std::vector<std::string>& outputs,
                        const std::vector<std::string>& numbered_dirs = {});

/// A numbered file's name, as removeStaleOutputs recognises it: dir/NNN.extension (at least
/// three digits, zero-padded; extension without its dot), e.g. "views/007.png".
std::string numberedFileName(const std::string& dir, int number, const std::string& extension);

}  // namespace fvp::host
