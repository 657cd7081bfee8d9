// The paper's experiment (DESIGN.md section 9, `fvp experiment` / `fvp merge`): every
// planner on the same worlds, one trial per (planner, seed); each finished trial is one line
// of DIR/trials.jsonl, appended atomically (one write, then fsync), so an interrupted run
// loses at most the trial in flight and --resume skips what is there. Shards partition the
// (planner, seed) list deterministically; merging shards gives what one run gives.
// From trials.jsonl: summary.json (per planner, fruitlets pooled over trials), table1.md
// (next to the paper's Table 1) and sizes.png (the size distributions of Figure 7).
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fvp/robot/sim/trial.h"

namespace fvp::robot::sim {

struct ExperimentOptions {
  std::vector<std::string> planners{"fvp", "rvp"};
  int trials = 35;
  std::uint64_t first_seed = 1;
  int shard_index = 0, shard_count = 1;  ///< --shard i/n
  bool resume = false;
  TrialOptions trial;  ///< world, config, budget, backend, engine, clock, max views
  std::filesystem::path out_dir;
};

using TrialRunner = std::function<nlohmann::json(const TrialOptions&)>;

/// Runs the experiment's trials of this shard (skipping finished ones with resume) and
/// writes the reports. progress(line) is called with a short status line per event.
/// Throws std::invalid_argument / std::runtime_error for bad options and files.
void runExperiment(const ExperimentOptions& options, const TrialRunner& run_trial,
                   const std::function<void(const std::string&)>& progress);

/// Reads trials.jsonl: one JSON object per line. A malformed line is an error naming the file
/// and the line number, except a last line without its newline (a write cut short), which
/// is reported through `warning` and ignored.
std::vector<nlohmann::json> readTrials(const std::filesystem::path& jsonl,
                                       const std::function<void(const std::string&)>& warning);

/// summary.json's object: per planner key {"trials", "gt_fruitlets", "matched",
/// "match_percent", "mae_mm", "mape_percent", "precision_percent", "mean_views",
/// "wall_s_per_trial"}, plus "<planner>-paper-sizing" keys where trials carry the paper
/// estimator's sizes.
nlohmann::json summarize(const std::vector<nlohmann::json>& trials);

/// summary.json, table1.md and sizes.png from trials.jsonl in dir.
void writeReports(const std::filesystem::path& dir, const std::vector<nlohmann::json>& trials);

/// `fvp merge`: combines the trials.jsonl of shard directories into out_dir (duplicate
/// (planner, seed) trials are an error) and writes the reports.
void mergeExperiments(const std::vector<std::filesystem::path>& shard_dirs,
                      const std::filesystem::path& out_dir);

}  // namespace fvp::robot::sim
