#include "fvp/robot/sim/experiment.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/gnuplot.h"
#include "trial_parts.h"

namespace fvp::robot::sim {
namespace {

std::string trialKey(const std::string& planner, std::uint64_t seed) {
  return planner + "-" + std::to_string(seed);
}

/// The summary row of a finished trial: its planner, plus the engine when that is not the
/// planner's default (the "FVP on the octomap engine" ablation is its own row).
std::string rowKey(const nlohmann::json& trial) {
  std::string key = trial["planner"].get<std::string>();
  const std::string engine = trial.value("engine", "");
  if (!engine.empty() && engine != defaultEngine(key)) key += "-" + engine;
  return key;
}

/// Canonical trial order: by world seed, then by row.
bool bySeedThenRow(const nlohmann::json& a, const nlohmann::json& b) {
  return std::make_pair(a["seed"].get<std::uint64_t>(), rowKey(a)) <
         std::make_pair(b["seed"].get<std::uint64_t>(), rowKey(b));
}

/// Appends one line with a single write and fsync: a reader sees whole lines, or a last
/// line cut short by a crash, which readTrials reports and ignores.
void appendLine(const std::filesystem::path& path, const std::string& line) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) throw std::runtime_error(path.string() + ": cannot open for appending");
  const std::string text = line + "\n";
  const ssize_t written = ::write(fd, text.data(), text.size());
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  if (written != ssize_t(text.size()) || !synced)
    throw std::runtime_error(path.string() + ": appending a trial failed (disk full?)");
}

std::string fmt(const nlohmann::json& v, int precision) {
  if (!v.is_number()) return "-";
  std::ostringstream s;
  s << std::fixed << std::setprecision(precision) << v.get<double>();
  return s.str();
}

/// Pools the fruitlets of some trials under one estimator's field names.
nlohmann::json pool(const std::vector<const nlohmann::json*>& trials, const char* fruitlets_key,
                    const char* metrics_key) {
  std::size_t gt = 0, matched = 0, detections = 0;
  double abs_sum = 0, pct_sum = 0, views = 0, wall = 0;
  for (const nlohmann::json* t : trials) {
    views += t->value("views", 0);
    wall += t->value("wall_time_s", 0.0);
    detections += t->value("detections", 0);
    for (const auto& f : (*t)[fruitlets_key]) {
      ++gt;
      if (!f.value("matched", false)) continue;
      ++matched;
      const double e = std::abs(f["est_size_mm"].get<double>() - f["gt_size_mm"].get<double>());
      abs_sum += e;
      pct_sum += 100.0 * e / f["gt_size_mm"].get<double>();
    }
    (void)metrics_key;
  }
  const auto opt = [](bool ok, double v) { return ok ? nlohmann::json(v) : nlohmann::json(); };
  const std::size_t n = trials.size();
  return {
      {"trials", n},
      {"gt_fruitlets", gt},
      {"matched", matched},
      {"match_percent", opt(gt > 0, gt ? 100.0 * matched / gt : 0.0)},
      {"mae_mm", opt(matched > 0, matched ? abs_sum / matched : 0.0)},
      {"mape_percent", opt(matched > 0, matched ? pct_sum / matched : 0.0)},
      {"precision_percent", opt(detections > 0, detections ? 100.0 * matched / detections : 0.0)},
      {"mean_views", opt(n > 0, n ? views / n : 0.0)},
      {"wall_s_per_trial", opt(n > 0, n ? wall / n : 0.0)}};
}

}  // namespace

std::vector<nlohmann::json> readTrials(const std::filesystem::path& jsonl,
                                       const std::function<void(const std::string&)>& warning) {
  std::vector<nlohmann::json> out;
  std::ifstream in(jsonl, std::ios::binary);
  if (!in) return out;
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  std::size_t start = 0, line_no = 0;
  while (start < text.size()) {
    ++line_no;
    const std::size_t end = text.find('\n', start);
    if (end == std::string::npos) {
      if (warning)
        warning(jsonl.string() + ": line " + std::to_string(line_no) +
                " has no newline (a write cut short); ignored, its trial will run again");
      break;
    }
    const std::string line = text.substr(start, end - start);
    start = end + 1;
    if (line.empty()) continue;
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(jsonl.string() + ": line " + std::to_string(line_no) +
                               ": expected one trial's result as JSON: " + e.what());
    }
    if (!j.is_object() || !j.contains("planner") || !j.contains("seed") || !j.contains("fruitlets"))
      throw std::runtime_error(jsonl.string() + ": line " + std::to_string(line_no) +
                               ": expected a trial result with 'planner', 'seed' and 'fruitlets'");
    out.push_back(std::move(j));
  }
  return out;
}

