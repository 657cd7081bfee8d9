#include "fvp/trials/experiment.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "experiment_index.h"
#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/gnuplot.h"
#include "fvp/host/core/interrupt.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/planner/planner_registry.h"
#include "fvp/robot/sim/world_config.h"
#include "number_text.h"

namespace fvp::trials {
namespace {

namespace fs = std::filesystem;

std::string trialKey(const std::string& planner, std::uint64_t seed) {
  return planner + "-" + std::to_string(seed);
}

/// Canonical trial order: by world seed, then by row.
bool bySeedThenRow(const nlohmann::json& a, const nlohmann::json& b) {
  return std::make_pair(a.at("seed").get<std::uint64_t>(), trialRowKey(a)) <
         std::make_pair(b.at("seed").get<std::uint64_t>(), trialRowKey(b));
}

/// Appends one line with a single write and fsync: a reader sees whole lines, or a last
/// line cut short by a crash, which readTrials reports and ignores.
void appendLine(const fs::path& path, const std::string& line) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) throw std::runtime_error(path.string() + ": cannot open for appending");
  const std::string text = line + "\n";
  const ssize_t written = ::write(fd, text.data(), text.size());
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  if (written != ssize_t(text.size()) || !synced)
    throw std::runtime_error(path.string() + ": appending a trial failed (disk full?)");
}

/// Cuts a last line without its newline (a write cut short) off trials.jsonl, so that the
/// next append starts on a line of its own. The whole lines are kept byte for byte.
void cutTornTail(const fs::path& jsonl) {
  const std::optional<std::string> bytes = readFileBytes(jsonl);
  if (!bytes || bytes->empty() || bytes->back() == '\n') return;
  const std::string& text = *bytes;
  const std::size_t newline = text.rfind('\n');
  const std::string kept = newline == std::string::npos ? "" : text.substr(0, newline + 1);
  host::writeFileAtomically(jsonl, "trials (a torn last line cut off)", kept);
}

ConfigFileStamp stampOf(const fs::path& path, const std::string& what) {
  if (path.empty()) return {};
  const std::optional<std::string> bytes = readFileBytes(path);
  if (!bytes) throw std::runtime_error("experiment: cannot read the " + what + " " + path.string());
  return {fs::absolute(path).lexically_normal().string(), fnv1a64Hex(*bytes)};
}

/// The manifest an experiment with these options has.
}  // namespace

fs::path writeScaledWorldConfig(const fs::path& world, const std::string& error_scale,
                                const fs::path& out_dir) {
  const auto [group, factor] = parseErrorScale(error_scale);
  const robot::sim::WorldConfig base =
      world.empty() ? robot::sim::WorldConfig{} : robot::sim::WorldConfig::fromYamlFile(world);
  robot::sim::WorldConfig scaled;
  try {
    scaled = base.withErrorsScaled(group, factor);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(
        "--error-scale: " + std::string(e.what()) +
        (world.empty() ? " (built-in world config)" : " (world config " + world.string() + ")"));
  }
  fs::create_directories(out_dir);
  const fs::path path = out_dir / "world.yaml";
  // JSON is YAML: the config's keys and values, read back by WorldConfig::fromYamlFile.
  host::writeFileAtomically(path, "scaled world config", scaled.toJson() + "\n");
  return path;
}

