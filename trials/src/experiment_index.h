// An experiment's index.html (docs/experiment.md): Table 1, the figures, and every trial
// with a link to its viewer and report, for a person to start from.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace fvp::trials {

/// The trial's output directory (where its viewer.html and report.md are).
using TrialDirFn = std::function<std::filesystem::path(const nlohmann::json& trial)>;

/// Writes dir/index.html: table_markdown (table1.md's tables) as HTML tables, sizes.png,
/// accuracy_vs_time.png and time_split.png where present, and one row per trial linking its
/// viewer.html and report.md (relative links; "-" where a trial's files are not there).
void writeIndexPage(const std::filesystem::path& dir, const std::string& table_markdown,
                    const std::vector<nlohmann::json>& trials, const TrialDirFn& trial_dir);

}  // namespace fvp::trials
