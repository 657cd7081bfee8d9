#include "fvp/trials/season_trial.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/report/season_report.h"
#include "fvp/host/season/season_visit.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/sim/world_config.h"
#include "fvp/trials/experiment_directory.h"
#include "fvp/trials/trial_fields.h"

namespace fvp::trials {
namespace fs = std::filesystem;

namespace {

std::string dayText(double day) {
  std::ostringstream s;
  s << std::setprecision(17) << day;  // distinct days, distinct directories
  return s.str();
}

/// One visit's figures for the season's line.
nlohmann::json visitFigures(double day, const nlohmann::json& result) {
  std::size_t truth = 0, matched = 0;
  for (const auto& f : result.value("fruitlets", nlohmann::json::array())) {
    ++truth;
    matched += f.value("matched", false);
  }
  const nlohmann::json metrics = result.value("metrics", nlohmann::json::object());
  return {{"day", day},
          {"sim_time_s", result.value("sim_time_s", 0.0)},
          {"views", result.value("views", 0)},
          {"gt_fruitlets", truth},
          {"matched", matched},
          {"detections", result.value("detections", 0)},
          {"mae_mm", metrics.value("mae_mm", nlohmann::json())},
          {"wall_time_s", result.value("wall_time_s", 0.0)}};
}

/// The visit a result remembered, by its directory's name ("day-4"; empty: none): the season's
/// directory may be spelled or placed otherwise on a resume.
fs::path rememberedDay(const nlohmann::json& result) {
  const auto it = result.find("remembered_visit");
  if (it == result.end() || !it->is_string()) return {};
  fs::path day = fs::path(it->get<std::string>()).lexically_normal();
  return day.has_filename() ? day.filename() : day.parent_path().filename();
}

/// The first key of `now` whose value `old` does not hold; a switch added after `old` was
/// written (absent there) is the same when it is off (empty: the same settings).
std::string firstSettingDifference(const nlohmann::json& old, const nlohmann::json& now) {
  for (const auto& [key, value] : now.items())
    if (old.contains(key) ? old.at(key) != value : value != false) return key;
  return {};
}

/// A visit's result.json already in its directory (a season cut short), when it is this
/// visit's: the same settings, seed and day; another is an error naming the file.
std::optional<nlohmann::json> finishedVisit(const TrialOptions& visit) {
  const fs::path file = visit.out_dir / "result.json";
  if (visit.out_dir.empty() || !fs::exists(file)) return std::nullopt;
  std::ifstream in(file);
  const nlohmann::json result = nlohmann::json::parse(in, nullptr, false);
  TrialOptions resolved = visit;
  resolved.register_views = registerViewsOf(visit);
  nlohmann::json settings = trialSettingsJson(resolved);
  // A visit remembering nothing (the first) runs the same with known_fruitlets on or off:
  // one from before the switch is still this visit's.
  if (visit.remembered_visit.empty()) settings.erase("known_fruitlets");
  if (result.is_discarded() || !result.is_object() ||
      !result.value("settings", nlohmann::json()).is_object() ||
      !firstSettingDifference(result.at("settings"), settings).empty() ||
      rememberedDay(result) != visit.remembered_visit.filename() ||
      result.value("clock_charges", "") != ExperimentManifest::clockChargesFor(visit.guided_stereo))
    throw std::runtime_error(file.string() +
                             ": not this visit's result (another seed, day, settings, "
                             "remembered visit or clock); another --out");
  return result;
}

}  // namespace

void checkSeasonDays(const std::vector<double>& days) {
  if (days.size() < 2)
    throw std::invalid_argument("season: expected two or more visit days, got " +
                                std::to_string(days.size()));
  for (std::size_t i = 0; i < days.size(); ++i) {
    if (!std::isfinite(days[i]) || days[i] < 0.0 || days[i] > robot::sim::kMaxSeasonDay)
      throw std::invalid_argument("season: visit day " + dayText(days[i]) +
                                  ": expected a day from 0 to " +
                                  dayText(robot::sim::kMaxSeasonDay));
    if (i > 0 && !(days[i] > days[i - 1]))
      throw std::invalid_argument("season: visit day " + dayText(days[i]) +
                                  ": expected days in increasing order, each after " +
                                  dayText(days[i - 1]));
  }
}

namespace {

/// What must be the same for seasons to pool: the visits' settings but the seed and day, the
/// caliper baseline's error and what the clock charged (a season finished before the clock
/// charged motion plans their work holds no "clock_charges" and is not pooled).
nlohmann::json seasonSettings(const SeasonTrialOptions& o) {
  nlohmann::json settings = trialSettingsJson(o.visit);
  settings.erase("seed");
  settings.erase("season_day");
  settings["caliper_sigma_mm"] = o.caliper_sigma_mm;
  settings["remember_visits"] = o.remember_visits;
  settings["clock_charges"] = ExperimentManifest::clockChargesFor(o.visit.guided_stereo);
  return settings;
}

}  // namespace

nlohmann::json runSeasonTrial(const SeasonTrialOptions& o) {
  checkSeasonDays(o.days);
  o.season.validate();
  if (!(o.caliper_sigma_mm >= host::season::kMinStandardErrorMm) ||
      !std::isfinite(o.caliper_sigma_mm))
    throw std::invalid_argument(
        "season: caliper_sigma_mm (--caliper-sigma-mm): expected at least " +
        dayText(host::season::kMinStandardErrorMm) + " mm");
  if (o.remember_visits && o.out_dir.empty())
    throw std::invalid_argument(
        "season: remember_visits reads each visit's result from out_dir: set out_dir, or "
        "remember_visits false");
  if (!o.out_dir.empty()) host::prepareOutputDirectory(o.out_dir, "season output directory");
  robot::sim::WorldConfig config =
      o.visit.world_config.empty() ? robot::sim::WorldConfig{}
                                   : robot::sim::WorldConfig::fromYamlFile(o.visit.world_config);
  std::vector<nlohmann::json> results;
  std::vector<robot::sim::World> worlds;
  std::vector<host::season::SeasonVisit> visits;
  nlohmann::json line = {
      {"seed", o.visit.seed}, {"days", o.days}, {"visits", nlohmann::json::array()}};
  for (const double day : o.days) {
    TrialOptions visit = o.visit;
    visit.season_day = day;
    if (!o.out_dir.empty()) visit.out_dir = o.out_dir / ("day-" + dayText(day));
    if (o.remember_visits && !results.empty())
      visit.remembered_visit = o.out_dir / ("day-" + dayText(o.days[results.size() - 1]));
    std::optional<nlohmann::json> kept = o.reuse_visits ? finishedVisit(visit) : std::nullopt;
    results.push_back(kept ? std::move(*kept) : runTrial(visit));
    config.season_day = day;
    worlds.push_back(robot::sim::World::generate(config, o.visit.seed));
    const std::string source = visit.out_dir.empty() ? "visit of day " + dayText(day)
                                                     : (visit.out_dir / "result.json").string();
    visits.push_back(host::season::parseSeasonVisit(results.back().dump(), source, day));
    line["visits"].push_back(visitFigures(day, results.back()));
    if (o.progress)
      o.progress("season " + std::to_string(o.visit.seed) + ", day " + dayText(day) + ": " +
                 trialSummary(results.back()));
  }
  const host::season::SeasonAnalysis analysis = host::season::analyzeSeason(visits, o.season);
  SeasonScoreInput input;
  input.analysis = &analysis;
  for (std::size_t v = 0; v < results.size(); ++v) {
    input.visit_results.push_back(&results[v]);
    input.visit_worlds.push_back(&worlds[v]);
  }
  input.caliper_sigma_mm = o.caliper_sigma_mm;
  input.caliper_seed = robot::sim::visitSeed(o.visit.seed, -1.0);  // a stream of its own
  input.fate = o.season.fate;
  line["score"] = scoreSeason(input);
  line["settings"] = seasonSettings(o);
  if (!o.out_dir.empty()) {
    host::writeFileAtomically(o.out_dir / "season.json", "season",
                              host::season::seasonJson(analysis, o.season).dump(2) + "\n");
    host::report::writeSeasonReport(analysis, o.out_dir, o.progress);
    host::writeFileAtomically(o.out_dir / "season_score.json", "season score", line.dump(2) + "\n");
  }
  return line;
}

namespace {

struct Pooled {
  std::map<std::string, double> sums;
  void add(const nlohmann::json& object, const std::string& prefix) {
    for (const auto& [key, value] : object.items())
      if (value.is_number() && (key.find("percent") == std::string::npos) &&
          key.find("mae") == std::string::npos && key.find("f1") == std::string::npos &&
          key.find("worst") == std::string::npos && key.find("floor") == std::string::npos)
        sums[prefix + key] += value.get<double>();
  }
  double at(const std::string& key) const {
    const auto it = sums.find(key);
    return it == sums.end() ? 0.0 : it->second;
  }
};

nlohmann::json ratio(double part, double whole, double scale = 100.0) {
  return whole > 0 ? nlohmann::json(scale * part / whole) : nlohmann::json(nullptr);
}

nlohmann::json numberOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

/// sqrt(sum / count): a root mean square from pooled sums; null without any.
nlohmann::json rootOfRatio(double sum, double count) {
  return count > 0 ? nlohmann::json(std::sqrt(sum / count)) : nlohmann::json(nullptr);
}

/// Every season's tracks whose every size states a standard error, as the floor's fit takes
/// them (the score's growth.sizes, grouped by track).
std::vector<std::vector<SizeError>> pooledSizeErrors(const std::vector<nlohmann::json>& seasons) {
  std::vector<std::vector<SizeError>> tracks;
  for (const nlohmann::json& s : seasons) {
    const nlohmann::json& growth = s.at("score").at("growth");
    std::map<std::size_t, std::vector<SizeError>> by_track;
    std::set<std::size_t> incomplete;
    for (const nlohmann::json& r : growth.value("sizes", nlohmann::json::array())) {
      const std::size_t track = r.at("track").get<std::size_t>();
      if (!r.at("standard_error_mm").is_number()) {
        incomplete.insert(track);
        continue;
      }
      by_track[track].push_back({r.at("size_mm").get<double>() - r.at("truth_mm").get<double>(),
                                 r.at("standard_error_mm").get<double>()});
    }
    for (auto& [track, errors] : by_track)
      if (!incomplete.count(track)) tracks.push_back(std::move(errors));
  }
  return tracks;
}

}  // namespace

nlohmann::json summarizeSeasons(const std::vector<nlohmann::json>& seasons) {
  Pooled p;
  double growth_abs = 0.0, fruit_set_robot = 0.0, fruit_set_calipers = 0.0, fruit_set_n = 0.0;
  std::map<std::size_t, std::vector<const nlohmann::json*>> visits_by_place;
  for (const nlohmann::json& s : seasons) {
    const nlohmann::json& score = s.at("score");
    p.add(score.at("association"), "association.");
    p.add(score.at("gone"), "gone.");
    p.add(score.at("growth"), "growth.");
    p.add(score.at("fate").at("robot"), "robot.");
    p.add(score.at("fate").at("calipers"), "calipers.");
    const nlohmann::json& g = score.at("growth");
    if (g.at("mae_mm_per_day").is_number())
      growth_abs += g.at("mae_mm_per_day").get<double>() * g.at("tracks_scored").get<double>();
    const nlohmann::json& set = score.at("fruit_set_percent");
    if (set.at("truth").is_number() && set.at("robot").is_number() &&
        set.at("calipers").is_number()) {
      fruit_set_robot += std::abs(set.at("robot").get<double>() - set.at("truth").get<double>());
      fruit_set_calipers +=
          std::abs(set.at("calipers").get<double>() - set.at("truth").get<double>());
      ++fruit_set_n;
    }
    for (std::size_t v = 0; v < s.at("visits").size(); ++v)
      visits_by_place[v].push_back(&s.at("visits")[v]);
  }
  nlohmann::json visits = nlohmann::json::array();
  for (const auto& [place, list] : visits_by_place) {
    double sim = 0, truth = 0, matched = 0, detections = 0, abs = 0;
    for (const nlohmann::json* v : list) {
      sim += v->at("sim_time_s").get<double>();
      truth += v->at("gt_fruitlets").get<double>();
      matched += v->at("matched").get<double>();
      detections += v->at("detections").get<double>();
      if (v->at("mae_mm").is_number())
        abs += v->at("mae_mm").get<double>() * v->at("matched").get<double>();
    }
    visits.push_back({{"visit", place + 1},
                      {"mean_sim_s", ratio(sim, double(list.size()), 1.0)},
                      {"match_percent", ratio(matched, truth)},
                      {"mae_mm", ratio(abs, matched, 1.0)},
                      {"precision_percent", ratio(matched, detections)}});
  }
  // Seasons scored before the score recorded its sizes add none: the fit says how many.
  const std::vector<std::vector<SizeError>> size_errors = pooledSizeErrors(seasons);
  const auto rf1 = [&](const std::string& who) {
    return dropsF1(p.at(who + ".true_drops"), p.at(who + ".false_drops"),
                   p.at(who + ".missed_drops"));
  };
  return {{"seasons", seasons.size()},
          {"association_correct_percent",
           ratio(p.at("association.links_correct"), p.at("association.links_made"))},
          {"association_links_with_spurious", p.at("association.links_with_spurious")},
          {"association_found_percent",
           ratio(p.at("association.truth_links_found"), p.at("association.truth_links"))},
          {"gone_reported_percent", ratio(p.at("gone.reported_gone"), p.at("gone.fallen_sized"))},
          {"wrongly_gone", p.at("gone.wrongly_gone")},
          {"growth_mae_mm_per_day", ratio(growth_abs, p.at("growth.tracks_scored"), 1.0)},
          {"growth_covered_95_percent",
           ratio(p.at("growth.covered_95"), p.at("growth.with_standard_error"))},
          {"size_error_between_visits_mm",
           rootOfRatio(p.at("growth.size_deviation_ss_mm2"), p.at("growth.size_deviation_dof"))},
          {"stated_standard_error_rms_mm", rootOfRatio(p.at("growth.stated_standard_error_ss_mm2"),
                                                       p.at("growth.size_deviation_dof"))},
          {"size_error_floor_fit_mm", numberOrNull(sizeErrorFloorFit(size_errors))},
          {"size_error_floor_fit_tracks", size_errors.size()},
          {"robot_fate_f1", rf1("robot")},
          {"calipers_fate_f1", rf1("calipers")},
          {"robot_undecided", p.at("robot.undecided")},
          {"fruit_set_error_pp_robot", ratio(fruit_set_robot, fruit_set_n, 1.0)},
          {"fruit_set_error_pp_calipers", ratio(fruit_set_calipers, fruit_set_n, 1.0)},
          {"visits", visits}};
}

namespace {

/// The first setting (or the days) in which a finished season differs from these options.
std::string seasonDifference(const nlohmann::json& line, const nlohmann::json& settings,
                             const std::vector<double>& days) {
  if (line.value("days", nlohmann::json()) != nlohmann::json(days)) return "days";
  return firstSettingDifference(line.value("settings", nlohmann::json::object()), settings);
}

}  // namespace

std::vector<nlohmann::json> readSeasons(const fs::path& dir) {
  std::map<std::uint64_t, nlohmann::json> by_seed;
  if (!fs::is_directory(dir)) return {};
  for (const auto& entry : fs::directory_iterator(dir)) {
    const fs::path file = entry.path() / "season_score.json";
    if (!entry.is_directory() || !entry.path().filename().string().starts_with("season-") ||
        !fs::exists(file))
      continue;
    std::ifstream in(file);
    nlohmann::json line;
    try {
      line = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(file.string() + ": not JSON: " + e.what());
    }
    if (!line.is_object() || !line.contains("seed") || !line["seed"].is_number_unsigned() ||
        !line.contains("score") || !line.contains("visits"))
      throw std::runtime_error(file.string() +
                               ": expected a season's line (seed, days, visits, score)");
    const std::uint64_t seed = line["seed"].get<std::uint64_t>();
    by_seed[seed] = std::move(line);
  }
  std::vector<nlohmann::json> out;
  for (auto& [seed, line] : by_seed) out.push_back(std::move(line));
  return out;
}

nlohmann::json runSeasonExperiment(const SeasonExperimentOptions& o) {
  checkSeasonDays(o.season.days);
  if (o.seasons < 1) throw std::invalid_argument("seasons: --seasons must be at least 1");
  if (o.shard_count < 1 || o.shard_index < 0 || o.shard_index >= o.shard_count)
    throw std::invalid_argument("seasons: --shard i/n needs 0 <= i < n");
  if (o.season.visit.season_day)
    throw std::invalid_argument("seasons: --season-day is set per visit by --days");
  host::prepareOutputDirectory(o.out_dir, "seasons: --out");
  const nlohmann::json settings = seasonSettings(o.season);
  for (int k = o.shard_index; k < o.seasons; k += o.shard_count) {
    SeasonTrialOptions season = o.season;
    season.reuse_visits = o.resume;
    season.visit.seed = o.first_seed + std::uint64_t(k);
    season.out_dir = o.out_dir / ("season-" + std::to_string(season.visit.seed));
    const fs::path done = season.out_dir / "season_score.json";
    if (fs::exists(done)) {
      if (!o.resume)
        throw std::runtime_error(done.string() +
                                 ": this season is finished already; --resume to keep it, or "
                                 "another --out");
      continue;  // checked with every other finished season below
    }
    runSeasonTrial(season);
  }
  // Only seasons of this run's settings and days pool into one table.
  const std::vector<nlohmann::json> seasons = readSeasons(o.out_dir);
  for (const nlohmann::json& line : seasons)
    if (const std::string differs = seasonDifference(line, settings, o.season.days);
        !differs.empty())
      throw std::runtime_error(
          (o.out_dir / ("season-" + std::to_string(line["seed"].get<std::uint64_t>()))).string() +
          ": its " + differs + " differs from this run's; another --out");
  const nlohmann::json summary = summarizeSeasons(seasons);
  host::writeFileAtomically(o.out_dir / "summary.json", "season summary", summary.dump(2) + "\n");
  host::writeFileAtomically(o.out_dir / "table.md", "season table", seasonTable(summary));
  return summary;
}

std::string seasonTable(const nlohmann::json& summary) {
  const auto fmt = [](const nlohmann::json& v, int digits) {
    if (!v.is_number()) return std::string("-");
    std::ostringstream s;
    s << std::fixed << std::setprecision(digits) << v.get<double>();
    return s.str();
  };
  std::ostringstream md;
  md << "# Simulated seasons\n\n"
     << summary.at("seasons") << " seasons (docs/season.md).\n\n"
     << "| association correct % | found % | fallen reported gone % | growth-rate MAE mm/day | "
        "fate F1 robot | fate F1 calipers | fruit-set error pp robot | calipers |\n"
     << "|---|---|---|---|---|---|---|---|\n"
     << "| " << fmt(summary["association_correct_percent"], 1) << " | "
     << fmt(summary["association_found_percent"], 1) << " | "
     << fmt(summary["gone_reported_percent"], 1) << " | "
     << fmt(summary["growth_mae_mm_per_day"], 3) << " | " << fmt(summary["robot_fate_f1"], 2)
     << " | " << fmt(summary["calipers_fate_f1"], 2) << " | "
     << fmt(summary["fruit_set_error_pp_robot"], 1) << " | "
     << fmt(summary["fruit_set_error_pp_calipers"], 1) << " |\n\n"
     << "Growth rates' 95 % intervals hold the true rate for "
     << fmt(summary["growth_covered_95_percent"], 1)
     << " %. Sizes' errors between visits: " << fmt(summary["size_error_between_visits_mm"], 2)
     << " mm RMS against stated " << fmt(summary["stated_standard_error_rms_mm"], 2)
     << " mm; the floor that would account for them: " << fmt(summary["size_error_floor_fit_mm"], 2)
     << " mm.\n\n"
     << "| visit | mean simulated s | MP % | MAE mm | precision % |\n|---|---|---|---|---|\n";
  for (const auto& v : summary.at("visits"))
    md << "| " << v.at("visit") << " | " << fmt(v["mean_sim_s"], 1) << " | "
       << fmt(v["match_percent"], 1) << " | " << fmt(v["mae_mm"], 2) << " | "
       << fmt(v["precision_percent"], 1) << " |\n";
  return md.str();
}

}  // namespace fvp::trials
