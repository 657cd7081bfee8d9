// `fvp run`: one simulated trial (docs/design.md section 9); writes result.json, the maps, the
// TSDF surface, the clusters and report.md to --out and prints a short summary.
#include <unistd.h>
#include <iomanip>
#include <iostream>
#include <memory>
#include <string>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/planner/planner_registry.h"
#include "fvp/trials/trial.h"
#include "trial_cli.h"

namespace fvp::apps {

void addRunCommand(CLI::App& app) {
  struct Options {
    trials::TrialOptions trial;
    std::string world, config, arm, out;
    int max_views = 0;
  };
  auto opt = optionStorage<Options>();
  auto* cmd = app.add_subcommand("run",
                                 "Run one simulated trial; write result.json, report.md and "
                                 "viewer.html (the trial in 3-D) to --out");
  cmd->add_option("--planner", opt->trial.planner, "viewpoint planner: fvp | rvp")
      ->check(CLI::IsMember(plannerNames()))
      ->capture_default_str();
  cmd->add_option("--seed", opt->trial.seed, "world seed")
      ->check(decimalUnsigned())
      ->capture_default_str();
  cmd->add_option("--world", opt->world, "world config YAML (default: built-in defaults)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--config", opt->config, "planner config YAML (default: the planner's)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--arm", opt->arm,
                  "arm config YAML (default: built-in, robot/config/arm_default.yaml)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--max-views", opt->max_views, "stop after this many views (0: no limit)")
      ->check(decimalUnsigned());
  addTrialOptions(cmd, opt->trial);
  cmd->add_option("--out", opt->out, "output directory")->required()->check(nonEmptyPath());
  FVP_ON_RUN(cmd, [opt] {
    trials::TrialOptions trial = opt->trial;
    trial.world_config = opt->world;
    trial.planner_config = opt->config;
    trial.arm_config = opt->arm;
    trial.out_dir = opt->out;
    if (opt->max_views > 0) trial.max_views = opt->max_views;
    const bool tty = isatty(STDERR_FILENO);
    trial.on_progress = [tty](const trials::TrialProgress& p) {
      std::cerr << (tty ? "\r" : "") << "view " << p.views << "  sim " << std::fixed
                << std::setprecision(1) << p.sim_time_s << " / " << p.budget_s << " s  wall "
                << p.wall_time_s << " s" << (tty ? "   " : "\n") << std::flush;
    };
    trial.on_warning = [tty](const std::string& text) {
      std::cerr << (tty ? "\n" : "") << "fvp: warning: " << text << "\n";
    };
    const nlohmann::json result = trials::runTrial(trial);
    if (tty) std::cerr << "\n";
    std::cout << trials::trialSummary(result)
              << "report: " << (std::filesystem::path(opt->out) / "report.md").string() << "\n"
              << "3-D viewer: " << (std::filesystem::path(opt->out) / "viewer.html").string()
              << " (open it in a browser)\n";
    // The result is kept; an extra that could not be written (a full disk) still fails the
    // command, so that a script notices.
    if (const auto it = result.find("unwritten_outputs"); it != result.end())
      throw std::runtime_error(std::to_string(it->size()) + " of the trial's files not written (" +
                               it->dump() + "; see the warnings above); result.json holds " +
                               "the trial");
  });
}

}  // namespace fvp::apps
