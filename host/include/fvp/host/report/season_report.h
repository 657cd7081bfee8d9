// A season's report (docs/season.md "The season report"): season.md, per cluster each
// fruitlet's sizes and growth rate with its predicted fate and the cluster's predicted fruit
// set, the sample's, and each visit's source; season.png, size against day for every
// fruitlet, one panel per cluster, coloured by predicted fate (drawn by gnuplot).
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fvp/host/season/season_analysis.h"

namespace fvp::host::report {

/// season.md's text; `figure` names the figure beside it, empty when none was drawn;
/// viewers[v], where given and not empty, links visit v's 3-D viewer; season_viewer, when not
/// empty, links the season's.
std::string seasonMarkdown(const season::SeasonAnalysis& season, const std::string& figure,
                           const std::vector<std::string>& viewers = {},
                           const std::string& season_viewer = {});

/// The season viewer's scene (docs/viewer.md): each cluster's tag where the cluster's last
/// visit that gave its pose saw it, and each fruitlet track there at its last size, coloured
/// by its predicted fate; a gone one where it was last seen. Clusters without a tag pose are
/// left out.
nlohmann::json seasonViewerScene(const season::SeasonAnalysis& season);

/// season.png's gnuplot script: one panel per cluster (at most 8), a line per fruitlet track,
/// green persists, red abscises, grey gone, black unknown.
std::string seasonFigureScript(const season::SeasonAnalysis& season);

/// Writes dir/season.png (a figure gnuplot cannot draw goes to warning, and no stale figure
/// is left), dir/season_viewer.html (when a cluster has a tag pose) and then dir/season.md,
/// each atomically, linking each visit's viewer.html where
/// one lies beside its source (a trial's result.json, a sized capture set's fruitlets.json).
/// Returns whether the figure was drawn.
bool writeSeasonReport(const season::SeasonAnalysis& season, const std::filesystem::path& dir,
                       const std::function<void(const std::string&)>& warning = {});

}  // namespace fvp::host::report