nlohmann::json summarize(const std::vector<nlohmann::json>& trials) {
  std::map<std::string, std::vector<const nlohmann::json*>> by_key;
  for (const auto& t : trials) {
    by_key[rowKey(t)].push_back(&t);
  }
  nlohmann::ordered_json summary;
  for (const auto& [key, list] : by_key) {
    summary[key] = pool(list, "fruitlets", "metrics");
    bool paper = true;
    for (const auto* t : list) paper &= t->contains("fruitlets_paper_sizing");
    if (paper)
      summary[key + "-paper-sizing"] = pool(list, "fruitlets_paper_sizing", "metrics_paper_sizing");
  }
  return summary;
}

void writeReports(const std::filesystem::path& dir, const std::vector<nlohmann::json>& unsorted) {
  // A canonical order: sums (and so every figure) do not depend on how trials were run.
  std::vector<nlohmann::json> trials = unsorted;
  std::sort(trials.begin(), trials.end(), bySeedThenRow);
  const nlohmann::json summary = summarize(trials);
  host::writeFileAtomically(dir / "summary.json", "experiment summary", summary.dump(2) + "\n");

  std::ostringstream md;
  md << "# Table 1: sizing accuracy (simulated orchard)\n\n"
     << "Fruitlets pooled over the trials of each row. MP: matched / ground-truth fruitlets "
        "(centre within 5 mm, one-to-one); MAE and MAPE over matched pairs.\n\n"
     << "| planner | trials | views / trial | MP (%) | MAE (mm) | MAPE (%) | precision (%) |\n"
     << "|---|---|---|---|---|---|---|\n"
     << "| RVP, paper (35 trials) | 35 | - | 82.2 | 1.65 | 14.9 | - |\n"
     << "| FVP, paper (35 trials) | 35 | - | 90.1 | 1.04 | 9.35 | - |\n";
  const std::map<std::string, std::string> names = {
      {"fvp", "FVP (ours)"},
      {"rvp", "RVP (ours)"},
      {"fvp-octomap", "FVP on the octomap engine"},
      {"fvp-paper-sizing", "FVP, paper's sizing estimator"},
      {"rvp-paper-sizing", "RVP, paper's sizing estimator"},
      {"fvp-octomap-paper-sizing", "FVP on octomap, paper's sizing estimator"}};
  for (const auto& [key, row] : summary.items()) {
    const auto name = names.count(key) ? names.at(key) : key;
    md << "| " << name << " | " << row["trials"] << " | " << fmt(row["mean_views"], 1) << " | "
       << fmt(row["match_percent"], 1) << " | " << fmt(row["mae_mm"], 2) << " | "
       << fmt(row["mape_percent"], 2) << " | " << fmt(row["precision_percent"], 1) << " |\n";
  }
  md << "\nSize distributions: sizes.png.\n";
  host::writeFileAtomically(dir / "table1.md", "Table 1", md.str());

  // Figure 7: ground truth, RVP and FVP sizes (matched fruitlets), box plots with means.
  std::map<std::string, std::vector<double>> sizes;
  for (const auto& t : trials) {
    const std::string planner = t["planner"].get<std::string>();
    if (rowKey(t) != planner) continue;  // engine ablations are not in the figure
    for (const auto& f : t["fruitlets"]) {
      if (planner == "fvp") sizes["GT"].push_back(f["gt_size_mm"].get<double>());
      if (f.value("matched", false))
        sizes[planner == "fvp" ? "FVP" : "RVP"].push_back(f["est_size_mm"].get<double>());
    }
  }
  if (sizes["GT"].empty())
    for (const auto& t : trials)
      for (const auto& f : t["fruitlets"]) sizes["GT"].push_back(f["gt_size_mm"].get<double>());
  std::ostringstream gp;
  gp << "set terminal pngcairo size 900,600 font 'DejaVu Sans,12'\nset output '{png}'\n"
     << "set title 'Fruitlet sizes: ground truth and matched estimates (x: mean, line: median)'\n"
     << "set ylabel 'size (mm)'\nset style fill solid 0.35 border -1\nset style boxplot "
        "nooutliers\nset style data boxplot\nset boxwidth 0.5\nset grid ytics\n"
     << "set xtics ('GT' 1, 'RVP' 2, 'FVP' 3)\nset xrange [0.4:3.6]\nunset key\n";
  const char* order[] = {"GT", "RVP", "FVP"};
  for (int i = 0; i < 3; ++i) {
    gp << "$d" << i << " << EOD\n";
    for (double v : sizes[order[i]]) gp << v << "\n";
    if (sizes[order[i]].empty()) gp << "NaN\n";
    gp << "EOD\n";
  }
  gp << "$means << EOD\n";
  for (int i = 0; i < 3; ++i) {
    double sum = 0;
    for (double v : sizes[order[i]]) sum += v;
    gp << i + 1 << " " << (sizes[order[i]].empty() ? NAN : sum / sizes[order[i]].size()) << "\n";
  }
  gp << "EOD\nplot $d0 using (1):1 lc rgb '#7f7f7f', $d1 using (2):1 lc rgb '#ff7f0e', "
        "$d2 using (3):1 lc rgb '#1f77b4', $means using 1:2 with points pt 2 ps 2.5 lw 2 lc rgb "
        "'black'\n";
  host::plotWithGnuplot(gp.str(), dir / "sizes.png", "size distribution figure");
}

