// `fvp experiment` and `fvp merge`: the paper's experiment over many worlds, resumable and
// shardable (docs/design.md section 9; docs/experiment.md has the cluster recipe).
#include <unistd.h>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <tuple>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/trials/experiment.h"
#include "fvp/trials/sensitivity_report.h"
#include "trial_cli.h"

namespace fvp::apps {

namespace {

/// `fvp experiment`'s options: the runner's, and those the command turns into them.
struct ExperimentCommandOptions {
  trials::ExperimentOptions experiment;
  std::string planners = "fvp,rvp", shard, out, error_scale;
};

// Unused in the parse-only build of the CLI fuzz harness (FVP_ON_RUN).
[[maybe_unused]] void runExperimentCommand(const ExperimentCommandOptions* opt) {
  trials::ExperimentOptions o = opt->experiment;
  // Every comma-separated name, empty ones too: the runner rejects empty, unknown and
  // repeated planners with a message.
  o.planners.clear();
  for (std::size_t from = 0;;) {
    const std::size_t comma = opt->planners.find(',', from);
    o.planners.push_back(opt->planners.substr(from, comma - from));
    if (comma == std::string::npos) break;
    from = comma + 1;
  }
  if (opt->planners.empty()) o.planners.clear();
  if (!opt->shard.empty()) std::tie(o.shard_index, o.shard_count) = trials::parseShard(opt->shard);
  o.error_scale = opt->error_scale;
  // One writer from the first file on: --error-scale writes OUT/world.yaml before the
  // runner (which takes the same lock, shared within this process) starts.
  std::optional<host::OutputDirectoryLock> lock;
  if (!opt->error_scale.empty()) {
    (void)trials::parseErrorScale(opt->error_scale);  // a bad one fails before --out is made
    host::prepareOutputDirectory(opt->out, "experiment: --out");
    lock.emplace(opt->out, "experiment: --out");
  }
  if (!opt->error_scale.empty())
    o.trial.world_config =
        trials::writeScaledWorldConfig(o.trial.world_config, opt->error_scale, opt->out);
  o.out_dir = opt->out;
  const bool tty = isatty(STDERR_FILENO);
  const auto progress = [tty](const std::string& line) {
    std::cerr << (tty ? "\r\033[K" : "") << line << (tty ? "" : "\n") << std::flush;
  };
  // A warning on a line of its own: the next progress line must not overwrite it.
  const auto warning = [tty](const std::string& line) {
    std::cerr << (tty ? "\r\033[K" : "") << "fvp: warning: " << line << "\n" << std::flush;
  };
  trials::runExperiment(o, trials::runTrial, progress, warning);
  if (tty) std::cerr << "\n";
  std::cout << "wrote " << opt->out << "/{manifest.json, trials.jsonl, summary.json, table1.md"
            << (std::filesystem::exists(o.out_dir / "sizes.png") ? ", sizes.png" : "")
            << ", index.html}\n"
            << "open " << (o.out_dir / "index.html").string()
            << " for Table 1, the figures and every trial's 3-D viewer\n";
}

void addExperimentCommand(CLI::App& app) {
  auto opt = optionStorage<ExperimentCommandOptions>();
  auto* cmd =
      app.add_subcommand("experiment",
                         "Run every planner on the same simulated worlds; write trials.jsonl, "
                         "summary.json, table1.md, sizes.png and index.html to --out");
  cmd->add_option("--planners", opt->planners, "comma-separated planners (fvp, rvp)")
      ->capture_default_str();
  cmd->add_option("--trials", opt->experiment.trials, "worlds (seeds) per planner")
      ->check(decimalUnsigned())
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--first-seed", opt->experiment.first_seed, "seed of the first world")
      ->check(decimalUnsigned())
      ->capture_default_str();
  cmd->add_option("--error-scale", opt->error_scale,
                  "GROUP=FACTOR: the world's pose, stereo, wind, segmentation, light or all errors "
                  "times FACTOR (a sweep point; written to OUT/world.yaml)")
      ->check(errorScaleText());
  addTrialOptions(cmd, opt->experiment.trial, /*with_per_trial=*/false);
  cmd->add_option("--shard", opt->shard, "run shard i of n (0-based, 0 <= i < n), e.g. 0/4")
      ->check(shardText());
  cmd->add_flag("--resume", opt->experiment.resume, "skip trials already in trials.jsonl");
  cmd->add_option("--out", opt->out, "output directory")->required()->check(nonEmptyPath());
  FVP_ON_RUN(cmd, [opt] { runExperimentCommand(opt.get()); });
}

void addMergeCommand(CLI::App& app) {
  auto merge_out = optionStorage<std::string>();
  auto shards = optionStorage<std::vector<std::string>>();
  auto* merge = app.add_subcommand("merge", "Combine experiment shards into one experiment");
  merge->add_option("shards", *shards, "shard output directories")->required();
  merge->add_option("--out", *merge_out, "merged output directory")
      ->required()
      ->check(nonEmptyPath());
  FVP_ON_RUN(merge, [merge_out, shards] {
    std::vector<std::filesystem::path> dirs(shards->begin(), shards->end());
    trials::mergeExperiments(dirs, *merge_out, [](const std::string& line) {
      std::cerr << "fvp: warning: " << line << "\n";
    });
    std::cout << "merged " << dirs.size() << " shards into " << *merge_out << " (index.html: "
              << "Table 1, the figures and every trial's viewer)\n";
  });
}

void addSensitivityCommand(CLI::App& app) {
  auto sweep_out = optionStorage<std::string>();
  auto points = optionStorage<std::vector<std::string>>();
  auto* sensitivity =
      app.add_subcommand("sensitivity",
                         "Tabulate and plot a sweep of experiments made with --error-scale; write "
                         "sensitivity.json, sensitivity.md and sensitivity.png to --out");
  sensitivity->add_option("experiments", *points, "experiment directories (the sweep's points)")
      ->required();
  sensitivity->add_option("--out", *sweep_out, "output directory")
      ->required()
      ->check(nonEmptyPath());
  FVP_ON_RUN(sensitivity, [sweep_out, points] {
    std::vector<std::filesystem::path> dirs(points->begin(), points->end());
    const bool drawn = trials::writeSensitivityReport(
        dirs, *sweep_out,
        [](const std::string& line) { std::cerr << "fvp: warning: " << line << "\n"; });
    std::cout << "wrote " << *sweep_out << "/{sensitivity.json, sensitivity.md"
              << (drawn ? ", sensitivity.png" : "") << "}\n";
  });
}

}  // namespace

void addExperimentCommands(CLI::App& app) {
  addExperimentCommand(app);
  addMergeCommand(app);
  addSensitivityCommand(app);
}

}  // namespace fvp::apps
