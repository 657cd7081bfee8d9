// `fvp plan`: one planning iteration on a map of K simulated views; writes plan.json and
// candidates.ply (docs/design.md section 9).
#include <iostream>
#include <memory>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/planner/planner_registry.h"
#include "fvp/trials/plan_once.h"

namespace fvp::apps {

void addPlanCommand(CLI::App& app) {
  auto opt = optionStorage<trials::PlanOnceOptions>();
  auto world = optionStorage<std::string>(), config = optionStorage<std::string>(),
       out = optionStorage<std::string>();
  auto* cmd = app.add_subcommand(
      "plan",
      "One planning iteration on a map of K simulated views; write plan.json and "
      "candidates.ply to --out");
  cmd->add_option("--planner", opt->planner, "fvp | rvp")
      ->check(CLI::IsMember(plannerNames()))
      ->capture_default_str();
  cmd->add_option("--seed", opt->seed, "world seed")
      ->check(decimalUnsigned())
      ->capture_default_str();
  cmd->add_option("--views", opt->views, "views orbiting the cluster that build the map")
      ->check(decimalUnsigned())
      ->check(CLI::Range(1, 360))
      ->capture_default_str();
  addBackendOption(cmd, opt->backend, "compute backend");
  cmd->add_option("--engine", opt->engine, "grid | octomap (default: the planner's)")
      ->check(CLI::IsMember(mapEngineNames()));
  cmd->add_option("--world", *world, "world config YAML")->check(CLI::ExistingFile);
  cmd->add_option("--config", *config, "planner config YAML")->check(CLI::ExistingFile);
  auto captures = optionStorage<std::string>(), perception = optionStorage<std::string>();
  cmd->add_option("--captures", *captures,
                  "plan from a robot's capture set (docs/capture-format.md) instead of "
                  "simulated views: the next best view from where the last capture was taken")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--perception-config", *perception,
                  "perception config YAML for --captures (tag, Cluster Region, HSV)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", *out, "output directory")->required()->check(nonEmptyPath());
  FVP_ON_RUN(cmd, [opt, world, config, out, captures, perception] {
    trials::PlanOnceOptions o = *opt;
    o.captures_dir = *captures;
    o.perception_config = *perception;
    o.world_config = *world;
    o.planner_config = *config;
    o.out_dir = *out;
    const nlohmann::json plan = trials::planOnce(o);
    for (const auto& w : plan["warnings"])
      std::cerr << "fvp: warning: " << w.get<std::string>() << "\n";
    std::size_t reachable = 0;
    for (const auto& c : plan["candidates"]) reachable += c["reachable"].get<bool>();
    std::cout << "planner " << o.planner << ", engine " << plan["engine"].get<std::string>()
              << ", backend " << plan["backend"].get<std::string>() << "\n"
              << plan["candidates"].size() << " candidates, " << reachable << " reachable, "
              << plan["move_attempts"] << " move attempts, chosen "
              << (plan["chosen"].is_null() ? std::string("none")
                                           : std::to_string(plan["chosen"].get<int>()))
              << "\ntimings_s " << plan["timings_s"].dump() << "\nwrote " << *out
              << "/{plan.json, candidates.ply}\n";
  });
}

}  // namespace fvp::apps