void runExperiment(const ExperimentOptions& o, const TrialRunner& run_trial,
                   const std::function<void(const std::string&)>& progress) {
  if (o.trials < 1) throw std::invalid_argument("experiment: --trials must be at least 1");
  if (o.shard_count < 1 || o.shard_index < 0 || o.shard_index >= o.shard_count)
    throw std::invalid_argument("experiment: --shard i/n needs 0 <= i < n");
  for (const auto& p : o.planners)
    if (p != "fvp" && p != "rvp")
      throw std::invalid_argument("experiment: unknown planner '" + p + "' (expected fvp, rvp)");
  std::filesystem::create_directories(o.out_dir);
  const std::filesystem::path jsonl = o.out_dir / "trials.jsonl";
  // Probe that the directory is writable before the first (long) trial.
  host::writeFileAtomically(o.out_dir / ".fvp-write-check", "output directory check", "");
  std::filesystem::remove(o.out_dir / ".fvp-write-check");

  std::vector<nlohmann::json> done = readTrials(jsonl, progress);
  if (!done.empty() && !o.resume)
    throw std::runtime_error(jsonl.string() + " already holds " + std::to_string(done.size()) +
                             " trials: use --resume to continue, or another --out");
  std::set<std::string> finished;
  for (const auto& t : done)
    finished.insert(trialKey(t["planner"], t["seed"].get<std::uint64_t>()));
  if (!done.empty()) {
    // Drop a torn last line so appends start on a fresh line.
    std::ostringstream whole;
    for (const auto& t : done) whole << t.dump() << "\n";
    host::writeFileAtomically(jsonl, "trials", whole.str());
  }

  // The (seed, planner) list, seed-major so that planners alternate on the same world.
  std::vector<std::pair<std::string, std::uint64_t>> all;
  for (int i = 0; i < o.trials; ++i)
    for (const auto& p : o.planners) all.emplace_back(p, o.first_seed + std::uint64_t(i));
  std::vector<std::pair<std::string, std::uint64_t>> mine;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (int(i % o.shard_count) == o.shard_index) mine.push_back(all[i]);

  const auto start = std::chrono::steady_clock::now();
  const auto elapsed_s = [start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  std::size_t ran = 0, todo = 0;
  double finished_s = 0.0;  // elapsed when the last trial finished
  for (const auto& [p, s] : mine) todo += !finished.count(trialKey(p, s));
  for (const auto& [planner, seed] : mine) {
    if (finished.count(trialKey(planner, seed))) continue;
    TrialOptions t = o.trial;
    t.planner = planner;
    t.seed = seed;
    t.out_dir = o.out_dir / "trials" / trialKey(planner, seed);
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
    appendLine(jsonl, result.dump());
    ++ran;
    finished_s = elapsed_s();
    done.push_back(std::move(result));
  }
  writeReports(o.out_dir, done);
}

void mergeExperiments(const std::vector<std::filesystem::path>& shard_dirs,
                      const std::filesystem::path& out_dir) {
  if (shard_dirs.empty()) throw std::invalid_argument("merge: no shard directories given");
  std::vector<nlohmann::json> all;
  std::set<std::string> seen;
  for (const auto& dir : shard_dirs) {
    const std::filesystem::path jsonl = dir / "trials.jsonl";
    if (!std::filesystem::exists(jsonl))
      throw std::runtime_error(jsonl.string() + ": not found (not an experiment directory?)");
    for (auto& t : readTrials(jsonl, nullptr)) {
      // A row's trial once: the main run and an engine ablation of one planner may merge.
      const std::string key = trialKey(rowKey(t), t["seed"].get<std::uint64_t>());
      if (!seen.insert(key).second)
        throw std::runtime_error(jsonl.string() + ": trial " + key + " is in two shards");
      all.push_back(std::move(t));
    }
  }
  // A canonical order, so that merged output does not depend on the shard split.
  std::sort(all.begin(), all.end(), bySeedThenRow);
  std::filesystem::create_directories(out_dir);
  std::ostringstream whole;
  for (const auto& t : all) whole << t.dump() << "\n";
  host::writeFileAtomically(out_dir / "trials.jsonl", "merged trials", whole.str());
  writeReports(out_dir, all);
}

}  // namespace fvp::robot::sim
