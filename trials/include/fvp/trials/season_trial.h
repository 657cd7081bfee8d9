// A simulated season (docs/season.md "Simulated seasons", `fvp seasons`): one tree visited
// on given days, each visit a trial of the world grown to that day with its own draws
// (TrialOptions::season_day); the visits' results followed across the days by the library
// (host/season, as `fvp season` does for real visits), and that scored against the world's
// truth beside a simulated person with calipers (season_score.h).
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fvp/host/season/season_analysis.h"
#include "fvp/trials/season_score.h"
#include "fvp/trials/trial.h"

namespace fvp::trials {

struct SeasonTrialOptions {
  /// Every visit's settings (world, clock, stop, backend, ...); visit.seed is the season's
  /// tree. Its season_day, out_dir and on_progress are set per visit.
  TrialOptions visit;
  std::vector<double> days{0.0, 4.0, 7.0};  ///< increasing, each in the world's season range
  host::season::SeasonConfig season;
  double caliper_sigma_mm = kCaliperSigmaMm;
  /// DIR/day-<d>/ (each visit's trial files), DIR/season.json (the analysis, as `fvp season`
  /// writes it) and DIR/season_score.json; empty: nothing written.
  std::filesystem::path out_dir;
  std::function<void(const std::string&)> progress;  ///< a line per visit
  /// Keep a visit whose result.json is already in its directory (the same settings, seed and
  /// day; another is an error) instead of running it again: a season cut short resumes, and
  /// a finished one is rescored after its season_score.json is removed.
  bool reuse_visits = false;
  /// Each visit after the first starts from the one before it (TrialOptions::remembered_visit,
  /// docs/season.md "Visits remembered"): read from out_dir, which it needs. Off: each visit
  /// starts afresh, as a first visit does (docs/results.md: remembering gets the season's
  /// fates right, and costs later visits time).
  bool remember_visits = true;
};

/// The days' check: two or more, finite, increasing, within season_day's range. Throws
/// std::invalid_argument naming the offending day.
void checkSeasonDays(const std::vector<double>& days);

/// Runs the visits and scores the season. Returns the season's line: {"seed", "days",
/// "visits": [{day, sim_time_s, views, gt_fruitlets, matched, detections, mae_mm,
/// wall_time_s}], "score": scoreSeason's object}.
nlohmann::json runSeasonTrial(const SeasonTrialOptions& options);

struct SeasonExperimentOptions {
  SeasonTrialOptions season;  ///< every season's settings; its seed and out_dir set per season
  int seasons = 10;
  std::uint64_t first_seed = 1;
  int shard_index = 0, shard_count = 1;  ///< --shard i/n: seasons i, i + n, ...
  bool resume = false;
  /// DIR/season-<seed>/ each season (runSeasonTrial's files), DIR/summary.json, DIR/table.md.
  std::filesystem::path out_dir;
};

/// Runs this shard's seasons (seeds first_seed + k, k = shard_index mod shard_count), then
/// writes summary.json and table.md over every finished season in out_dir (so shards run into
/// one directory make one report). A season already finished there is skipped with resume
/// when its settings and days are these (else an error naming the first that differs), and
/// is an error without; with resume, an unfinished season keeps its finished visits
/// (SeasonTrialOptions::reuse_visits). Returns the summary.
nlohmann::json runSeasonExperiment(const SeasonExperimentOptions& options);

/// The finished seasons' lines in a directory (season-*/season_score.json), by seed.
std::vector<nlohmann::json> readSeasons(const std::filesystem::path& dir);

/// summary.json of some seasons' lines: the seasons pooled (association, gone, growth, fates
/// of robot and calipers, fruit-set error, each visit's time and sizing by its place in the
/// season).
nlohmann::json summarizeSeasons(const std::vector<nlohmann::json>& seasons);

/// table.md of a summary: the season table of docs/season.md.
std::string seasonTable(const nlohmann::json& summary);

}  // namespace fvp::trials
