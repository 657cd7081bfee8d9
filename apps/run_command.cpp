// `fvp run`: one simulated trial (docs/design.md section 9); writes result.json, the maps, the
// TSDF surface, the clusters and report.md to --out and prints a short summary.
#include <unistd.h>
#include <iomanip>
#include <iostream>
#include <memory>
#include <string>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/trials/trial.h"
#include "stereo_bag_files.h"
#include "trial_cli.h"

namespace fvp::apps {

void addRunCommand(CLI::App& app) {
  struct Options {
    trials::TrialOptions trial;
    std::string out;
    std::string bag;  ///< also the trial's frames as a ROS bag
  };
  auto opt = optionStorage<Options>();
  auto* cmd = app.add_subcommand("run",
                                 "Run one simulated trial; write result.json, report.md and "
                                 "viewer.html (the trial in 3-D) to --out");
  addTrialOptions(cmd, opt->trial, /*with_per_trial=*/true);
  cmd->add_option("--remember", opt->trial.remembered_visit,
                  "an earlier visit of the same tree (its result.json or --out directory): "
                  "each cluster starts from what it learned (docs/season.md)")
      ->check(nonEmptyPath());
  cmd->add_option("--bag", opt->bag,
                  "also record every frame the trial captured as this ROS bag: stereo pairs, "
                  "camera infos and the told pose on tf, stamped 1 s + simulated time, and its "
                  "RViz markers (docs/ros.md; fvp size --bag sizes it)")
      ->check(nonEmptyPath());
  cmd->add_option("--out", opt->out, "output directory")->required()->check(nonEmptyPath());
  FVP_ON_RUN(cmd, [opt] {
    trials::TrialOptions trial = opt->trial;
    std::unique_ptr<TrialBagRecorder> recorder;
    if (!opt->bag.empty()) {
      recorder = std::make_unique<TrialBagRecorder>(opt->bag);
      trial.on_frame = [&recorder](const host::StereoFrame& frame, double sim_time_s) {
        recorder->add(frame, sim_time_s);
      };
    }
    trial.out_dir = opt->out;
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
    if (recorder) {
      const std::size_t pairs = recorder->finish(result);
      std::cout << "bag -> " << opt->bag << " (" << pairs << " stereo pairs)\n";
    }
    // The result is kept; an extra that could not be written (a full disk) still fails the
    // command, so that a script notices.
    if (const auto it = result.find("unwritten_outputs"); it != result.end())
      throw std::runtime_error(std::to_string(it->size()) + " of the trial's files not written (" +
                               it->dump() + "; see the warnings above); result.json holds " +
                               "the trial");
  });
}

}  // namespace fvp::apps
