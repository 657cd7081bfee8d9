// `fvp seasons`: simulated seasons, each a tree visited on given days with the automatic stop
// (or the given stop), followed across the visits and scored against the truth beside a
// simulated person with calipers (docs/season.md "Simulated seasons").
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/host/core/number_text.h"
#include "fvp/trials/experiment.h"
#include "trial_cli.h"
#ifndef FVP_CLI_PARSE_ONLY  // the parse-only fuzz build takes the options, not the work
#include "fvp/trials/season_trial.h"
#endif

namespace fvp::apps {
namespace {

/// "0,4,7": the day texts between the commas.
std::vector<std::string> dayTexts(const std::string& text) {
  std::vector<std::string> days;
  for (std::size_t from = 0;;) {
    const std::size_t comma = text.find(',', from);
    days.push_back(text.substr(from, comma - from));
    if (comma == std::string::npos) return days;
    from = comma + 1;
  }
}

/// Decimal days, comma-separated (their order and range: trials::checkSeasonDays).
CLI::Validator dayListText() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        for (const std::string& day : dayTexts(text))
          if (!host::isDecimalNumberText(day, false))
            return "expected decimal days separated by commas (e.g. 0,4,7), got '" + day + "'";
        return {};
      },
      "DAY,DAY,...", "dayList");
}

[[maybe_unused]] std::vector<double> parseDays(const std::string& text) {
  std::vector<double> days;
  for (const std::string& day : dayTexts(text)) days.push_back(std::strtod(day.c_str(), nullptr));
  return days;
}

struct SeasonsCommandOptions {
  trials::TrialOptions visit;
  int seasons = 10;
  std::uint64_t first_seed = 1;
  bool resume = false, forget_visits = false;
  std::optional<double> caliper_sigma_mm;
  std::string days = "0,4,7", shard, out;
};

}  // namespace

void addSeasonsCommand(CLI::App& app) {
  auto opt = optionStorage<SeasonsCommandOptions>();
  opt->visit.stop = host::nbv::StopRule::kAuto;
  auto* cmd = app.add_subcommand(
      "seasons",
      "Simulated seasons: each tree visited on --days (a trial of the world grown to each day), "
      "its fruitlets followed across the visits and scored against the truth and a person with "
      "calipers; season-<seed>/, summary.json and table.md to --out");
  cmd->add_option("--seasons", opt->seasons, "seasons (trees, one seed each)")
      ->check(decimalUnsigned())
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--first-seed", opt->first_seed, "seed of the first season's tree")
      ->check(decimalUnsigned())
      ->capture_default_str();
  cmd->add_option("--days", opt->days, "the visits' days, increasing (two or more)")
      ->check(dayListText())
      ->capture_default_str();
  cmd->add_option_function<double>(
         "--caliper-sigma-mm", [opt](double sigma) { opt->caliper_sigma_mm = sigma; },
         "the simulated caliper reading's standard deviation, mm (default: 0.2, docs/season.md)")
      ->check(numberFromZero(false));
  addTrialOptions(cmd, opt->visit, /*with_per_trial=*/false);
  cmd->add_option("--shard", opt->shard, "run shard i of n (0-based, 0 <= i < n), e.g. 0/2")
      ->check(shardText());
  cmd->add_flag("--resume", opt->resume, "keep the seasons already finished in --out");
  cmd->add_flag("--forget-visits", opt->forget_visits,
                "start every visit afresh (default: each starts from the one before it)");
  cmd->add_option("--out", opt->out, "output directory")->required()->check(nonEmptyPath());
  FVP_ON_RUN(cmd, [opt] {
    trials::SeasonExperimentOptions o;
    o.season.visit = opt->visit;
    o.season.days = parseDays(opt->days);
    if (opt->caliper_sigma_mm) o.season.caliper_sigma_mm = *opt->caliper_sigma_mm;
    o.seasons = opt->seasons;
    o.first_seed = opt->first_seed;
    o.resume = opt->resume;
    o.season.remember_visits = !opt->forget_visits;
    if (!opt->shard.empty())
      std::tie(o.shard_index, o.shard_count) = trials::parseShard(opt->shard);
    o.out_dir = opt->out;
    o.season.progress = [](const std::string& line) { std::cerr << line << "\n"; };
    const nlohmann::json summary = trials::runSeasonExperiment(o);
    std::cout << trials::seasonTable(summary) << "wrote " << opt->out
              << "/{season-<seed>/, summary.json, table.md}\n";
  });
}

}  // namespace fvp::apps
