// `fvp season`: visits of the same tagged clusters on different days (trial results or sized
// capture sets) turned into growth rates, predicted fates and fruit set (docs/season.md).
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/number_text.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/season/season_analysis.h"
#ifndef FVP_CLI_PARSE_ONLY
#include "fvp/host/report/season_report.h"
#endif

namespace fvp::apps {
namespace {

struct DayAndPath {
  double day = 0.0;
  std::string path;
};

/// DAY=PATH: a finite decimal day and a non-empty path (checked to exist when read); what was
/// wrong in `error` when it is not.
std::optional<DayAndPath> dayAndPath(const std::string& text, std::string& error) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq + 1 == text.size()) {
    error = "expected DAY=PATH (e.g. 4=out/day4), got '" + text + "'";
    return std::nullopt;
  }
  const std::string day = text.substr(0, eq);
  const double day_value = std::strtod(day.c_str(), nullptr);
  if (!host::isDecimalNumberText(day, false) || !std::isfinite(day_value)) {
    error = "expected a finite decimal day before '=', got '" + day + "'";
    return std::nullopt;
  }
  return DayAndPath{day_value, text.substr(eq + 1)};
}

CLI::Validator seasonVisitText() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::string error;
        dayAndPath(text, error);
        return error;
      },
      "DAY=PATH", "seasonVisit");
}

[[maybe_unused]] void printSeason(const host::season::SeasonAnalysis& season) {
  const auto percent = [](const host::season::FruitSet& s) {
    std::ostringstream t;
    if (!std::isfinite(s.percent)) return std::string("-");
    t << std::fixed << std::setprecision(1) << s.percent << " +- " << s.standard_error_percent
      << " %";
    return t.str();
  };
  std::cout << season.days.size() << " visits; reference growth " << std::setprecision(3)
            << season.reference_mm_per_day << " mm/day\n"
            << "  tag  fruitlets  persist  abscise  gone  unknown  fruit set\n";
  for (const auto& c : season.clusters)
    std::cout << std::setw(5) << c.tag_id << std::setw(11) << c.tracks.size() << std::setw(9)
              << c.fruit_set.persisting << std::setw(9) << c.fruit_set.abscising << std::setw(6)
              << c.fruit_set.gone << std::setw(9) << c.fruit_set.unknown << "  "
              << percent(c.fruit_set) << "\n";
  std::cout << "predicted fruit set of the sample: " << percent(season.fruit_set) << "\n";
}

}  // namespace

void addSeasonCommand(CLI::App& app) {
  struct Options {
    std::vector<std::string> visits;
    std::string out;
    double size_error_floor_mm = host::season::SeasonConfig{}.size_error_floor_mm;
  };
  auto opt = optionStorage<Options>();
  auto* cmd = app.add_subcommand(
      "season",
      "Follow tagged clusters' fruitlets across visits on different days (trial results or "
      "sized capture sets): growth rates, predicted fates and fruit set to --out/season.json");
  cmd->add_option("--visit", opt->visits,
                  "DAY=PATH, once per visit (two or more): the visit's day and its result.json, "
                  "fruitlets.json or a directory holding one")
      ->required()
      ->check(seasonVisitText());
  cmd->add_option("--out", opt->out, "output directory")->required()->check(nonEmptyPath());
  cmd->add_option("--size-error-floor-mm", opt->size_error_floor_mm,
                  "what a visit's images share and their spread cannot show, added in quadrature "
                  "to each size's standard error before a rate is fitted (docs/season.md)")
      ->check(numberFromZero(true))
      ->capture_default_str();
  FVP_ON_RUN(cmd, [opt] {
    if (opt->visits.size() < 2)
      throw std::runtime_error("--visit: expected two or more visits, got " +
                               std::to_string(opt->visits.size()));
    std::vector<host::season::SeasonVisit> visits;
    for (const std::string& v : opt->visits) {
      std::string error;
      const std::optional<DayAndPath> visit = dayAndPath(v, error);
      if (!visit) throw std::runtime_error("--visit: " + error);  // the validator ran first
      visits.push_back(host::season::readSeasonVisit(visit->path, visit->day));
    }
    host::season::SeasonConfig config;
    config.size_error_floor_mm = opt->size_error_floor_mm;
    const host::season::SeasonAnalysis season = host::season::analyzeSeason(visits, config);
    host::prepareOutputDirectory(opt->out, "--out");
    const host::OutputDirectoryLock lock(opt->out, "--out");
    host::writeFileAtomically(std::filesystem::path(opt->out) / "season.json", "season",
                              host::season::seasonJson(season, config).dump(2) + "\n");
    const bool drawn = host::report::writeSeasonReport(
        season, opt->out,
        [](const std::string& line) { std::cerr << "fvp: warning: " << line << "\n"; });
    printSeason(season);
    std::cout << "wrote " << opt->out << "/{season.json, season.md" << (drawn ? ", season.png" : "")
              << "}\n";
  });
}

}  // namespace fvp::apps
