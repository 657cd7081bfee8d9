// The sensitivity report of an error sweep (docs/simulation.md "Sweeping an error"): each
// experiment made with `fvp experiment --error-scale GROUP=FACTOR` is one point; the report
// tabulates MP, MAE and precision against the factor per group, planner and registration,
// and draws MAE and MP against the factor (gnuplot, the project's plotting path).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace fvp::trials {

struct SensitivityPoint {
  std::string group;        ///< pose, stereo, wind, segmentation, light or all
  double factor = 1.0;      ///< times the world config's magnitudes
  bool registered = false;  ///< --register-views
  std::string planner;      ///< a row of the experiment's summary (fvp, rvp, fvp-octomap, ...)
  int trials = 0;
  double match_percent = 0.0, mae_mm = 0.0, precision_percent = 0.0;
  std::string experiment;  ///< its directory
};

/// The points of the experiment directories (manifest and trials.jsonl of each), sorted by
/// group, planner, registration and factor. Throws std::runtime_error naming a directory
/// without an error scale in its manifest or without trials.
std::vector<SensitivityPoint> readSensitivityPoints(
    const std::vector<std::filesystem::path>& experiments);

/// sensitivity.json and sensitivity.md in out_dir (created), then sensitivity.png: a figure
/// gnuplot cannot draw is reported through warning and the tables stand. Returns whether the
/// figure was drawn.
bool writeSensitivityReport(const std::vector<std::filesystem::path>& experiments,
                            const std::filesystem::path& out_dir,
                            const std::function<void(const std::string&)>& warning);

}  // namespace fvp::trials
