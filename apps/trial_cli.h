// The options of a simulated trial, declared once for `fvp run` and `fvp experiment` (the
// Python keywords are checked against them: python/tests/test_trial_options.py). Names are
// parsed into the run specification's types here; nothing after parsing compares them.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/host/nbv/stop_rule.h"
#include "fvp/robot/sim/sim_clock.h"
#include "fvp/trials/trial.h"

namespace fvp::apps {

inline void addTrialOptions(CLI::App* cmd, trials::TrialOptions& trial) {
  using host::nbv::StopRule;
  using host::nbv::stopRuleFromString;
  using host::nbv::toString;
  using Mode = robot::sim::SimClock::Mode;
  cmd->add_option("--budget-s", trial.budget_s, "simulated time budget per cluster, seconds")
      ->check(finiteNumber())
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--backend", trial.backend, "compute backend: cpu | opencl | vulkan | auto")
      ->capture_default_str();
  cmd->add_option("--engine", trial.engine,
                  "map engine: grid | octomap (default: each planner's own, grid for fvp, "
                  "octomap for rvp)")
      ->check(CLI::IsMember(mapEngineNames()));
  cmd->add_option_function<std::string>(
         "--stop", [&trial](const std::string& name) { trial.stop = *stopRuleFromString(name); },
         "budget: run the whole budget (the paper) | auto: stop once the cluster's sizes have "
         "settled, the budget being the cap")
      ->check(CLI::IsMember({toString(StopRule::kBudget), toString(StopRule::kAuto)}))
      ->default_str(toString(trial.stop));
  cmd->add_flag("--confirm-detections,!--no-confirm-detections", trial.confirm_detections,
                "with --stop auto: look again at detections sized by a sphere fit to less than "
                "a hemisphere before a cluster is done (the default; docs/nbv-loop.md)");
  cmd->add_flag("--release-left-out,!--no-release-left-out", trial.release_left_out,
                "with --stop auto: a fruitlet the planner has looked for twice in vain no longer "
                "holds the stop (the default; docs/nbv-loop.md)");
  cmd->add_flag_function(
      "--register-views,!--no-register-views",
      [&trial](std::int64_t count) { trial.register_views = count > 0; },
      "align each view to the earlier ones before fusing it (a counter-measure to pose errors; "
      "default: as the world config's run_register_views says, on for the field preset)");
  cmd->add_flag("--size-history", trial.record_size_history,
                "size after every view and keep each sizing in result.json (size_history; always "
                "with --stop auto; not charged to the clock)");
  cmd->add_option_function<std::string>(
         "--clock",
         [&trial](const std::string& name) {
           trial.clock = robot::sim::SimClock::modeFromString(name);
         },
         "simulated clock: wall (charge measured compute time) | fixed (a constant)")
      ->check(CLI::IsMember({robot::sim::SimClock::modeName(Mode::kWall),
                             robot::sim::SimClock::modeName(Mode::kFixed)}))
      ->default_str(robot::sim::SimClock::modeName(trial.clock));
}

}  // namespace fvp::apps
