// `fvp experiment` and `fvp merge`: the paper's experiment over many worlds, resumable and
// shardable (DESIGN.md section 9; docs/experiment.md has the cluster recipe).
#include <unistd.h>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "commands.h"
#include "fvp/robot/sim/experiment.h"

namespace fvp::apps {

void addExperimentCommands(CLI::App& app) {
  struct Options {
    robot::sim::ExperimentOptions experiment;
    std::string planners = "fvp,rvp", shard, world, config, out;
    int max_views = 0;
  };
  auto opt = std::make_shared<Options>();
  auto* cmd =
      app.add_subcommand("experiment",
                         "Run every planner on the same simulated worlds; write trials.jsonl, "
                         "summary.json, table1.md and sizes.png to --out");
  cmd->add_option("--planners", opt->planners, "comma-separated planners (fvp, rvp)")
      ->capture_default_str();
  cmd->add_option("--trials", opt->experiment.trials, "worlds (seeds) per planner")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--first-seed", opt->experiment.first_seed, "seed of the first world")
      ->capture_default_str();
  cmd->add_option("--world", opt->world, "world config YAML")->check(CLI::ExistingFile);
  cmd->add_option("--config", opt->config, "planner config YAML")->check(CLI::ExistingFile);
  cmd->add_option("--budget-s", opt->experiment.trial.budget_s, "simulated budget per trial, s")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--backend", opt->experiment.trial.backend, "cpu | opencl | vulkan | auto")
      ->capture_default_str();
  cmd->add_option("--engine", opt->experiment.trial.engine,
                  "map engine for every planner (default: each planner's own)")
      ->check(CLI::IsMember({"grid", "octomap"}));
  cmd->add_option("--clock", opt->experiment.trial.clock, "wall | fixed")
      ->check(CLI::IsMember({"wall", "fixed"}))
      ->capture_default_str();
  cmd->add_option("--max-views", opt->max_views, "stop each trial after this many views");
  cmd->add_option("--shard", opt->shard, "run shard i of n (0-based), e.g. 0/4");
  cmd->add_flag("--resume", opt->experiment.resume, "skip trials already in trials.jsonl");
  cmd->add_option("--out", opt->out, "output directory")->required();
  cmd->callback([opt] {
    robot::sim::ExperimentOptions o = opt->experiment;
    o.planners.clear();
    std::stringstream list(opt->planners);
    for (std::string p; std::getline(list, p, ',');)
      if (!p.empty()) o.planners.push_back(p);
    if (!opt->shard.empty()) {
      const auto slash = opt->shard.find('/');
      try {
        if (slash == std::string::npos) throw std::invalid_argument("no slash");
        o.shard_index = std::stoi(opt->shard.substr(0, slash));
        o.shard_count = std::stoi(opt->shard.substr(slash + 1));
      } catch (const std::exception&) {
        throw std::invalid_argument("--shard: expected i/n, e.g. 0/4, got '" + opt->shard + "'");
      }
    }
    o.trial.world_config = opt->world;
    o.trial.planner_config = opt->config;
    if (opt->max_views > 0) o.trial.max_views = opt->max_views;
    o.out_dir = opt->out;
    const bool tty = isatty(STDERR_FILENO);
    robot::sim::runExperiment(o, robot::sim::runTrial, [tty](const std::string& line) {
      std::cerr << (tty ? "\r\033[K" : "") << line << (tty ? "" : "\n") << std::flush;
    });
    if (tty) std::cerr << "\n";
    std::cout << "wrote " << opt->out << "/{trials.jsonl, summary.json, table1.md, sizes.png}\n";
  });

  auto merge_out = std::make_shared<std::string>();
  auto shards = std::make_shared<std::vector<std::string>>();
  auto* merge = app.add_subcommand("merge", "Combine experiment shards into one experiment");
  merge->add_option("shards", *shards, "shard output directories")->required();
  merge->add_option("--out", *merge_out, "merged output directory")->required();
  merge->callback([merge_out, shards] {
    std::vector<std::filesystem::path> dirs(shards->begin(), shards->end());
    robot::sim::mergeExperiments(dirs, *merge_out);
    std::cout << "merged " << dirs.size() << " shards into " << *merge_out << "\n";
  });
}

}  // namespace fvp::apps