namespace {

ExperimentManifest manifestOf(const ExperimentOptions& o) {
  ExperimentManifest m;
  m.kind = "run";
  m.settings = o.trial;
  m.clock_charges = ExperimentManifest::clockChargesFor(o.trial.guided_stereo);
  m.settings.register_views = registerViewsOf(o.trial);
  // Switches of the automatic stop: nothing under the budget stop, recorded as off there so
  // that budget experiments from before they existed still resume and merge.
  const bool automatic = o.trial.stop == host::nbv::StopRule::kAuto;
  m.settings.confirm_detections = automatic && o.trial.confirm_detections;
  m.settings.seek_partly_seen = automatic && o.trial.seek_partly_seen;
  m.settings.release_left_out = automatic && o.trial.release_left_out;
  // No experiment's trial remembers an earlier visit, so known_fruitlets changes nothing:
  // recorded off, so that automatic-stop experiments from before it still resume and merge.
  m.settings.known_fruitlets = false;
  m.error_scale = o.error_scale;
  m.configs = {{"world_config", stampOf(o.trial.world_config, "world config")},
               {"planner_config", stampOf(o.trial.planner_config, "planner config")},
               {"arm_config", stampOf(o.trial.arm_config, "arm config")}};
  m.planners = o.planners;
  m.trials = o.trials;
  m.first_seed = o.first_seed;
  m.shard_index = o.shard_index;
  m.shard_count = o.shard_count;
  return m;
}

void checkOptions(const ExperimentOptions& o) {
  if (o.trials < 1) throw std::invalid_argument("experiment: --trials must be at least 1");
  // A trial takes minutes: more than this is a typo, and its trial list alone (2^31 worlds)
  // exhausted memory before a trial ran.
  if (o.trials > kMaxExperimentTrials)
    throw std::invalid_argument("experiment: --trials " + std::to_string(o.trials) +
                                ": expected at most " + std::to_string(kMaxExperimentTrials) +
                                " worlds (split a larger run into experiments and merge them)");
  if (o.shard_count < 1 || o.shard_index < 0 || o.shard_index >= o.shard_count)
    throw std::invalid_argument("experiment: --shard i/n needs 0 <= i < n");
  if (o.planners.empty())
    throw std::invalid_argument("experiment: no planners given (--planners, e.g. fvp,rvp)");
  const auto& registry = host::planner::PlannerRegistry::instance();
  for (std::size_t i = 0; i < o.planners.size(); ++i) {
    const std::string& p = o.planners[i];
    if (p.empty()) throw std::invalid_argument("experiment: an empty planner name in --planners");
    if (!registry.contains(p))
      throw std::invalid_argument("experiment: unknown planner '" + p + "' (expected one of " +
                                  registry.knownNames() + ")");
    if (std::find(o.planners.begin(), o.planners.begin() + long(i), p) !=
        o.planners.begin() + long(i))
      throw std::invalid_argument("experiment: --planners lists '" + p +
                                  "' twice (each of its trials would run and count twice)");
  }
  if (o.first_seed > UINT64_MAX - std::uint64_t(o.trials - 1))
    throw std::invalid_argument("experiment: --first-seed + --trials runs past the largest seed");
  if (!std::isfinite(o.trial.budget_s) || o.trial.budget_s <= 0)
    throw std::invalid_argument("experiment: --budget-s must be a finite positive number");
  if (o.trial.max_views && *o.trial.max_views < 1)
    throw std::invalid_argument(
        "experiment: max_views must be at least 1 when set (unset: no "
        "limit; --max-views 0)");
  if (!o.trial.engine.empty() && !host::map::MapEngineRegistry::instance().contains(o.trial.engine))
    throw std::invalid_argument("experiment: --engine must be one of " +
                                host::map::MapEngineRegistry::instance().knownNames() + ", not '" +
                                o.trial.engine + "'");
}

/// A one-line reason from an exception's text (gnuplot's log may span lines).
std::string oneLine(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

/// A member that is a number, or null (absent, null or another type: an older or partial line).
std::optional<double> numberAt(const nlohmann::json& object, const char* key) {
  if (!object.is_object()) return std::nullopt;
  const auto it = object.find(key);
  if (it == object.end() || !it->is_number()) return std::nullopt;
  return it->get<double>();
}

/// A summary figure, or null where there was nothing to compute it from.
nlohmann::json numberOrNull(bool defined, double value) {
  return defined ? nlohmann::json(value) : nlohmann::json();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// What a trial sized, cluster by cluster: a tree trial's clusters that were run (each with
/// its fruitlets, sim_time_s and size_history), else the trial itself (one cluster).
std::vector<const nlohmann::json*> sizedUnits(const nlohmann::json& trial) {
  std::vector<const nlohmann::json*> units;
  const auto it = trial.find("clusters");
  if (it == trial.end() || !it->is_array()) return {&trial};
  for (const auto& cluster : *it)
    if (cluster.is_object() && cluster.contains("fruitlets")) units.push_back(&cluster);
  return units;
}

/// A tree trial's moves between clusters that failed (every status but success).
double failedTransitMoves(const nlohmann::json& trial) {
  double failed = 0.0;
  const auto tour = trial.find("tour");
  if (tour == trial.end() || !tour->is_object()) return 0.0;
  const auto statuses = tour->find("transit_motion_status");
  if (statuses == tour->end() || !statuses->is_object()) return 0.0;
  for (const auto& [status, count] : statuses->items())
    if (status != "success" && count.is_number()) failed += count.get<double>();
  return failed;
}

/// Where the trials' simulated time went, in percent of it: the clock's stages summed
/// (sim_time_by_stage_s), the arm's motion split into moves between views and a tour's
/// transit between clusters, and what no stage holds as "other". Null when a trial lacks its
/// stages (a line of an older build) or no time was charged.
nlohmann::json timeSplitPercent(const std::vector<const nlohmann::json*>& trials) {
  std::map<std::string, double> seconds;
  double sim = 0.0;
  for (const nlohmann::json* t : trials) {
    const std::optional<double> sim_s = numberAt(*t, "sim_time_s");
    const auto stages = t->find("sim_time_by_stage_s");
    if (!sim_s || stages == t->end() || !stages->is_object()) return nullptr;
    sim += *sim_s;
    // The transit's motion (its planning stays in the planning stages); a line of an older
    // build has only the whole transit time, its moves' planning included.
    const nlohmann::json tour = t->value("tour", nlohmann::json());
    double transit = numberAt(tour, "transit_motion_sim_s")
                         .value_or(numberAt(tour, "transit_sim_s").value_or(0.0));
    for (const auto& [stage, value] : stages->items()) {
      if (!value.is_number()) continue;
      std::string name = stage.substr(0, stage.size() - (stage.ends_with("_s") ? 2 : 0));
      double s = value.get<double>();
      if (name == "motion") {
        transit = std::min(transit, s);  // a transit's seconds are the arm's motion
        seconds["transit"] += transit;
        s -= transit;
        name = "motion_between_views";
      }
      seconds[name] += s;
    }
  }
  if (!(sim > 0.0)) return nullptr;
  nlohmann::json percent = nlohmann::json::object();
  double charged = 0.0;
  for (const auto& [name, s] : seconds) percent[name] = 100.0 * s / sim, charged += s;
  percent["other"] = std::max(0.0, 100.0 * (sim - charged) / sim);
  return percent;
}

/// The grower's figures of some checked trials: a cluster's time (median and worst), views
/// and failed moves (between views and between clusters) per cluster, a tree's transit, and
/// where the time went.
nlohmann::json growersFigures(const std::vector<const nlohmann::json*>& trials) {
  std::vector<double> sim_per_cluster;
  double clusters = 0, views = 0, failed = 0, transit = 0, tours = 0;
  for (const nlohmann::json* t : trials) {
    const std::vector<const nlohmann::json*> units = sizedUnits(*t);
    clusters += double(units.size());
    for (const nlohmann::json* cluster : units)
      if (const std::optional<double> cluster_s = numberAt(*cluster, "sim_time_s"))
        sim_per_cluster.push_back(*cluster_s);
    views += numberAt(*t, "views").value_or(0.0);
    failed += numberAt(t->value("events", nlohmann::json()), "failed_moves").value_or(0.0) +
              failedTransitMoves(*t);
    if (const auto s = numberAt(t->value("tour", nlohmann::json()), "transit_sim_s"))
      transit += *s, ++tours;
  }
  const bool sized = clusters > 0;
  return {
      {"clusters", clusters},
      {"median_sim_s_per_cluster", numberOrNull(!sim_per_cluster.empty(), median(sim_per_cluster))},
      {"worst_sim_s_per_cluster",
       numberOrNull(!sim_per_cluster.empty(),
                    sim_per_cluster.empty()
                        ? 0.0
                        : *std::max_element(sim_per_cluster.begin(), sim_per_cluster.end()))},
      {"views_per_cluster", numberOrNull(sized, sized ? views / clusters : 0.0)},
      {"failed_moves_per_cluster", numberOrNull(sized, sized ? failed / clusters : 0.0)},
      {"transit_s_per_tree", numberOrNull(tours > 0, tours > 0 ? transit / tours : 0.0)},
      {"sim_time_percent", timeSplitPercent(trials)}};
}

/// Pools the fruitlets of some checked trials under one estimator's field names.
nlohmann::json pool(const std::vector<const nlohmann::json*>& trials, const char* fruitlets_key) {
  std::size_t gt = 0, matched = 0;
  std::uint64_t detections = 0;
  double abs_sum = 0, pct_sum = 0, views = 0, wall = 0, sim = 0, matched_in_sim = 0;
  for (const nlohmann::json* t : trials) {
    views += t->contains("views") ? t->at("views").get<double>() : 0.0;
    const std::optional<double> sim_s = numberAt(*t, "sim_time_s");
    if (sim_s) {
      sim += *sim_s;
      for (const auto& f : t->at(fruitlets_key)) matched_in_sim += f.at("matched").get<bool>();
    }
    wall += t->contains("wall_time_s") ? t->at("wall_time_s").get<double>() : 0.0;
    detections += t->contains("detections") ? t->at("detections").get<std::uint64_t>() : 0;
    for (const auto& f : t->at(fruitlets_key)) {
      ++gt;
      if (!f.at("matched").get<bool>()) continue;
      ++matched;
      const double truth = f.at("gt_size_mm").get<double>();
      const double e = std::abs(f.at("est_size_mm").get<double>() - truth);
      abs_sum += e;
      pct_sum += 100.0 * e / truth;
    }
  }
  const std::size_t n = trials.size();
  nlohmann::json pooled = {
      {"trials", n},
      {"gt_fruitlets", gt},
      {"matched", matched},
      {"match_percent", numberOrNull(gt > 0, gt ? 100.0 * double(matched) / double(gt) : 0.0)},
      {"mae_mm", numberOrNull(matched > 0, matched ? abs_sum / double(matched) : 0.0)},
      {"mape_percent", numberOrNull(matched > 0, matched ? pct_sum / double(matched) : 0.0)},
      {"precision_percent",
       numberOrNull(detections > 0,
                    detections ? 100.0 * double(matched) / double(detections) : 0.0)},
      {"mean_views", numberOrNull(n > 0, n ? views / double(n) : 0.0)},
      // What the trials' whole time bought (a tree's moves between clusters included).
      {"matched_per_sim_min", numberOrNull(sim > 0, sim > 0 ? 60.0 * matched_in_sim / sim : 0.0)},
      {"wall_s_per_trial", numberOrNull(n > 0, n ? wall / double(n) : 0.0)}};
  // A cluster's time: the budget, or less with --stop auto; a tree's clusters each, the
  // moves between them not included.
  pooled.update(growersFigures(trials));
  return pooled;
}

/// The gnuplot script of Figure 7: ground truth and each planner's sizes (matched fruitlets;
/// planners in registry order, named by their labels), box plots with means. The ground truth
/// is the first planner's trials' (every planner sees the same worlds).
std::string sizesFigureScript(const std::vector<nlohmann::json>& trials) {
  const auto& registry = host::planner::PlannerRegistry::instance();
  std::vector<std::string> columns = {"GT"};
  std::map<std::string, std::vector<double>> sizes;
  std::string truth_from;
  for (const std::string& planner : registry.names())
    for (const auto& t : trials) {
      if (t.at("planner").get<std::string>() != planner) continue;
      if (trialRowKey(t) != planner) continue;  // engine ablations are not in the figure
      const std::string& label = registry.at(planner).label;
      if (columns.back() != label) columns.push_back(label);
      if (truth_from.empty()) truth_from = planner;
      for (const auto& f : t.at("fruitlets")) {
        if (planner == truth_from) sizes["GT"].push_back(f.at("gt_size_mm").get<double>());
        if (f.at("matched").get<bool>()) sizes[label].push_back(f.at("est_size_mm").get<double>());
      }
    }
  if (sizes["GT"].empty())
    for (const auto& t : trials)
      for (const auto& f : t.at("fruitlets"))
        sizes["GT"].push_back(f.at("gt_size_mm").get<double>());
  static const char* const colours[] = {"#7f7f7f", "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728"};
  std::ostringstream gp;
  gp << "set terminal pngcairo size 900,600 font 'DejaVu Sans,12'\n"
     << "set title 'Fruitlet sizes: ground truth and matched estimates (x: mean, line: median)'\n"
     << "set ylabel 'size (mm)'\nset style fill solid 0.35 border -1\nset style boxplot "
        "nooutliers\nset style data boxplot\nset boxwidth 0.5\nset grid ytics\nset xtics (";
  for (std::size_t i = 0; i < columns.size(); ++i)
    gp << (i ? ", " : "") << host::gnuplotQuoted(columns[i]) << " " << i + 1;
  gp << ")\nset xrange [0.4:" << columns.size() + 0.6 << "]\nunset key\n";
  for (std::size_t i = 0; i < columns.size(); ++i) {
    gp << "$d" << i << " << EOD\n";
    for (double v : sizes[columns[i]]) gp << v << "\n";
    if (sizes[columns[i]].empty()) gp << "NaN\n";
    gp << "EOD\n";
  }
  gp << "$means << EOD\n";
  for (std::size_t i = 0; i < columns.size(); ++i) {
    double sum = 0;
    for (double v : sizes[columns[i]]) sum += v;
    gp << i + 1 << " " << (sizes[columns[i]].empty() ? NAN : sum / sizes[columns[i]].size())
       << "\n";
  }
  gp << "EOD\nplot ";
  for (std::size_t i = 0; i < columns.size(); ++i)
    gp << "$d" << i << " using (" << i + 1 << "):1 lc rgb '" << colours[i % 5] << "', ";
  gp << "$means using 1:2 with points pt 2 ps 2.5 lw 2 lc rgb 'black'\n";
  return gp.str();
}

/// The stages of the time split in the order a view spends them, with the words of the
/// tables and the figure.
const std::vector<std::pair<std::string, std::string>>& timeSplitStages() {
  static const std::vector<std::pair<std::string, std::string>> stages = {
      {"motion_between_views", "motion between views"},
      {"transit", "transit between clusters"},
      {"capture", "capture"},
      {"perception", "perception"},
      {"mapping", "mapping"},
      {"tsdf", "TSDF"},
      {"sizing", "sizing"},
      {"planning", "planning"},
      {"goal_check", "goal checks"},
      {"motion_planning", "motion planning"},
      {"other", "other"}};
  return stages;
}

/// Summary rows the grower's tables show: every row but the paper-sizing twins (the same
/// trials, so the same times).
std::vector<std::string> timedRows(const nlohmann::json& summary) {
  std::vector<std::string> rows;
  for (const auto& [key, row] : summary.items())
    if (!key.ends_with("-paper-sizing")) rows.push_back(key);
  return rows;
}

/// table1.md's second and third tables: the grower's figures and where the time went.
std::string growersTablesMarkdown(const nlohmann::json& summary,
                                  const std::map<std::string, std::string>& names) {
  const auto name = [&](const std::string& key) { return names.count(key) ? names.at(key) : key; };
  std::ostringstream md;
  md << "\n## The grower's figures\n\nA cluster's simulated seconds (median and worst; a tree's "
        "clusters each), its views and failed moves (between views and, on a tree, between "
        "clusters), a tree's transit between clusters, matched fruitlets per simulated "
        "minute.\n\n| planner | clusters | s / cluster (median) | s / cluster (worst) | views / "
        "cluster | failed moves / cluster | transit s / tree | matched / min |\n"
     << "|---|---|---|---|---|---|---|---|\n";
  for (const std::string& key : timedRows(summary)) {
    const nlohmann::json& row = summary[key];
    md << "| " << name(key) << " | " << fmtOrDash(row["clusters"], 0) << " | "
       << fmtOrDash(row["median_sim_s_per_cluster"], 1) << " | "
       << fmtOrDash(row["worst_sim_s_per_cluster"], 1) << " | "
       << fmtOrDash(row["views_per_cluster"], 1) << " | "
       << fmtOrDash(row["failed_moves_per_cluster"], 2) << " | "
       << fmtOrDash(row["transit_s_per_tree"], 1) << " | "
       << fmtOrDash(row["matched_per_sim_min"], 2) << " |\n";
  }
  md << "\n## Where the simulated time went (% of it)\n\n| planner |";
  for (const auto& [stage, words] : timeSplitStages()) md << " " << words << " |";
  md << "\n|---|";
  for (std::size_t i = 0; i < timeSplitStages().size(); ++i) md << "---|";
  md << "\n";
  for (const std::string& key : timedRows(summary)) {
    const nlohmann::json& split = summary[key]["sim_time_percent"];
    md << "| " << name(key) << " |";
    for (const auto& [stage, words] : timeSplitStages())
      md << " " << fmtOrDash(split.is_object() ? split.value(stage, nlohmann::json(0.0)) : split, 1)
         << " |";
    md << "\n";
  }
  return md.str();
}

/// The gnuplot script of time_split.png: one stacked bar per row, the time split's stages in
/// percent of the row's simulated time. Empty when no row has a split.
std::string timeSplitFigureScript(const nlohmann::json& summary,
                                  const std::map<std::string, std::string>& names) {
  std::ostringstream data;
  std::size_t bars = 0;
  for (const std::string& key : timedRows(summary)) {
    const nlohmann::json& split = summary[key]["sim_time_percent"];
    if (!split.is_object()) continue;
    // A data column in double quotes (gnuplot splits single-quoted words into columns).
    std::string label = names.count(key) ? names.at(key) : key;
    std::erase(label, '"');
    data << '"' << label << '"';
    for (const auto& [stage, words] : timeSplitStages()) data << " " << split.value(stage, 0.0);
    data << "\n";
    ++bars;
  }
  if (bars == 0) return "";
  // Motion in blues, capture grey, perception purple, compute in warm colours, planning in
  // greens.
  static const char* const colours[] = {"#1f77b4", "#aec7e8", "#7f7f7f", "#9467bd",
                                        "#ff7f0e", "#ffbb78", "#d62728", "#2ca02c",
                                        "#98df8a", "#17becf", "#e5e5e5"};
  std::ostringstream gp;
  gp << "set terminal pngcairo size 900," << 220 + 60 * bars << " font 'DejaVu Sans,12'\n"
     << "set title 'Where the simulated time went'\n"
     << "set style data histograms\nset style histogram rowstacked\nset style fill solid "
        "0.8 border -1\nset boxwidth 0.6\nset key outside right\nset yrange [0:105]\n"
     << "set grid ytics\nset ylabel '% of the simulated time'\nset xrange [-0.5:" << bars - 0.5
     << "]\n"
     << "$split << EOD\n"
     << data.str() << "EOD\nplot ";
  for (std::size_t i = 0; i < timeSplitStages().size(); ++i)
    gp << (i ? ", " : "") << "$split using " << i + 2 << (i ? "" : ":xtic(1)") << " title "
       << host::gnuplotQuoted(timeSplitStages()[i].second) << " lc rgb '"
       << colours[i % std::size(colours)] << "'";
  gp << "\n";
  return gp.str();
}

/// Accuracy against the time spent on a cluster (pooled over the trials of a row that kept a
/// size_history): at each time, every trial as its latest sizing up to then reported it (none
/// yet: nothing matched). Empty when no trial kept one.
struct AccuracyAtTime {
  double t_s = 0.0, match_percent = 0.0;
  std::optional<double> mae_mm;
};
std::map<std::string, std::vector<AccuracyAtTime>> accuracyAgainstTime(
    const std::vector<nlohmann::json>& trials, double step_s) {
  // Each cluster that kept a size_history (its times count from the cluster's start).
  std::map<std::string, std::vector<const nlohmann::json*>> rows;
  double end_s = 0.0;
  for (const auto& t : trials)
    for (const nlohmann::json* unit : sizedUnits(t)) {
      if (!unit->contains("size_history") || !unit->at("size_history").is_array() ||
          unit->at("size_history").empty())
        continue;
      rows[trialRowKey(t)].push_back(unit);
      if (const std::optional<double> sim_s = numberAt(*unit, "sim_time_s"))
        end_s = std::max(end_s, *sim_s);
      for (const auto& h : unit->at("size_history"))
        if (const std::optional<double> h_s = numberAt(h, "sim_time_s"))
          end_s = std::max(end_s, *h_s);
    }
  std::map<std::string, std::vector<AccuracyAtTime>> out;
  for (const auto& [key, list] : rows)
    for (double t_s = step_s; t_s <= end_s + step_s; t_s += step_s) {
      double gt = 0, matched = 0, abs_sum = 0;
      for (const nlohmann::json* trial : list) {
        const double trial_gt = double(trial->at("fruitlets").size());
        gt += trial_gt;
        const nlohmann::json* latest = nullptr;
        for (const auto& h : trial->at("size_history"))
          if (const std::optional<double> h_s = numberAt(h, "sim_time_s"); h_s && *h_s <= t_s)
            latest = &h;
        if (!latest) continue;
        const std::optional<double> mp = numberAt(*latest, "match_percent");
        const std::optional<double> mae = numberAt(*latest, "mae_mm");
        const double m = mp ? std::round(*mp * trial_gt / 100.0) : 0.0;
        matched += m;
        if (m > 0 && mae) abs_sum += m * *mae;
      }
      AccuracyAtTime a;
      a.t_s = t_s;
      a.match_percent = gt > 0 ? 100.0 * matched / gt : 0.0;
      if (matched > 0) a.mae_mm = abs_sum / matched;
      out[key].push_back(a);
    }
  return out;
}

std::string accuracyTimeFigureScript(const std::map<std::string, std::vector<AccuracyAtTime>>& rows,
                                     const std::vector<nlohmann::json>& trials) {
  std::ostringstream gp;
  gp << "set terminal pngcairo size 900,600 font 'DejaVu Sans,12'\n"
     << "set title 'Accuracy against simulated time spent on a cluster (pooled over trials)'\n"
     << "set xlabel 'simulated time on the cluster (s)'\nset ylabel 'MAE (mm)'\n"
     << "set y2label 'MP (%)'\nset y2range [0:105]\nset yrange [0:*]\nset ytics nomirror\n"
     << "set y2tics\nset grid\nset key bottom right\n";
  // Where automatic stops ended their trials (median per row), as vertical lines.
  std::map<std::string, std::vector<double>> stops;
  for (const auto& t : trials)
    for (const nlohmann::json* unit : sizedUnits(t)) {
      const auto reason = unit->find("stop_reason");
      const std::optional<double> sim_s = numberAt(*unit, "sim_time_s");
      if (reason != unit->end() && (*reason == "cluster_done" || *reason == "no_reachable_view") &&
          sim_s)
        stops[trialRowKey(t)].push_back(*sim_s);
    }
  int mark = 1;
  for (const auto& [key, times] : stops) {
    gp << "set arrow " << mark << " from " << median(times) << ", graph 0 to " << median(times)
       << ", graph 1 nohead dt 2 lc rgb 'black'\nset label " << mark << " "
       << host::gnuplotQuoted(key + ": median automatic stop") << " at " << median(times)
       << ", graph 0.95 offset 0.5,0\n";
    ++mark;
  }
  std::string plot = "plot ";
  int i = 0;
  for (const auto& [key, points] : rows) {
    gp << "$r" << i << " << EOD\n";
    for (const auto& a : points)
      gp << a.t_s << " " << (a.mae_mm ? std::to_string(*a.mae_mm) : "NaN") << " " << a.match_percent
         << "\n";
    gp << "EOD\n";
    plot += (i ? ", " : "") + std::string("$r") + std::to_string(i) +
            " using 1:2 with lines lw 2 title " + host::gnuplotQuoted(key + " MAE") + ", $r" +
            std::to_string(i) + " using 1:3 axes x1y2 with lines dt 3 lw 2 title " +
            host::gnuplotQuoted(key + " MP");
    ++i;
  }
  gp << plot << "\n";
  return gp.str();
}

/// The tables' words for the summary's rows (others by their keys).
const std::map<std::string, std::string>& rowNames() {
  static const std::map<std::string, std::string> names = {
      {"fvp", "FVP (ours)"},
      {"rvp", "RVP (ours)"},
      {"fvp-octomap", "FVP on the octomap engine"},
      {"fvp-paper-sizing", "FVP, paper's sizing estimator"},
      {"fvp-tag-frame", "FVP, in the tag's frame"},
      {"rvp-tag-frame", "RVP, in the tag's frame"},
      {"rvp-paper-sizing", "RVP, paper's sizing estimator"},
      {"fvp-octomap-paper-sizing", "FVP on octomap, paper's sizing estimator"}};
  return names;
}

/// table1.md without its closing line: Table 1, the grower's figures, where the time went.
std::string table1Markdown(const nlohmann::json& summary) {
  std::ostringstream md;
  md << "# Table 1: sizing accuracy (simulated orchard)\n\n"
     << "Fruitlets pooled over the trials of each row. MP: matched / ground-truth fruitlets "
        "(centre within 5 mm, one-to-one); MAE and MAPE over matched pairs. s / cluster: "
        "simulated seconds a cluster took (the budget, or less with --stop auto; each cluster "
        "of a tree); matched / min: matched fruitlets per simulated minute of the whole run "
        "(a tree's moves between clusters included).\n\n"
     << "| planner | trials | views / trial | MP (%) | MAE (mm) | MAPE (%) | precision (%) | "
        "s / cluster (median) | matched / min |\n"
     << "|---|---|---|---|---|---|---|---|---|\n"
     << "| RVP, paper (35 trials) | 35 | - | 82.2 | 1.65 | 14.9 | - | 180 | - |\n"
     << "| FVP, paper (35 trials) | 35 | - | 90.1 | 1.04 | 9.35 | - | 180 | - |\n";
  const std::map<std::string, std::string>& names = rowNames();
  for (const auto& [key, row] : summary.items()) {
    const auto name = names.count(key) ? names.at(key) : key;
    md << "| " << name << " | " << row["trials"] << " | " << fmtOrDash(row["mean_views"], 1)
       << " | " << fmtOrDash(row["match_percent"], 1) << " | " << fmtOrDash(row["mae_mm"], 2)
       << " | " << fmtOrDash(row["mape_percent"], 2) << " | "
       << fmtOrDash(row["precision_percent"], 1) << " | "
       << fmtOrDash(row["median_sim_s_per_cluster"], 1) << " | "
       << fmtOrDash(row["matched_per_sim_min"], 2) << " |\n";
  }
  md << growersTablesMarkdown(summary, names);
  return md.str();
}

/// time_split.png where some row has a time split (an extra: a failure is a warning); an
/// older figure is removed first, so none outlives the tables it would contradict.
void drawTimeSplitFigure(const fs::path& dir, const nlohmann::json& summary,
                         const MessageSink& warning) {
  std::error_code stale;
  fs::remove(dir / "time_split.png", stale);
  const std::string script = timeSplitFigureScript(summary, rowNames());
  if (script.empty()) return;
  try {
    host::plotWithGnuplot(script, dir / "time_split.png", "time split figure");
  } catch (const std::exception& e) {
    if (warning) warning((dir / "time_split.png").string() + " not drawn: " + oneLine(e.what()));
  }
}

}  // namespace

nlohmann::json summarize(const std::vector<nlohmann::json>& trials) {
  std::map<std::string, std::vector<const nlohmann::json*>> by_key;
  for (const auto& t : trials) by_key[trialRowKey(t)].push_back(&t);
  nlohmann::ordered_json summary = nlohmann::ordered_json::object();
  for (const auto& [key, list] : by_key) {
    summary[key] = pool(list, "fruitlets");
    bool paper = true;
    for (const auto* t : list) paper &= t->contains("fruitlets_paper_sizing");
    if (paper) summary[key + "-paper-sizing"] = pool(list, "fruitlets_paper_sizing");
    bool tag_frame = true;
    for (const auto* t : list) tag_frame &= t->contains("fruitlets_tag_frame");
    if (tag_frame) summary[key + "-tag-frame"] = pool(list, "fruitlets_tag_frame");
  }
  return summary;
}

bool writeReports(const fs::path& dir, const std::vector<nlohmann::json>& unsorted,
                  const MessageSink& warning, const TrialDirFn& trial_dir) {
  // A canonical order: sums (and so every figure) do not depend on how trials were run.
  std::vector<nlohmann::json> trials = unsorted;
  std::sort(trials.begin(), trials.end(), bySeedThenRow);
  const nlohmann::json summary = summarize(trials);
  host::writeFileAtomically(dir / "summary.json", "experiment summary", summary.dump(2) + "\n");

  const std::string table = table1Markdown(summary);
  // The tables first: the figure is an extra that must not cost them.
  host::writeFileAtomically(dir / "table1.md", "Table 1",
                            table + "\nSize distributions: sizes.png.\n");
  // The index links the figures that exist when it is written: written again after them.
  const TrialDirFn dir_of_trial =
      trial_dir ? TrialDirFn(trial_dir) : TrialDirFn([&dir](const nlohmann::json& t) {
        return dir / "trials" /
               trialKey(t.at("planner").get<std::string>(), t.at("seed").get<std::uint64_t>());
      });
  const auto write_index = [&] { writeIndexPage(dir, table, trials, dir_of_trial); };

  // Accuracy against time, when trials kept their sizings (--size-history or --stop auto):
  // an extra like sizes.png, its data in accuracy_vs_time.json.
  const auto against_time = accuracyAgainstTime(trials, 5.0);
  std::error_code stale;
  fs::remove(dir / "accuracy_vs_time.png", stale);
  fs::remove(dir / "accuracy_vs_time.json", stale);
  if (!against_time.empty()) {
    nlohmann::json data = nlohmann::json::object();
    for (const auto& [key, points] : against_time)
      for (const auto& a : points)
        data[key].push_back({{"sim_time_s", a.t_s},
                             {"match_percent", a.match_percent},
                             {"mae_mm", a.mae_mm ? nlohmann::json(*a.mae_mm) : nlohmann::json()}});
    host::writeFileAtomically(dir / "accuracy_vs_time.json", "accuracy against time",
                              data.dump(1) + "\n");
    try {
      host::plotWithGnuplot(accuracyTimeFigureScript(against_time, trials),
                            dir / "accuracy_vs_time.png", "accuracy against time figure");
    } catch (const std::exception& e) {
      if (warning)
        warning((dir / "accuracy_vs_time.png").string() + " not drawn: " + oneLine(e.what()));
    }
  }

  drawTimeSplitFigure(dir, summary, warning);

  std::string why_not;
  if (trials.empty()) {
    why_not = "no trials";
  } else {
    try {
      host::plotWithGnuplot(sizesFigureScript(trials), dir / "sizes.png",
                            "size distribution figure");
      write_index();
      return true;
    } catch (const std::exception& e) {
      why_not = oneLine(e.what());
      if (warning) warning((dir / "sizes.png").string() + " not drawn: " + why_not);
    }
  }
  std::error_code ignored;
  fs::remove(dir / "sizes.png", ignored);  // an older figure would not match these tables
  host::writeFileAtomically(dir / "table1.md", "Table 1",
                            table + "\nsizes.png: not drawn: " + why_not + "\n");
  write_index();
  return false;
}

namespace {

/// What an experiment directory holds at its top (checked before the first trial).
const std::vector<std::string>& experimentOutputFiles() {
  static const std::vector<std::string> files = {"manifest.json",
                                                 "trials.jsonl",
                                                 "summary.json",
                                                 "table1.md",
                                                 "sizes.png",
                                                 "time_split.png",
                                                 "index.html",
                                                 "accuracy_vs_time.json",
                                                 "accuracy_vs_time.png",
                                                 "world.yaml"};
  return files;
}

/// merge --out must be new, empty or an earlier merge: anything else (a user's table1.md, a
/// trial's directory) would be overwritten.
void refuseForeignMergeOut(const fs::path& out_dir) {
  const fs::path manifest = out_dir / "manifest.json";
  if (fs::exists(manifest) && readManifest(manifest).kind == "merged") return;
  for (const auto& entry : fs::directory_iterator(out_dir)) {
    const std::string name = entry.path().filename().string();
    if (name == host::kOutputLockFile) continue;
    throw std::runtime_error("merge: --out " + out_dir.string() + " is not empty (it holds " +
                             name +
                             ") and is not an earlier merge; merge into a new or empty "
                             "directory");
  }
}

/// The run's manifest in the directory: written for a new experiment (or over one that never
/// finished a trial), else compared with the one there (a difference is an error).
void adoptManifest(const ExperimentManifest& manifest, const fs::path& manifest_path,
                   const fs::path& jsonl) {
  // A manifest without a finished trial (a start that failed) binds nothing: the next run
  // writes its own instead of refusing the directory.
  std::error_code size_ec;
  const bool no_trials = !fs::exists(jsonl) || fs::file_size(jsonl, size_ec) == 0;

  if (fs::exists(manifest_path)) {
    const ExperimentManifest old = readManifest(manifest_path);
    if (old.kind != "run")
      throw std::runtime_error(manifest_path.string() +
                               ": a merged experiment (kind \"merged\"), not a run: it cannot be "
                               "resumed or run into; use another --out");
    if (no_trials)
      host::writeFileAtomically(manifest_path, "experiment manifest",
                                manifest.toJson().dump(2) + "\n");
    else if (const auto d = resumeDifference(old, manifest))
      throw std::runtime_error(manifest_path.string() + ": this experiment was made with " +
                               d->setting + " " + d->old_value + ", this run asks for " +
                               d->new_value +
                               "; its trials would not be comparable. Run with the "
                               "experiment's settings, or use another --out");
  } else if (fs::exists(jsonl)) {
    throw std::runtime_error(jsonl.string() +
                             ": no manifest.json beside it (made by an fvp before experiment "
                             "manifests), so the settings its trials ran with are unknown and "
                             "it is not resumed; run the experiment again in another --out");
  } else {
    host::writeFileAtomically(manifest_path, "experiment manifest",
                              manifest.toJson().dump(2) + "\n");
  }
}

}  // namespace

void runExperiment(const ExperimentOptions& o, const TrialRunner& run_trial,
                   const MessageSink& progress, const MessageSink& warning_sink) {
  const MessageSink& warning = warning_sink ? warning_sink : progress;
  checkOptions(o);
  const ExperimentManifest manifest = manifestOf(o);
  host::prepareOutputDirectory(o.out_dir, "experiment: --out");
  // One writer: a second experiment into the same directory appended its trials beside the
  // first's. Held until the reports are written.
  const host::OutputDirectoryLock lock(o.out_dir, "experiment: --out");
  host::checkOutputPaths(o.out_dir, "experiment: --out", experimentOutputFiles(), {"trials"});
  const fs::path jsonl = o.out_dir / "trials.jsonl";
  adoptManifest(manifest, o.out_dir / "manifest.json", jsonl);
  if (!fs::exists(jsonl)) host::writeFileAtomically(jsonl, "trials", "");

  std::vector<nlohmann::json> done = readTrials(jsonl, warning);
  if (!done.empty() && !o.resume)
    throw std::runtime_error(jsonl.string() + " already holds " + std::to_string(done.size()) +
                             " trials: use --resume to continue, or another --out");
  cutTornTail(jsonl);  // appends start on a fresh line

  // The (seed, planner) list, seed-major so that planners alternate on the same world.
  std::vector<std::pair<std::string, std::uint64_t>> all;
  for (int i = 0; i < o.trials; ++i)
    for (const auto& p : o.planners) all.emplace_back(p, o.first_seed + std::uint64_t(i));
  std::vector<std::pair<std::string, std::uint64_t>> mine;
  std::set<std::string> mine_keys;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (int(i % std::size_t(o.shard_count)) == o.shard_index) {
      mine.push_back(all[i]);
      mine_keys.insert(trialKey(all[i].first, all[i].second));
    }
  std::set<std::string> finished;
  for (const auto& t : done) {
    const std::string key =
        trialKey(t.at("planner").get<std::string>(), t.at("seed").get<std::uint64_t>());
    if (!mine_keys.count(key))
      throw std::runtime_error(jsonl.string() + ": trial " + key +
                               " is not one of this experiment's (shard's) trials");
    finished.insert(key);
  }

  const auto start = std::chrono::steady_clock::now();
  const auto elapsed_s = [start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  std::size_t ran = 0, todo = 0;
  double finished_s = 0.0;  // elapsed when the last trial finished
  for (const auto& [p, s] : mine) todo += !finished.count(trialKey(p, s));
  for (const auto& [planner, seed] : mine) {
    if (finished.count(trialKey(planner, seed))) continue;
    host::throwIfInterrupted();  // a signal stops between trials; finished lines are kept
    TrialOptions t = o.trial;
    t.planner = planner;
    t.seed = seed;
    t.out_dir = o.out_dir / "trials" / trialKey(planner, seed);
    t.on_warning = [&warning, key = trialKey(planner, seed)](const std::string& text) {
      if (warning) warning("trial " + key + ": " + text);
    };
    const std::size_t index = ran;
    // Init-captures: clang 14 (the libFuzzer build) cannot capture structured bindings.
    t.on_progress = [&, index, planner = planner, seed = seed](const TrialProgress& p) {
      const double elapsed = elapsed_s();
      std::ostringstream line;
      line << "trial " << index + 1 << "/" << todo << " (" << planner << ", seed " << seed
           << "): view " << p.views << ", sim " << std::fixed << std::setprecision(0)
           << p.sim_time_s << "/" << p.budget_s << " s";
      // Mean finished trial times the trials left, less what the trial in flight has run.
      if (index > 0) {
        const double eta_s =
            finished_s / double(index) * double(todo - index) - (elapsed - finished_s);
        line << ", ETA " << std::max(0.0, eta_s) / 60.0 << " min";
      }
      if (progress) progress(line.str());
    };
    nlohmann::json result = run_trial(t);
    result.erase("view_log");  // per-view detail stays in the trial's own result.json
    result.erase("plan_log");
    result.erase("clock");
    // The line as a reader will see it, checked as readTrials checks it: a bad result
    // fails here instead of poisoning trials.jsonl for every later resume and merge.
    const std::string line = result.dump();
    nlohmann::json written = nlohmann::json::parse(line);
    checkTrial(written, "the result of trial " + trialKey(planner, seed));
    if (written.at("planner") != planner || written.at("seed").get<std::uint64_t>() != seed)
      throw std::runtime_error("the result of trial " + trialKey(planner, seed) +
                               " names another trial: " +
                               trialKey(written.at("planner").get<std::string>(),
                                        written.at("seed").get<std::uint64_t>()));
    appendLine(jsonl, line);
    ++ran;
    finished_s = elapsed_s();
    done.push_back(std::move(written));
  }
  writeReports(o.out_dir, done, warning);
}

void mergeExperiments(const std::vector<fs::path>& shard_dirs, const fs::path& out_dir,
                      const MessageSink& warning) {
  if (shard_dirs.empty()) throw std::invalid_argument("merge: no shard directories given");
  std::vector<ExperimentManifest> manifests;
  std::vector<nlohmann::json> all;
  std::map<std::string, fs::path> dir_of;  // row-seed -> the directory holding it
  std::set<fs::path> given;
  for (const auto& dir : shard_dirs) {
    std::error_code ec;
    if (!given.insert(fs::weakly_canonical(dir, ec)).second)
      throw std::runtime_error("merge: " + dir.string() + " is given twice");
    const fs::path manifest_path = dir / "manifest.json", jsonl = dir / "trials.jsonl";
    if (!fs::exists(manifest_path)) {
      if (fs::exists(jsonl))
        throw std::runtime_error("merge: " + dir.string() +
                                 " has trials.jsonl but no manifest.json (made by an fvp before "
                                 "experiment manifests): its settings cannot be checked against "
                                 "the other directories', so it is not merged; run it again");
      throw std::runtime_error("merge: " + dir.string() +
                               " is not an experiment directory (no manifest.json)");
    }
    manifests.push_back(readManifest(manifest_path));
    if (const auto d = mergeDifference(manifests.front(), manifests.back()))
      throw std::runtime_error("merge: " + shard_dirs.front().string() + " and " + dir.string() +
                               " are different experiments: " + d->setting + " is " + d->old_value +
                               " in the first and " + d->new_value +
                               " in the second; their trials would pool into the same rows");
    if (!fs::exists(jsonl))
      throw std::runtime_error("merge: " + jsonl.string() +
                               ": not found (the experiment never started?)");
    for (auto& t : readTrials(jsonl, warning)) {
      // A row's trial once: the main run and an engine ablation of one planner may merge.
      const std::string key = trialKey(trialRowKey(t), t.at("seed").get<std::uint64_t>());
      const auto [it, fresh] = dir_of.emplace(key, dir);
      if (!fresh)
        throw std::runtime_error("merge: trial " + key + " is in both " + it->second.string() +
                                 " and " + dir.string());
      all.push_back(std::move(t));
    }
  }
  {
    std::error_code ec;
    if (given.count(fs::weakly_canonical(out_dir, ec)))
      throw std::runtime_error("merge: --out " + out_dir.string() +
                               " is one of the merged directories; merge into another one");
    const fs::path out_manifest = out_dir / "manifest.json";
    const bool old_merge = fs::exists(out_manifest) && readManifest(out_manifest).kind == "merged";
    if (!old_merge && (fs::exists(out_manifest) || fs::exists(out_dir / "trials.jsonl")))
      throw std::runtime_error("merge: --out " + out_dir.string() +
                               " holds an experiment run; merge into a new directory (or an "
                               "earlier merge's)");
  }
  host::prepareOutputDirectory(out_dir, "merge: --out");
  const host::OutputDirectoryLock lock(out_dir, "merge: --out");
  refuseForeignMergeOut(out_dir);
  ExperimentManifest merged = manifests.front();
  merged.kind = "merged";
  merged.sources.clear();
  for (const auto& dir : shard_dirs)
    merged.sources.push_back(fs::absolute(dir).lexically_normal().string());
  host::writeFileAtomically(out_dir / "manifest.json", "experiment manifest",
                            merged.toJson().dump(2) + "\n");
  // A canonical order, so that merged output does not depend on the shard split.
  std::sort(all.begin(), all.end(), bySeedThenRow);
  std::ostringstream whole;
  for (const auto& t : all) whole << t.dump() << "\n";
  host::writeFileAtomically(out_dir / "trials.jsonl", "merged trials", whole.str());
  writeReports(out_dir, all, warning, [&dir_of](const nlohmann::json& t) {
    const std::uint64_t seed = t.at("seed").get<std::uint64_t>();
    return dir_of.at(trialKey(trialRowKey(t), seed)) / "trials" /
           trialKey(t.at("planner").get<std::string>(), seed);
  });
}

}  // namespace fvp::trials
