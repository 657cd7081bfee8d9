// The files of an experiment directory (`fvp experiment` / `fvp merge`, docs/experiment.md)
// and their contract, read and checked: trials.jsonl (one finished trial a line) and
// manifest.json (the settings that define the experiment's rows). Links nlohmann_json and the
// standard library only (library fvp_experiment_directory; the settings list and its types
// are header-only), so that a fuzzing harness can link the readers alone.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fvp/trials/trial.h"

namespace fvp::trials {

/// A file's bytes; nothing when it cannot be opened (the directory's readers and the
/// experiment runner share it).
std::optional<std::string> readFileBytes(const std::filesystem::path& path);

/// Reads trials.jsonl: one JSON object per line (empty lines are skipped), each checked
/// against the fields the reports read (checkTrial). A line that is not a valid trial is an
/// error `FILE: line N: ...`; the same trial (row key and seed) on two lines is an error
/// naming both lines. A last line without its newline (a write cut short) is reported
/// through `warning` and ignored. A missing file holds no trials.
std::vector<nlohmann::json> readTrials(const std::filesystem::path& jsonl,
                                       const std::function<void(const std::string&)>& warning);

/// Checks one trial's result object against the fields the reports read; throws
/// std::runtime_error "`where`: field 'X': expected Y, got Z". The fields: planner (a known
/// planner), seed (an unsigned integer), engine (a string, optional), views and detections
/// (non-negative integers, optional), wall_time_s (a finite non-negative number, optional),
/// fruitlets and fruitlets_paper_sizing (optional) arrays of objects with gt_size_mm (a
/// finite positive number), matched (a bool) and est_size_mm (a finite number when matched).
void checkTrial(const nlohmann::json& trial, const std::string& where);

/// The error groups of --error-scale (robot::sim::WorldConfig::errorGroups(), held equal by
/// a test): pose, stereo, wind, segmentation, light, all.
const std::vector<std::string>& errorScaleGroups();
/// The largest --error-scale factor (a sweep point is a multiple of the world config's
/// errors; beyond this it is no longer a magnitude the model means).
inline constexpr double kMaxErrorScaleFactor = 1000.0;

/// Parses --shard's "i/n": two decimal integers (no sign, no leading zeros), 0 <= i < n.
/// Throws std::invalid_argument. (Here, with the other readers of experiment text, so that
/// the option checks need no trial code.)
std::pair<int, int> parseShard(const std::string& text);

/// --error-scale's GROUP=FACTOR split into its group and factor: GROUP one of
/// errorScaleGroups(), FACTOR a decimal number from 0 to kMaxErrorScaleFactor (no sign,
/// exponent-free forms and exponents both fine, no hex, inf or nan). Throws
/// std::invalid_argument naming the text and what was expected.
std::pair<std::string, double> parseErrorScale(const std::string& error_scale);

/// A trial's summary row: its planner, plus "-<engine>" when that is not the planner's
/// default engine (fvp: grid, rvp: octomap), so the octomap ablation of FVP is its own row.
/// The trial must have passed checkTrial.
std::string trialRowKey(const nlohmann::json& trial);

/// FNV-1a 64 of some bytes as 16 lowercase hex digits (a config file's stamp).
std::string fnv1a64Hex(std::string_view bytes);

/// A config file an experiment ran with: its path and the hash of its bytes, so that an
/// edited file is caught. An empty path: the built-in defaults (and an empty hash).
struct ConfigFileStamp {
  std::string path;     ///< absolute, for the reader; not compared
  std::string fnv1a64;  ///< fnv1a64Hex of the file's bytes; compared
};

/// DIR/manifest.json: written when `fvp experiment` creates DIR (kind "run") or by `fvp
/// merge` (kind "merged"). Row-defining settings are those that change what a trial
/// measures; trials with different ones must not be pooled into one Table 1 row.
struct ExperimentManifest {
  /// 2: the settings written through the trial's settings list (max_views null for no
  /// limit, size_history added). 1 is read too.
  static constexpr int kFormatVersion = 2;
  std::string kind = "run";  ///< "run" (fvp experiment) or "merged" (fvp merge)
  /// The trials' settings: every setting of trials/trial_fields.h but the per-trial planner
  /// and seed, written and read through that list under their keys. register_views is
  /// resolved; under stop budget the automatic stop's switches are recorded false (they do
  /// nothing there). Row-defining (resume and merge refuse a difference) except the engine
  /// (resume only: the row key shows it) and the backend (recorded only: it picks the compute
  /// device, not what a trial measures). Settings added after format 1 read as off when
  /// absent (stop budget, no view registration, switches off, the built-in arm).
  TrialOptions settings;
  /// The config files of the settings (world_config, planner_config, arm_config), by key.
  std::map<std::string, ConfigFileStamp> configs;
  /// --error-scale GROUP=FACTOR, or empty; the world config's hash already tells runs apart,
  /// this names the sweep point (absent in a manifest: empty).
  std::string error_scale;
  /// What the simulated clock charged the trials (robot/sim/sim_clock.h), so that resume and
  /// merge never pool trials timed by different clocks: clockChargesFor(the run's stereo
  /// pass), or, in a manifest without the key, kClockChargesBeforePerception.
  std::string clock_charges = kClockCharges;
  /// With SGBM's stereo pass (the default; the same words since 2026-11-30's charges).
  static constexpr const char* kClockCharges =
      "capture, perception and every compute stage (fixed clock: 0.2 s, 0.4 s, 0.1 s each; "
      "a motion plan at least its validity checks at 660 000 a second)";
  /// With the guided stereo pass: its perception charged 0.2 s (before 2026-12-01 it was
  /// charged SGBM's 0.4 s under kClockCharges, and those runs are not pooled with these).
  static constexpr const char* kClockChargesGuidedStereo =
      "capture, perception and every compute stage (fixed clock: capture 0.2 s, perception "
      "0.2 s for the guided stereo pass, each other stage 0.1 s; a motion plan at least its "
      "validity checks at 660 000 a second)";
  static const char* clockChargesFor(bool guided_stereo) {
    return guided_stereo ? kClockChargesGuidedStereo : kClockCharges;
  }
  static constexpr const char* kClockChargesBeforePerception =
      "capture and the compute stages but not perception (an fvp before 2026-11-30)";
  // The run's own plan (kind "run" only). Resume refuses a difference; merge does not
  // compare them (shards differ in them by design).
  std::vector<std::string> planners;
  int trials = 0;
  std::uint64_t first_seed = 0;
  int shard_index = 0, shard_count = 1;
  /// Kind "merged": the merged directories (absolute paths).
  std::vector<std::string> sources;

  nlohmann::ordered_json toJson() const;
};

/// Reads and checks manifest.json; throws std::runtime_error "FILE: ..." (not found, not
/// JSON, `field 'X': expected Y`, a newer format version).
ExperimentManifest readManifest(const std::filesystem::path& path);

/// A setting that differs between two manifests, with both values as text.
struct ManifestDifference {
  std::string setting, old_value, new_value;
};

/// The first setting `now` changes against `old` that resume refuses: the row-defining
/// settings, then engine, what the clock charges, planners, trials, first_seed and shard
/// (backend is recorded only: it picks the compute device, not what a trial measures).
std::optional<ManifestDifference> resumeDifference(const ExperimentManifest& old,
                                                   const ExperimentManifest& now);

/// The first row-defining setting in which two experiments differ (what merge refuses): every
/// setting but the engine and the backend, in the settings list's order (configs by content
/// hash), then what the clock charges.
std::optional<ManifestDifference> mergeDifference(const ExperimentManifest& a,
                                                  const ExperimentManifest& b);

}  // namespace fvp::trials
