// The paper's experiment (docs/design.md section 9, `fvp experiment` / `fvp merge`): every
// planner on the same worlds, one trial per (planner, seed); each finished trial is one line
// of DIR/trials.jsonl, appended atomically (one write, then fsync), so an interrupted run
// loses at most the trial in flight and --resume skips what is there. Shards partition the
// (planner, seed) list deterministically; merging shards gives what one run gives.
// From trials.jsonl: summary.json (per planner, fruitlets pooled over trials), table1.md
// (next to the paper's Table 1) and sizes.png (the size distributions of Figure 7).
// DIR/manifest.json records the settings that define the rows; resume and merge refuse a
// mismatch (experiment_directory.h, docs/experiment.md).
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "fvp/trials/experiment_directory.h"
#include "fvp/trials/trial.h"

namespace fvp::trials {

/// The most worlds (--trials) an experiment runs: at minutes a trial, more is a typo.
inline constexpr int kMaxExperimentTrials = 100'000;

struct ExperimentOptions {
  std::vector<std::string> planners{"fvp", "rvp"};
  int trials = 35;
  std::uint64_t first_seed = 1;
  int shard_index = 0, shard_count = 1;  ///< --shard i/n
  bool resume = false;
  /// --error-scale's GROUP=FACTOR when the world config was scaled (writeScaledWorldConfig),
  /// recorded in the manifest for the sensitivity report; empty otherwise.
  std::string error_scale;
  TrialOptions trial;  ///< world, config, budget, backend, engine, clock, max views
  std::filesystem::path out_dir;
};

using TrialRunner = std::function<nlohmann::json(const TrialOptions&)>;
using MessageSink = std::function<void(const std::string&)>;

/// --error-scale GROUP=FACTOR (docs/simulation.md "Sweeping an error"): the world config
/// (world, or the default when empty) with that error group's magnitudes times FACTOR,
/// written to out_dir/world.yaml (out_dir created) for the trials to read and the manifest
/// to stamp. Returns that path. Throws std::invalid_argument for a bad GROUP=FACTOR.
std::filesystem::path writeScaledWorldConfig(const std::filesystem::path& world,
                                             const std::string& error_scale,
                                             const std::filesystem::path& out_dir);

/// Runs the experiment's trials of this shard (skipping finished ones with resume) and
/// writes the reports. Before the first trial: the options are checked, out_dir is made (an
/// existing non-directory is an error) and probed for writing, and DIR/manifest.json is
/// written for a new directory or compared with the options for an existing one (a
/// different setting is an error naming it; trials.jsonl without a manifest is an error).
/// A torn last line of trials.jsonl is cut off before anything is appended. progress(line)
/// gets a short status line per event; warning(line) gets warnings (a torn line, a figure
/// not drawn), or progress when warning is empty. Throws std::invalid_argument /
/// std::runtime_error for bad options and files.
void runExperiment(const ExperimentOptions& options, const TrialRunner& run_trial,
                   const MessageSink& progress, const MessageSink& warning = {});

/// summary.json's object: per planner key {"trials", "gt_fruitlets", "matched",
/// "match_percent", "mae_mm", "mape_percent", "precision_percent", "mean_views",
/// "wall_s_per_trial"}, plus "<planner>-paper-sizing" keys where trials carry the paper
/// estimator's sizes. The trials must have passed checkTrial (readTrials does that).
nlohmann::json summarize(const std::vector<nlohmann::json>& trials);

/// summary.json and table1.md from checked trials, then sizes.png: a figure gnuplot cannot
/// draw is reported through warning and noted in table1.md, and returns false (no stale
/// sizes.png is left); the reports stand. Returns whether sizes.png was drawn. Last,
/// index.html links the tables, figures and each trial's viewer.html and report.md, found
/// by trial_dir (default: dir/trials/<planner>-<seed>, where runExperiment puts them).
bool writeReports(
    const std::filesystem::path& dir, const std::vector<nlohmann::json>& trials,
    const MessageSink& warning = {},
    const std::function<std::filesystem::path(const nlohmann::json& trial)>& trial_dir = {});

/// `fvp merge`: combines the trials.jsonl of experiment directories into out_dir and writes
/// manifest.json (kind "merged") and the reports. Refused: a directory without a manifest,
/// directories whose row-defining settings differ (mergeDifference), a trial (row, seed) in
/// two directories, out_dir among the sources, and an out_dir that holds a run's trials.
void mergeExperiments(const std::vector<std::filesystem::path>& shard_dirs,
                      const std::filesystem::path& out_dir, const MessageSink& warning = {});

}  // namespace fvp::trials
