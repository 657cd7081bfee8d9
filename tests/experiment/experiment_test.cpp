// The experiment runner with a deterministic stand-in for the trial (a real trial takes
// minutes): pooled metrics by hand, resume after an interruption, shard + merge equals one
// run, and clear errors for corrupt files and unwritable directories; the directory's
// contract (manifest, duplicates, torn lines, schema, empty shards, plot failures).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "fvp/host/core/gnuplot.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/planner/planner_registry.h"
#include "fvp/robot/sim/world_config.h"
#include "fvp/trials/experiment.h"
#include "fvp/trials/sensitivity_report.h"
#include "fvp/trials/trial_fields.h"

namespace fvp::trials {
namespace {

namespace fs = std::filesystem;

// Two fruitlets per world: the first matched with +0.5 mm error, the second matched with
// -1 mm for fvp and unmatched for rvp; rvp detects one spurious fruitlet.
nlohmann::json fakeTrial(const TrialOptions& o) {
  const double gt0 = 6.0 + double(o.seed % 3), gt1 = 8.0;
  const bool fvp = o.planner == "fvp";
  nlohmann::json f0 = {{"gt_center_m", {0, 0, 1}},
                       {"gt_size_mm", gt0},
                       {"matched", true},
                       {"est_center_m", {0, 0, 1}},
                       {"est_size_mm", gt0 + 0.5}};
  nlohmann::json f1 = {{"gt_center_m", {0.02, 0, 1}}, {"gt_size_mm", gt1}, {"matched", fvp}};
  if (fvp) f1["est_size_mm"] = gt1 - 1.0;
  nlohmann::json r = {{"planner", o.planner},
                      {"seed", o.seed},
                      {"engine", !o.engine.empty() ? o.engine
                                 : fvp             ? "grid"
                                                   : "octomap"},
                      {"views", fvp ? 30 : 20},
                      {"wall_time_s", 100.0},
                      {"detections", fvp ? 2 : 2},
                      {"fruitlets", {f0, f1}},
                      {"fruitlets_paper_sizing", {f0, f1}}};
  if (o.on_progress) o.on_progress({1, 1.0, o.budget_s, 0.1});
  return r;
}

fs::path freshDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("fvp_experiment_test_" + name);
  fs::remove_all(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The message of the std::exception that f throws ("" when it throws none).
template <typename F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

/// The lines of a file.
std::vector<std::string> linesOf(const fs::path& p) {
  std::vector<std::string> lines;
  std::stringstream s(slurp(p));
  for (std::string line; std::getline(s, line);) lines.push_back(line);
  return lines;
}

void writeText(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

ExperimentOptions options(const fs::path& out, int trials) {
  ExperimentOptions o;
  o.trials = trials;
  o.first_seed = 10;
  o.out_dir = out;
  return o;
}

TEST(Experiment, PooledMetricsByHand) {
  const fs::path out = freshDir("metrics");
  runExperiment(options(out, 3), fakeTrial, nullptr);
  const nlohmann::json s = nlohmann::json::parse(slurp(out / "summary.json"));
  // fvp: 6 fruitlets, all matched; errors 0.5, 0.5, 0.5, 1, 1, 1 mm.
  EXPECT_EQ(s["fvp"]["trials"], 3);
  EXPECT_EQ(s["fvp"]["gt_fruitlets"], 6);
  EXPECT_EQ(s["fvp"]["matched"], 6);
  EXPECT_DOUBLE_EQ(s["fvp"]["match_percent"].get<double>(), 100.0);
  EXPECT_NEAR(s["fvp"]["mae_mm"].get<double>(), 0.75, 1e-12);
  // gt0 is 7, 8, 6 for seeds 10, 11, 12; gt1 is 8.
  const double mape = (0.5 / 7 + 0.5 / 8 + 0.5 / 6 + 3 * (1.0 / 8)) / 6 * 100;
  EXPECT_NEAR(s["fvp"]["mape_percent"].get<double>(), mape, 1e-9);
  EXPECT_DOUBLE_EQ(s["fvp"]["precision_percent"].get<double>(), 100.0);
  EXPECT_DOUBLE_EQ(s["fvp"]["mean_views"].get<double>(), 30.0);
  // rvp: 3 of 6 matched, 3 of 6 detections right.
  EXPECT_DOUBLE_EQ(s["rvp"]["match_percent"].get<double>(), 50.0);
  EXPECT_NEAR(s["rvp"]["mae_mm"].get<double>(), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(s["rvp"]["precision_percent"].get<double>(), 50.0);
  EXPECT_TRUE(s.contains("fvp-paper-sizing"));
  const std::string table = slurp(out / "table1.md");
  EXPECT_NE(table.find("| FVP, paper (35 trials) | 35 | - | 90.1 | 1.04 | 9.35 | - |"),
            std::string::npos);
  EXPECT_NE(table.find("| FVP (ours) | 3 | 30.0 | 100.0 | 0.75 |"), std::string::npos);
  EXPECT_GT(fs::file_size(out / "sizes.png"), 5000u);
  EXPECT_EQ(slurp(out / "sizes.png").substr(1, 3), "PNG");
  // Lines without the clock's stages (as an older build wrote them): no split, no figure.
  EXPECT_TRUE(s["fvp"]["sim_time_percent"].is_null());
  EXPECT_FALSE(fs::exists(out / "time_split.png"));
}

// Trials that kept their sizings: time per cluster, fruitlets per minute, and accuracy
// against time pooled by hand. fvp's trials stop (cluster_done) at 40 s: at 10 s nothing is
// sized, at 20 s one of two fruitlets (error 1 mm), from 30 s both (0.5 and 0.25 mm).
TEST(Experiment, TimePerClusterAndAccuracyAgainstTimeByHand) {
  const fs::path out = freshDir("against_time");
  const TrialRunner with_history = [](const TrialOptions& o) {
    nlohmann::json r = fakeTrial(o);
    r["sim_time_s"] = o.planner == "fvp" ? 40.0 : 180.0;
    r["stop_reason"] = o.planner == "fvp" ? "cluster_done" : "budget";
    if (o.planner == "fvp")
      r["size_history"] = {
          {{"view", 0}, {"sim_time_s", 12.0}, {"match_percent", 50.0}, {"mae_mm", 1.0}},
          {{"view", 1}, {"sim_time_s", 25.0}, {"match_percent", 100.0}, {"mae_mm", 0.375}},
          {{"view", 2}, {"sim_time_s", 40.0}, {"match_percent", 100.0}, {"mae_mm", 0.75}}};
    return r;
  };
  runExperiment(options(out, 2), with_history, nullptr);
  const nlohmann::json s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_DOUBLE_EQ(s["fvp"]["median_sim_s_per_cluster"].get<double>(), 40.0);
  // 4 matched fruitlets in 80 simulated seconds.
  EXPECT_DOUBLE_EQ(s["fvp"]["matched_per_sim_min"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(s["rvp"]["matched_per_sim_min"].get<double>(), 60.0 * 2 / 360.0);
  const std::string table = slurp(out / "table1.md");
  EXPECT_NE(table.find("| 100.0 | 40.0 | 3.00 |"), std::string::npos) << table;
  const nlohmann::json curve = nlohmann::json::parse(slurp(out / "accuracy_vs_time.json"));
  ASSERT_TRUE(curve.contains("fvp"));
  EXPECT_FALSE(curve.contains("rvp"));  // no sizings kept
  const auto at = [&](double t) {
    for (const auto& p : curve["fvp"])
      if (p["sim_time_s"] == t) return p;
    return nlohmann::json();
  };
  EXPECT_DOUBLE_EQ(at(10.0)["match_percent"].get<double>(), 0.0);
  EXPECT_TRUE(at(10.0)["mae_mm"].is_null());
  EXPECT_DOUBLE_EQ(at(20.0)["match_percent"].get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(at(20.0)["mae_mm"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(at(30.0)["mae_mm"].get<double>(), 0.375);
  EXPECT_DOUBLE_EQ(at(40.0)["mae_mm"].get<double>(), 0.75);
  EXPECT_EQ(slurp(out / "accuracy_vs_time.png").substr(1, 3), "PNG");
}

// Tree trials by hand: the grower's figures (a cluster's median and worst time, views and
// failed moves per cluster, transit per tree) and where the time went. Seed 10's tree: clusters
// of 20 and 30 s, 10 views, 1 failed move between views and 2 between clusters, 8 s of its
// 40 s of motion in transit (a line of an older build: the transit's time only); seed 11's:
// 40 and 50 s, 14 views, 3 failed, 12 s transit of which 11 s in motion, every stage twice
// seed 10's.
TEST(Experiment, TheGrowersFiguresAndTheTimeSplitByHand) {
  const fs::path out = freshDir("growers");
  const TrialRunner tree = [](const TrialOptions& o) {
    nlohmann::json r = fakeTrial(o);
    const bool first = o.seed == 10;
    const double k = first ? 1.0 : 2.0;
    r["views"] = first ? 10 : 14;
    r["sim_time_s"] = 60.0 * k;
    r["clusters"] = {{{"fruitlets", r["fruitlets"]}, {"sim_time_s", first ? 20.0 : 40.0}},
                     {{"fruitlets", nlohmann::json::array()}, {"sim_time_s", first ? 30.0 : 50.0}}};
    r["events"] = {{"failed_moves", first ? 1 : 3}};
    r["tour"] = {{"transit_sim_s", first ? 8.0 : 12.0},
                 {"transit_motion_status",
                  first ? nlohmann::json{{"success", 3}, {"no_collision_free_ik", 2}}
                        : nlohmann::json{{"success", 3}}}};
    if (!first) r["tour"]["transit_motion_sim_s"] = 11.0;
    r["sim_time_by_stage_s"] = {
        {"motion_s", 40.0 * k},    {"capture_s", 4.0 * k},         {"mapping_s", 4.0 * k},
        {"tsdf_s", 2.0 * k},       {"sizing_s", 2.0 * k},          {"planning_s", 2.0 * k},
        {"goal_check_s", 2.0 * k}, {"motion_planning_s", 2.0 * k}, {"perception_s", 1.0 * k}};
    return r;
  };
  runExperiment(options(out, 2), tree, nullptr);
  const nlohmann::json s = nlohmann::json::parse(slurp(out / "summary.json"));
  const nlohmann::json& fvp = s["fvp"];
  EXPECT_EQ(fvp["clusters"].get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(fvp["median_sim_s_per_cluster"].get<double>(), 35.0);
  EXPECT_DOUBLE_EQ(fvp["worst_sim_s_per_cluster"].get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(fvp["views_per_cluster"].get<double>(), 6.0);
  EXPECT_DOUBLE_EQ(fvp["failed_moves_per_cluster"].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(fvp["transit_s_per_tree"].get<double>(), 10.0);
  // 180 s in all: 120 s of motion of which 19 s transit, 12 s capture, 3 s perception, 3 s in
  // no stage.
  const nlohmann::json& split = fvp["sim_time_percent"];
  EXPECT_NEAR(split["motion_between_views"].get<double>(), 100.0 * 101 / 180, 1e-9);
  EXPECT_NEAR(split["transit"].get<double>(), 100.0 * 19 / 180, 1e-9);
  EXPECT_NEAR(split["capture"].get<double>(), 100.0 * 12 / 180, 1e-9);
  EXPECT_NEAR(split["perception"].get<double>(), 100.0 * 3 / 180, 1e-9);
  EXPECT_NEAR(split["other"].get<double>(), 100.0 * 3 / 180, 1e-9);
  const std::string table = slurp(out / "table1.md");
  EXPECT_NE(table.find("| FVP (ours) | 4 | 35.0 | 50.0 | 6.0 | 1.50 | 10.0 |"), std::string::npos)
      << table;
  EXPECT_NE(table.find("| FVP (ours) | 56.1 | 10.6 | 6.7 | 1.7 | 6.7 | 3.3 |"), std::string::npos)
      << table;
  EXPECT_EQ(table.find("paper's sizing estimator | 4 |"), std::string::npos);  // same trials
  EXPECT_EQ(slurp(out / "time_split.png").substr(1, 3), "PNG");
  const std::string index = slurp(out / "index.html");
  EXPECT_NE(index.find("<h2>Where the simulated time went (% of it)</h2>"), std::string::npos);
  EXPECT_NE(index.find("<img src=\"time_split.png\""), std::string::npos);
}

TEST(Experiment, ResumeAfterAnInterruptionGivesTheUninterruptedResult) {
  const fs::path whole = freshDir("whole"), cut = freshDir("cut");
  runExperiment(options(whole, 3), fakeTrial, nullptr);
  int calls = 0;
  const TrialRunner dies_on_fourth = [&](const TrialOptions& o) {
    if (++calls == 4) throw std::runtime_error("killed");
    return fakeTrial(o);
  };
  EXPECT_THROW(runExperiment(options(cut, 3), dies_on_fourth, nullptr), std::runtime_error);
  EXPECT_EQ(readTrials(cut / "trials.jsonl", nullptr).size(), 3u);
  // Without --resume an existing trials.jsonl is an error; with it the rest runs.
  EXPECT_THROW(runExperiment(options(cut, 3), fakeTrial, nullptr), std::runtime_error);
  ExperimentOptions resume = options(cut, 3);
  resume.resume = true;
  int resumed = 0;
  runExperiment(
      resume, [&](const TrialOptions& o) { return ++resumed, fakeTrial(o); }, nullptr);
  EXPECT_EQ(resumed, 3);
  EXPECT_EQ(slurp(cut / "trials.jsonl"), slurp(whole / "trials.jsonl"));
  EXPECT_EQ(slurp(cut / "summary.json"), slurp(whole / "summary.json"));
}

TEST(Experiment, ShardsMergedEqualOneRun) {
  const fs::path whole = freshDir("one"), a = freshDir("shard0"), b = freshDir("shard1"),
                 merged = freshDir("merged");
  runExperiment(options(whole, 5), fakeTrial, nullptr);
  ExperimentOptions s0 = options(a, 5), s1 = options(b, 5);
  s0.shard_count = s1.shard_count = 2;
  s1.shard_index = 1;
  runExperiment(s0, fakeTrial, nullptr);
  runExperiment(s1, fakeTrial, nullptr);
  EXPECT_EQ(readTrials(a / "trials.jsonl", nullptr).size() +
                readTrials(b / "trials.jsonl", nullptr).size(),
            10u);
  mergeExperiments({a, b}, merged);
  EXPECT_EQ(slurp(merged / "summary.json"), slurp(whole / "summary.json"));
  EXPECT_EQ(slurp(merged / "table1.md"), slurp(whole / "table1.md"));
  EXPECT_EQ(slurp(merged / "trials.jsonl"), slurp(whole / "trials.jsonl"));
  // The same shard twice is a conflict.
  EXPECT_THROW(mergeExperiments({a, a}, freshDir("dup")), std::runtime_error);
}

// index.html: Table 1's rows, and each trial's viewer and report linked where they are, in
// a run and, through the shards' directories, in a merge; "-" where a trial has none.
TEST(Experiment, TheIndexLinksEveryTrialsViewerWhereItIs) {
  const auto trial_with_files = [](const TrialOptions& o) {
    if (o.planner == "fvp") {
      fs::create_directories(o.out_dir);
      writeText(o.out_dir / "viewer.html", "<html></html>");
      writeText(o.out_dir / "report.md", "# report");
    }
    return fakeTrial(o);
  };
  const fs::path a = freshDir("index0"), b = freshDir("index1"), merged = freshDir("index_merged");
  ExperimentOptions s0 = options(a, 3), s1 = options(b, 3);
  s0.shard_count = s1.shard_count = 2;
  s1.shard_index = 1;
  runExperiment(s0, trial_with_files, nullptr);
  runExperiment(s1, trial_with_files, nullptr);
  mergeExperiments({a, b}, merged);
  for (const fs::path& dir : {a, merged}) {
    const std::string html = slurp(dir / "index.html");
    EXPECT_NE(html.find("<td>FVP (ours)</td>"), std::string::npos) << dir;
    std::size_t links = 0;
    for (std::size_t at = 0; (at = html.find("href=\"", at)) != std::string::npos; ++links) {
      at += 6;
      const std::string target = html.substr(at, html.find('"', at) - at);
      EXPECT_TRUE(fs::exists(dir / target)) << dir << ": " << target;
    }
    // fvp's trials have a viewer and a report each, rvp's none.
    std::size_t fvp_trials = 0;
    for (const auto& t : readTrials(dir / "trials.jsonl", nullptr))
      fvp_trials += t.at("planner") == "fvp";
    ASSERT_GT(fvp_trials, 0u);
    EXPECT_EQ(links, 2 * fvp_trials) << dir;
    if (dir == merged) {  // rvp's rows (shard 1's) say it has no viewer and no report
      const std::size_t row = html.find("<tr><td>rvp</td>");
      ASSERT_NE(row, std::string::npos);
      EXPECT_EQ(html.substr(row, html.find("</tr>", row) - row).find("<td>-</td><td>-</td>") ==
                    std::string::npos,
                false);
    }
  }
}

// The "FVP on the octomap engine" ablation runs on its own and merges with the main run
// into its own row: same planner and seeds, a different engine, not a conflict.
TEST(Experiment, AnEngineAblationMergesWithTheMainRunAsItsOwnRow) {
  const fs::path main_run = freshDir("main"), ablation = freshDir("ablation"),
                 merged = freshDir("merged_ablation");
  ExperimentOptions m = options(main_run, 3), a = options(ablation, 3);
  m.planners = a.planners = {"fvp"};
  a.trial.engine = "octomap";
  runExperiment(m, fakeTrial, nullptr);
  runExperiment(a, fakeTrial, nullptr);
  mergeExperiments({main_run, ablation}, merged);
  const auto summary = nlohmann::json::parse(slurp(merged / "summary.json"));
  EXPECT_EQ(summary["fvp"]["trials"].get<int>(), 3);
  EXPECT_EQ(summary["fvp-octomap"]["trials"].get<int>(), 3);
  EXPECT_NE(slurp(merged / "table1.md").find("FVP on the octomap engine"), std::string::npos);
  EXPECT_EQ(readTrials(merged / "trials.jsonl", nullptr).size(), 6u);
  EXPECT_THROW(mergeExperiments({ablation, ablation}, freshDir("dup_ablation")),
               std::runtime_error);
}

TEST(Experiment, CorruptLinesAreErrorsButATornLastLineIsReported) {
  const fs::path out = freshDir("corrupt");
  runExperiment(options(out, 2), fakeTrial, nullptr);
  const std::string good = slurp(out / "trials.jsonl");
  {
    std::ofstream(out / "trials.jsonl") << good << "{\"planner\": \"fvp\", \"seed\":";  // torn
  }
  std::vector<std::string> warnings;
  EXPECT_EQ(
      readTrials(out / "trials.jsonl", [&](const std::string& w) { warnings.push_back(w); }).size(),
      4u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("line 5"), std::string::npos);
  { std::ofstream(out / "trials.jsonl") << "{\"planner\": \"fvp\"}\n" << good; }
  try {
    readTrials(out / "trials.jsonl", nullptr);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("trials.jsonl: line 1"), std::string::npos) << e.what();
  }
}

TEST(Experiment, UnwritableOutputDirectoryFailsBeforeAnyTrial) {
  // Below a regular file no directory can be made, for root too.
  const fs::path dir = freshDir("unwritable");
  fs::create_directories(dir);
  std::ofstream(dir / "file") << "x";
  int calls = 0;
  EXPECT_ANY_THROW(runExperiment(
      options(dir / "file" / "out", 1),
      [&](const TrialOptions& o) { return ++calls, fakeTrial(o); }, nullptr));
  EXPECT_EQ(calls, 0);
}

TEST(Experiment, BadOptionsAreErrors) {
  ExperimentOptions o = options(freshDir("bad"), 1);
  o.planners = {"nbv"};
  EXPECT_THROW(runExperiment(o, fakeTrial, nullptr), std::invalid_argument);
  o = options(freshDir("bad"), 1);
  o.shard_index = 2;
  o.shard_count = 2;
  EXPECT_THROW(runExperiment(o, fakeTrial, nullptr), std::invalid_argument);
}

TEST(Experiment, ATornOnlyLineIsCutBeforeTheNextTrialIsAppended) {
  const fs::path whole = freshDir("torn_whole"), out = freshDir("torn_only");
  runExperiment(options(whole, 1), fakeTrial, nullptr);
  // The first trial dies (the directory has its manifest and an empty trials.jsonl), then a
  // write cut short leaves a torn first and only line.
  EXPECT_THROW(
      runExperiment(
          options(out, 1),
          [](const TrialOptions&) -> nlohmann::json { throw std::runtime_error("killed"); },
          nullptr),
      std::runtime_error);
  writeText(out / "trials.jsonl", "{\"planner\": \"fvp\", \"seed\": 1");
  ExperimentOptions resume = options(out, 1);
  resume.resume = true;
  std::vector<std::string> warnings;
  runExperiment(resume, fakeTrial, nullptr, [&](const std::string& w) { warnings.push_back(w); });
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("line 1 has no newline"), std::string::npos) << warnings[0];
  // Valid JSONL: every line one trial, and the same file as the uninterrupted run's.
  EXPECT_EQ(readTrials(out / "trials.jsonl", nullptr).size(), 2u);
  EXPECT_EQ(slurp(out / "trials.jsonl"), slurp(whole / "trials.jsonl"));
  resume.resume = true;
  EXPECT_NO_THROW(runExperiment(resume, fakeTrial, nullptr));
}

TEST(Experiment, ADuplicatedLineIsAnErrorNamingBothLines) {
  const fs::path out = freshDir("duplicate_line");
  runExperiment(options(out, 2), fakeTrial, nullptr);
  const std::vector<std::string> lines = linesOf(out / "trials.jsonl");
  ASSERT_EQ(lines.size(), 4u);
  { std::ofstream(out / "trials.jsonl", std::ios::app) << lines[1] << "\n"; }
  const std::string error = errorOf([&] { readTrials(out / "trials.jsonl", nullptr); });
  EXPECT_NE(error.find("trials.jsonl: lines 2 and 5 hold the same trial (row rvp, seed 10)"),
            std::string::npos)
      << error;
  ExperimentOptions resume = options(out, 2);
  resume.resume = true;
  EXPECT_NE(errorOf([&] { runExperiment(resume, fakeTrial, nullptr); }).find("lines 2 and 5"),
            std::string::npos);
  // The same planner and seed on another engine is another row, not a duplicate.
  nlohmann::json other = nlohmann::json::parse(lines[0]);
  other["engine"] = "octomap";
  writeText(out / "trials.jsonl", lines[0] + "\n" + other.dump() + "\n");
  EXPECT_EQ(readTrials(out / "trials.jsonl", nullptr).size(), 2u);
}

TEST(Experiment, DuplicateOrNoPlannersAreErrors) {
  int calls = 0;
  const TrialRunner counting = [&](const TrialOptions& o) { return ++calls, fakeTrial(o); };
  ExperimentOptions o = options(freshDir("duplicate_planners"), 1);
  o.planners = {"fvp", "fvp"};
  const std::string error = errorOf([&] { runExperiment(o, counting, nullptr); });
  EXPECT_NE(error.find("--planners lists 'fvp' twice"), std::string::npos) << error;
  o.planners = {};
  EXPECT_NE(errorOf([&] { runExperiment(o, counting, nullptr); }).find("no planners"),
            std::string::npos);
  o.planners = {"fvp", ""};
  EXPECT_THROW(runExperiment(o, counting, nullptr), std::invalid_argument);
  EXPECT_EQ(calls, 0);
  EXPECT_FALSE(fs::exists(o.out_dir));
}

TEST(Experiment, AnErrorScaleWritesTheScaledWorldConfigTheTrialsRead) {
  const fs::path out = fs::path(::testing::TempDir()) / "fvp_error_scale";
  fs::remove_all(out);
  const fs::path world = fs::path(FVP_SOURCE_DIR) / "robot/sim/config/world_field.yaml";
  const fs::path written = writeScaledWorldConfig(world, "pose=2", out);
  EXPECT_EQ(written, out / "world.yaml");
  const auto scaled = robot::sim::WorldConfig::fromYamlFile(written);
  const auto base = robot::sim::WorldConfig::fromYamlFile(world);
  EXPECT_DOUBLE_EQ(scaled.hand_eye_translation_sigma_m, 2.0 * base.hand_eye_translation_sigma_m);
  EXPECT_EQ(scaled.wind_leaf_tip_m, base.wind_leaf_tip_m);
  for (const char* bad :
       {"pose", "pose=", "pose=x", "pose=1x", "=1", "sun=1", "pose=-1", "pose=012", "pose=0x2",
        "pose= 2", "pose=2 ", "pose=+2", "pose=1e308", "pose=inf", "pose=20"})
    EXPECT_THROW(writeScaledWorldConfig(world, bad, out), std::invalid_argument) << bad;
  fs::remove_all(out);
}

TEST(Experiment, TheVocabulariesOfExperimentFilesAreTheRegistriesAndTheWorldConfigs) {
  // The readers of trials.jsonl and manifest.json keep their own copy of the error groups, so
  // that they need no simulator code; planners and engines are registry names (no copy: a new
  // planner touches no reader), which the runner checks against the registries.
  EXPECT_EQ(robot::sim::WorldConfig::errorGroups(), errorScaleGroups());
  // Every registered name is a name the schema accepts and figure text as it is.
  for (const auto& p : host::planner::PlannerRegistry::instance().names())
    for (const auto& e : host::map::MapEngineRegistry::instance().names()) {
      const nlohmann::json trial = {{"planner", p},
                                    {"seed", 1},
                                    {"engine", e},
                                    {"settings", {{"engine", e}}},
                                    {"fruitlets", nlohmann::json::array()}};
      EXPECT_NO_THROW(checkTrial(trial, "t")) << p << " " << e;
      EXPECT_TRUE(
          host::isGnuplotSafeText(trialRowKey(trial) + "-paper-sizing: median automatic stop"));
    }
  // Rows say which engine they asked for ("" : the planner's own); rows from before results
  // had settings are read with those versions' defaults.
  EXPECT_EQ(trialRowKey({{"planner", "fvp"}, {"engine", "grid"}, {"settings", {{"engine", ""}}}}),
            "fvp");
  EXPECT_EQ(trialRowKey(
                {{"planner", "fvp"}, {"engine", "octomap"}, {"settings", {{"engine", "octomap"}}}}),
            "fvp-octomap");
  EXPECT_EQ(trialRowKey({{"planner", "rvp"}, {"engine", "octomap"}}), "rvp");
  EXPECT_EQ(trialRowKey({{"planner", "rvp"}, {"engine", "grid"}}), "rvp-grid");
  for (const auto& g : errorScaleGroups()) EXPECT_TRUE(host::isGnuplotSafeText(g));
}

TEST(Experiment, TextFromExperimentFilesIsCheckedAgainstItsSchema) {
  // Issue 38: an engine or an error group that would have been written into a gnuplot title.
  const std::string injection = "grid'\nsystem \"touch PWNED\"\n#";
  const nlohmann::json trial = {
      {"planner", "fvp"},
      {"seed", 1},
      {"engine", injection},
      {"fruitlets", nlohmann::json::array({{{"gt_size_mm", 10.0}, {"matched", false}}})}};
  EXPECT_NE(errorOf([&] { checkTrial(trial, "t.jsonl: line 1"); })
                .find("t.jsonl: line 1: field 'engine': expected \"\" (the planner's own) or a map "
                      "engine name"),
            std::string::npos);
  nlohmann::json reason = trial;
  reason["engine"] = "octomap";
  EXPECT_NO_THROW(checkTrial(reason, "t"));
  reason["stop_reason"] = "budget'`id`";
  EXPECT_NE(errorOf([&] { checkTrial(reason, "t"); }).find("field 'stop_reason'"),
            std::string::npos);
  // The manifest's strings: each from its vocabulary.
  const fs::path dir = freshDir("manifest_schema");
  fs::create_directories(dir);
  ExperimentManifest m;
  m.kind = "run";
  m.settings.budget_s = 180;
  m.settings.clock = robot::sim::SimClock::Mode::kFixed;
  m.settings.backend = accel::BackendChoice::kCpu;
  m.planners = {"fvp"};
  m.trials = 1;
  const auto refused = [&](const char* field, const nlohmann::json& value) {
    nlohmann::ordered_json j = m.toJson();
    j[field] = value;
    std::ofstream(dir / "manifest.json") << j.dump();
    return errorOf([&] { readManifest(dir / "manifest.json"); });
  };
  EXPECT_EQ(refused("error_scale", "wind=0.5"), "");
  EXPECT_NE(refused("error_scale", "wind'\nsystem \"id\"\n#=1").find("field 'error_scale'"),
            std::string::npos);
  EXPECT_NE(refused("error_scale", "pose=1e308").find("field 'error_scale'"), std::string::npos);
  EXPECT_NE(refused("engine", injection).find("field 'engine'"), std::string::npos);
  EXPECT_NE(refused("backend", "gpu;id").find("field 'backend'"), std::string::npos);
  EXPECT_NE(refused("clock", "sundial").find("field 'clock'"), std::string::npos);
  EXPECT_NE(refused("world_config", {{"path", "rel.yaml"}, {"fnv1a64", "0123456789abcdef"}})
                .find("field 'world_config'"),
            std::string::npos);
}

TEST(Experiment, TheSensitivityReportHasAPointPerExperimentAndPlannerSortedByFactor) {
  // Three sweep points of one group (fake trials: every point has the same metrics), one
  // with registration, and the world config itself as another group's factor 1.
  std::vector<fs::path> dirs;
  for (const auto& [scale, registered] :
       std::vector<std::pair<std::string, bool>>{{"wind=2", false},
                                                 {"wind=0", false},
                                                 {"wind=0.5", false},
                                                 {"wind=1", true},
                                                 {"pose=1", false}}) {
    ExperimentOptions o = options(freshDir("sweep_" + scale + (registered ? "_reg" : "")), 2);
    o.error_scale = scale;
    o.trial.register_views = registered;
    runExperiment(o, fakeTrial, nullptr);
    EXPECT_EQ(nlohmann::json::parse(slurp(o.out_dir / "manifest.json"))["error_scale"], scale);
    dirs.push_back(o.out_dir);
  }
  const fs::path out = freshDir("sweep_report");
  EXPECT_TRUE(writeSensitivityReport(dirs, out, nullptr));
  const nlohmann::json points = nlohmann::json::parse(slurp(out / "sensitivity.json"));
  // 5 experiments x (fvp, rvp and each one's paper-sizing row), and factor 1 shared: pose's
  // unregistered point stands for wind's, wind's registered one for pose's.
  ASSERT_EQ(points.size(), 28u);
  std::map<std::pair<std::string, bool>, std::vector<double>> fvp_factors;
  for (const auto& p : points)
    if (p["planner"] == "fvp")
      fvp_factors[{p["group"].get<std::string>(), p["register_views"].get<bool>()}].push_back(
          p["factor"].get<double>());
  EXPECT_EQ(fvp_factors[std::pair("wind", false)], (std::vector<double>{0.0, 0.5, 1.0, 2.0}));
  EXPECT_EQ(fvp_factors[std::pair("wind", true)], (std::vector<double>{1.0}));
  EXPECT_EQ(fvp_factors[std::pair("pose", false)], (std::vector<double>{1.0}));
  EXPECT_EQ(fvp_factors[std::pair("pose", true)], (std::vector<double>{1.0}));
  // fvp: 4 of 4 fruitlets matched (two worlds of two), errors +0.5 and -1 mm.
  EXPECT_EQ(points[0]["group"], "pose");
  EXPECT_DOUBLE_EQ(points[0]["match_percent"].get<double>(), 100.0);
  EXPECT_DOUBLE_EQ(points[0]["mae_mm"].get<double>(), 0.75);
  EXPECT_EQ(slurp(out / "sensitivity.png").substr(1, 3), "PNG");
  EXPECT_NE(slurp(out / "sensitivity.md").find("| wind | 0.50 | fvp | no | 2 |"), std::string::npos)
      << slurp(out / "sensitivity.md");
  // An experiment that is not a sweep point is named.
  const fs::path plain = freshDir("sweep_plain");
  runExperiment(options(plain, 1), fakeTrial, nullptr);
  const std::string error = errorOf([&] { writeSensitivityReport({plain}, out, nullptr); });
  EXPECT_NE(error.find(plain.string() + ": its manifest has no error scale"), std::string::npos)
      << error;
}

TEST(Experiment, ShardTextIsParsedStrictly) {
  EXPECT_EQ(parseShard("0/4"), std::make_pair(0, 4));
  EXPECT_EQ(parseShard("3/4"), std::make_pair(3, 4));
  EXPECT_EQ(parseShard("12/13"), std::make_pair(12, 13));
  for (const char* bad : {"0/4x", "1/2/3", "4/4", "0/0", "-1/2", "+1/2", "01/2", "1/02", " 1/2",
                          "1 /2", "/2", "1/", "1", "", "0x1/2", "1/9999999999"})
    EXPECT_THROW(parseShard(bad), std::invalid_argument) << bad;
  EXPECT_NE(errorOf([] { parseShard("0/4x"); }).find("'4x' is not a decimal integer"),
            std::string::npos);
}

TEST(Experiment, ResumeWithAChangedSettingIsRefusedNamingIt) {
  const fs::path out = freshDir("changed_setting");
  const fs::path world = freshDir("changed_setting_world.yaml");
  writeText(world, "max_fruitlets: 5\n");
  ExperimentOptions o = options(out, 2);
  o.trial.world_config = world;
  runExperiment(o, fakeTrial, nullptr);
  const nlohmann::json manifest = nlohmann::json::parse(slurp(out / "manifest.json"));
  EXPECT_EQ(manifest["kind"], "run");
  EXPECT_EQ(manifest["budget_s"], 180.0);
  EXPECT_EQ(manifest["world_config"]["path"], fs::absolute(world).string());
  EXPECT_EQ(manifest["world_config"]["fnv1a64"], fnv1a64Hex("max_fruitlets: 5\n"));
  EXPECT_EQ(manifest["planner_config"]["path"], "");
  ExperimentOptions resume = o;
  resume.resume = true;
  resume.trial.budget_s = 90;
  int calls = 0;
  const TrialRunner counting = [&](const TrialOptions& t) { return ++calls, fakeTrial(t); };
  const std::string error = errorOf([&] { runExperiment(resume, counting, nullptr); });
  EXPECT_NE(error.find("manifest.json: this experiment was made with budget_s 180.0, this run "
                       "asks for 90.0"),
            std::string::npos)
      << error;
  // Each row-defining setting and each part of the run's plan is checked.
  const auto refused = [&](const std::function<void(ExperimentOptions&)>& change) {
    ExperimentOptions r = o;
    r.resume = true;
    change(r);
    return errorOf([&] { runExperiment(r, counting, nullptr); });
  };
  const std::string clock =
      refused([](auto& r) { r.trial.clock = robot::sim::SimClock::Mode::kFixed; });
  EXPECT_NE(clock.find("clock wall, this run asks for fixed"), std::string::npos) << clock;
  EXPECT_NE(refused([](auto& r) { r.trial.max_views = 3; }).find("max_views"), std::string::npos);
  const std::string stop = refused([](auto& r) { r.trial.stop = host::nbv::StopRule::kAuto; });
  EXPECT_NE(stop.find("stop budget, this run asks for auto"), std::string::npos) << stop;
  EXPECT_EQ(manifest["stop"], "budget");
  const std::string registration = refused([](auto& r) { r.trial.register_views = true; });
  EXPECT_NE(registration.find("register_views false, this run asks for true"), std::string::npos)
      << registration;
  EXPECT_EQ(manifest["register_views"], false);
  EXPECT_NE(refused([](auto& r) {
              r.trial.engine = "octomap";
            }).find("engine (each planner's own), this run asks for octomap"),
            std::string::npos);
  EXPECT_NE(refused([](auto& r) { r.planners = {"fvp"}; }).find("planners fvp,rvp"),
            std::string::npos);
  EXPECT_NE(refused([](auto& r) { r.trials = 3; }).find("trials 2"), std::string::npos);
  EXPECT_NE(refused([](auto& r) { r.first_seed = 11; }).find("first_seed 10"), std::string::npos);
  EXPECT_NE(refused([](auto& r) {
              r.shard_index = 1;
              r.shard_count = 2;
            }).find("shard 0/1, this run asks for 1/2"),
            std::string::npos);
  EXPECT_NE(refused([](auto& r) {
              r.trial.planner_config = r.trial.world_config;
            }).find("planner_config built-in defaults"),
            std::string::npos);
  EXPECT_EQ(manifest["arm_config"]["path"], "");
  EXPECT_NE(refused([](auto& r) {
              r.trial.arm_config = r.trial.world_config;
            }).find("arm_config built-in defaults"),
            std::string::npos);
  // An edited config file under the same path is caught by its hash.
  writeText(world, "max_fruitlets: 6\n");
  EXPECT_NE(refused([](auto&) {})
                .find("world_config " + fs::absolute(world).string() + " (fnv1a64 " +
                      fnv1a64Hex("max_fruitlets: 5\n") + ")"),
            std::string::npos);
  writeText(world, "max_fruitlets: 5\n");
  EXPECT_EQ(refused([](auto&) {}), "");  // the same settings resume
  EXPECT_EQ(calls, 0);
}

TEST(Experiment, ADirectoryWithoutAManifestIsNotResumedOrMerged) {
  // An experiment directory from an fvp before manifests: trials.jsonl only.
  const fs::path made = freshDir("old_made"), old = freshDir("old_format");
  runExperiment(options(made, 1), fakeTrial, nullptr);
  fs::create_directories(old);
  fs::copy_file(made / "trials.jsonl", old / "trials.jsonl");
  ExperimentOptions resume = options(old, 1);
  resume.resume = true;
  const std::string error = errorOf([&] { runExperiment(resume, fakeTrial, nullptr); });
  EXPECT_NE(error.find("trials.jsonl: no manifest.json beside it"), std::string::npos) << error;
  const std::string merge_error = errorOf([&] {
    mergeExperiments({made, old}, freshDir("old_merged"));
  });
  EXPECT_NE(merge_error.find(old.string() + " has trials.jsonl but no manifest.json"),
            std::string::npos)
      << merge_error;
}

TEST(Experiment, MergeRefusesShardsWithDifferentSettingsNamingThem) {
  const fs::path a = freshDir("clock_wall"), b = freshDir("clock_fixed");
  ExperimentOptions s0 = options(a, 2), s1 = options(b, 2);
  s0.shard_count = s1.shard_count = 2;
  s1.shard_index = 1;
  s1.trial.clock = robot::sim::SimClock::Mode::kFixed;
  runExperiment(s0, fakeTrial, nullptr);
  runExperiment(s1, fakeTrial, nullptr);
  const fs::path merged = freshDir("clock_merged");
  const std::string error = errorOf([&] { mergeExperiments({a, b}, merged); });
  EXPECT_NE(error.find("merge: " + a.string() + " and " + b.string() +
                       " are different experiments: clock is wall in the first and fixed in "
                       "the second"),
            std::string::npos)
      << error;
  EXPECT_FALSE(fs::exists(merged));
  // A different budget too; different planners, seeds and shards merge (below).
  ExperimentOptions s2 = options(freshDir("budget_90"), 2);
  s2.trial.budget_s = 90;
  s2.first_seed = 20;
  runExperiment(s2, fakeTrial, nullptr);
  EXPECT_NE(errorOf([&] {
              mergeExperiments({a, s2.out_dir}, merged);
            }).find("budget_s is 180.0"),
            std::string::npos);
}

TEST(Experiment, AnEmptyShardIsAValidExperimentAndMerges) {
  const fs::path whole = freshDir("empty_whole");
  ExperimentOptions w = options(whole, 2);
  w.planners = {"fvp"};
  runExperiment(w, fakeTrial, nullptr);
  std::vector<fs::path> shards;
  for (int i = 0; i < 4; ++i) {
    ExperimentOptions s = options(freshDir("empty_shard" + std::to_string(i)), 2);
    s.planners = {"fvp"};
    s.shard_index = i;
    s.shard_count = 4;
    runExperiment(s, fakeTrial, nullptr);
    shards.push_back(s.out_dir);
  }
  // Shards 2 and 3 of two trials: a manifest, an empty trials.jsonl, reports with no rows.
  for (int i = 2; i < 4; ++i) {
    EXPECT_TRUE(fs::exists(shards[i] / "manifest.json"));
    EXPECT_EQ(slurp(shards[i] / "trials.jsonl"), "");
    EXPECT_EQ(nlohmann::json::parse(slurp(shards[i] / "summary.json")), nlohmann::json::object());
    EXPECT_NE(slurp(shards[i] / "table1.md").find("sizes.png: not drawn: no trials"),
              std::string::npos);
    ExperimentOptions again = options(shards[i], 2);
    again.planners = {"fvp"};
    again.shard_index = i;
    again.shard_count = 4;
    again.resume = true;
    EXPECT_NO_THROW(runExperiment(again, fakeTrial, nullptr));
  }
  const fs::path merged = freshDir("empty_merged");
  mergeExperiments(shards, merged);
  EXPECT_EQ(slurp(merged / "trials.jsonl"), slurp(whole / "trials.jsonl"));
  EXPECT_EQ(slurp(merged / "summary.json"), slurp(whole / "summary.json"));
  const nlohmann::json manifest = nlohmann::json::parse(slurp(merged / "manifest.json"));
  EXPECT_EQ(manifest["kind"], "merged");
  EXPECT_EQ(manifest["sources"].size(), 4u);
  EXPECT_EQ(readManifest(merged / "manifest.json").sources[3], shards[3].string());
  // Merging again into the merged directory is fine; into a run's directory it is not.
  EXPECT_NO_THROW(mergeExperiments(shards, merged));
  EXPECT_NE(errorOf([&] {
              mergeExperiments({shards[0], shards[1]}, whole);
            }).find("holds an experiment run"),
            std::string::npos);
}

TEST(Experiment, SchemaErrorsNameTheFileTheLineAndTheField) {
  const fs::path out = freshDir("schema");
  runExperiment(options(out, 1), fakeTrial, nullptr);
  const std::vector<std::string> lines = linesOf(out / "trials.jsonl");
  ASSERT_EQ(lines.size(), 2u);
  const nlohmann::json good = nlohmann::json::parse(lines[1]);
  const auto errorFor = [&](const std::string& second_line) {
    writeText(out / "trials.jsonl", lines[0] + "\n" + second_line + "\n");
    return errorOf([&] { readTrials(out / "trials.jsonl", nullptr); });
  };
  const auto with = [&](const std::string& pointer, const nlohmann::json& value) {
    nlohmann::json t = good;
    t[nlohmann::json::json_pointer(pointer)] = value;
    return t.dump();
  };
  const auto without = [&](const std::string& pointer) {
    nlohmann::json t = good;
    t[nlohmann::json::json_pointer(pointer).parent_pointer()].erase(
        nlohmann::json::json_pointer(pointer).back());
    return t.dump();
  };
  const std::string at = (out / "trials.jsonl").string() + ": line 2: ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {with("/seed", -1), "field 'seed': expected an unsigned integer, got -1"},
      {with("/seed", 1.5), "field 'seed': expected an unsigned integer, got 1.5"},
      {"{\"planner\": \"rvp\", \"seed\": 18446744073709551616, \"fruitlets\": []}",
       "field 'seed': expected an unsigned integer"},
      {with("/planner", "n bv"),
       "field 'planner': expected a planner name (lower-case letters, digits and _), got \"n "
       "bv\""},
      {without("/planner"),
       "field 'planner': expected a planner name (lower-case letters, "
       "digits and _), but it is missing"},
      {with("/engine", 3),
       "field 'engine': expected \"\" (the planner's own) or a map engine "
       "name (lower-case letters, digits and _), got 3"},
      {with("/engine", "GPU"), "field 'engine': expected \"\" (the planner's own) or a map"},
      {with("/settings", nlohmann::json{{"engine", "a b"}}), "field 'settings.engine'"},
      {with("/views", -3), "field 'views': expected a non-negative integer"},
      {with("/detections", "2"), "field 'detections': expected a non-negative integer"},
      {with("/wall_time_s", nullptr), "field 'wall_time_s': expected a finite non-negative"},
      {without("/fruitlets"), "field 'fruitlets': expected an array of fruitlets"},
      {with("/fruitlets", nlohmann::json::object()), "field 'fruitlets': expected an array"},
      {with("/fruitlets", nlohmann::json::array({nlohmann::json{{"gt_size_mm", "x"}}})),
       "field 'fruitlets[0].gt_size_mm': expected a finite positive number, got \"x\""},
      {with("/fruitlets/1/gt_size_mm", 0), "field 'fruitlets[1].gt_size_mm': expected a finite"},
      {with("/fruitlets/0/matched", 1), "field 'fruitlets[0].matched': expected true or false"},
      {without("/fruitlets/0/est_size_mm"),
       "field 'fruitlets[0].est_size_mm': expected a finite number (the fruitlet is matched)"},
      {with("/fruitlets/1", 5), "field 'fruitlets[1]': expected an object"},
      {with("/fruitlets_paper_sizing/0/est_size_mm", "7"),
       "field 'fruitlets_paper_sizing[0].est_size_mm': expected a finite number"},
      {"[]", "expected one trial's result (a JSON object), got []"},
      {"{\"planner\": ", "expected one trial's result as JSON"},
  };
  for (const auto& [line, expected] : cases) {
    const std::string error = errorFor(line);
    EXPECT_NE(error.find(at + expected), std::string::npos) << line << "\n -> " << error;
  }
  // The unmatched fruitlet's est_size_mm is null in a real trial: fine.
  EXPECT_EQ(errorFor(with("/fruitlets/1/est_size_mm", nullptr)), "");
  // A run's manifest is read as strictly; one written before --stop existed ran on the budget.
  nlohmann::json manifest = nlohmann::json::parse(slurp(out / "manifest.json"));
  manifest.erase("stop");
  writeText(out / "manifest.json", manifest.dump());
  EXPECT_EQ(readManifest(out / "manifest.json").settings.stop, host::nbv::StopRule::kBudget);
  manifest["stop"] = "never";
  writeText(out / "manifest.json", manifest.dump());
  EXPECT_NE(errorOf([&] {
              readManifest(out / "manifest.json");
            }).find("manifest.json: field 'stop': expected one of \"budget\", \"auto\""),
            std::string::npos);
  manifest["stop"] = "budget";
  // Format 1 wrote 0 for no view cap; format 2 writes null.
  manifest["max_views"] = 0;
  writeText(out / "manifest.json", manifest.dump());
  EXPECT_FALSE(readManifest(out / "manifest.json").settings.max_views.has_value());
  manifest["max_views"] = nullptr;
  writeText(out / "manifest.json", manifest.dump());
  EXPECT_FALSE(readManifest(out / "manifest.json").settings.max_views.has_value());
  manifest["max_views"] = -2;
  writeText(out / "manifest.json", manifest.dump());
  EXPECT_NE(errorOf([&] { readManifest(out / "manifest.json"); }).find("field 'max_views'"),
            std::string::npos);
  manifest["max_views"] = 4;
  manifest["budget_s"] = "x";
  writeText(out / "manifest.json", manifest.dump());
  EXPECT_NE(errorOf([&] {
              readManifest(out / "manifest.json");
            }).find("manifest.json: field 'budget_s': expected a finite positive number"),
            std::string::npos);
}

TEST(Experiment, TheManifestRecordsEveryTrialSettingButThePerTrialOnes) {
  // Written and read through the trial's settings list (trials/trial_fields.h): a setting
  // added there is recorded, read back and compared with no change here.
  ExperimentManifest m;
  m.settings.budget_s = 90;
  m.settings.max_views = 3;
  m.settings.stop = host::nbv::StopRule::kAuto;
  m.settings.backend = accel::BackendChoice::kVulkan;
  m.settings.record_size_history = true;
  m.settings.register_views = true;
  m.planners = {"fvp"};
  m.trials = 1;
  const nlohmann::ordered_json j = m.toJson();
  std::set<std::string> keys;
  for (const auto& [key, value] : j.items()) keys.insert(key);
  const TrialOptions defaults;
  visitTrialFields(defaults, [&](const host::nbv::RunField& field, const auto&) {
    EXPECT_EQ(keys.count(std::string(field.key)), field.per_trial ? 0u : 1u) << field.key;
  });
  const fs::path dir = freshDir("manifest_fields");
  fs::create_directories(dir);
  writeText(dir / "manifest.json", j.dump(2));
  const ExperimentManifest read = readManifest(dir / "manifest.json");
  EXPECT_EQ(read.toJson(), j);
  EXPECT_FALSE(mergeDifference(m, read).has_value());
  // Each recorded setting is compared: a changed one is named.
  ExperimentManifest other = read;
  other.settings.record_size_history = false;
  ASSERT_TRUE(mergeDifference(read, other).has_value());
  EXPECT_EQ(mergeDifference(read, other)->setting, "size_history");
  // The backend picks the device: recorded, never compared; the engine only on resume.
  other = read;
  other.settings.backend = accel::BackendChoice::kCpu;
  other.settings.engine = "octomap";
  EXPECT_FALSE(mergeDifference(read, other).has_value());
  ASSERT_TRUE(resumeDifference(read, other).has_value());
  EXPECT_EQ(resumeDifference(read, other)->setting, "engine");
  EXPECT_EQ(resumeDifference(read, other)->old_value, "(each planner's own)");
}

TEST(Experiment, TrialsTimedByAnotherClockAreNeverPooled) {
  // A manifest without clock_charges was made before the clock charged perception: its
  // trials' times are not this build's, so neither resume nor merge pools them.
  ExperimentManifest m;
  m.planners = {"fvp"};
  m.trials = 1;
  nlohmann::ordered_json j = m.toJson();
  EXPECT_EQ(j["clock_charges"], ExperimentManifest::kClockCharges);
  j.erase("clock_charges");
  const fs::path dir = freshDir("manifest_clock");
  fs::create_directories(dir);
  writeText(dir / "manifest.json", j.dump(2));
  const ExperimentManifest old = readManifest(dir / "manifest.json");
  EXPECT_EQ(old.clock_charges, ExperimentManifest::kClockChargesBeforePerception);
  for (const auto& d : {resumeDifference(old, m), mergeDifference(old, m)}) {
    ASSERT_TRUE(d.has_value());
    EXPECT_EQ(d->setting, "clock_charges");
  }
  writeText(dir / "manifest.json", m.toJson().dump(2));
  EXPECT_FALSE(resumeDifference(readManifest(dir / "manifest.json"), m).has_value());
  // The guided stereo pass is charged its own perception since 2026-12-01: its runs charged
  // SGBM's before are not pooled with those after; SGBM's runs keep their words.
  EXPECT_STREQ(ExperimentManifest::clockChargesFor(false), ExperimentManifest::kClockCharges);
  ExperimentManifest guided = m;
  guided.settings.guided_stereo = true;
  guided.clock_charges = ExperimentManifest::clockChargesFor(true);
  ExperimentManifest guided_before = guided;
  guided_before.clock_charges = ExperimentManifest::kClockCharges;
  for (const auto& d :
       {resumeDifference(guided_before, guided), mergeDifference(guided_before, guided)}) {
    ASSERT_TRUE(d.has_value());
    EXPECT_EQ(d->setting, "clock_charges");
  }
  j["clock_charges"] = 7;
  writeText(dir / "manifest.json", j.dump(2));
  EXPECT_NE(errorOf([&] { readManifest(dir / "manifest.json"); }).find("field 'clock_charges'"),
            std::string::npos);
}

TEST(Experiment, ABadTrialResultIsNotAppended) {
  const fs::path out = freshDir("bad_result");
  const TrialRunner bad = [](const TrialOptions& o) {
    nlohmann::json r = fakeTrial(o);
    if (o.planner == "rvp") r["fruitlets"][0]["est_size_mm"] = NAN;  // written as null
    return r;
  };
  const std::string error = errorOf([&] { runExperiment(options(out, 1), bad, nullptr); });
  EXPECT_NE(error.find("the result of trial rvp-10: field 'fruitlets[0].est_size_mm'"),
            std::string::npos)
      << error;
  EXPECT_EQ(readTrials(out / "trials.jsonl", nullptr).size(), 1u);
}

/// Sets an environment variable for a scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(Experiment, APlotFailureIsAWarningAndTheReportsStand) {
  const fs::path out = freshDir("no_gnuplot"), empty_bin = freshDir("no_gnuplot_bin");
  fs::create_directories(empty_bin);
  std::vector<std::string> warnings;
  {
    const ScopedEnv path("PATH", empty_bin.string());  // no gnuplot to be found
    EXPECT_NO_THROW(runExperiment(options(out, 2), fakeTrial, nullptr,
                                  [&](const std::string& w) { warnings.push_back(w); }));
  }
  ASSERT_EQ(warnings.size(), 1u);
  // The reason is plotWithGnuplot's message, whatever it says.
  EXPECT_NE(warnings[0].find("sizes.png not drawn: size distribution figure"), std::string::npos)
      << warnings[0];
  EXPECT_FALSE(fs::exists(out / "sizes.png"));
  EXPECT_EQ(readTrials(out / "trials.jsonl", nullptr).size(), 4u);
  EXPECT_EQ(nlohmann::json::parse(slurp(out / "summary.json"))["fvp"]["trials"], 2);
  const std::string table = slurp(out / "table1.md");
  EXPECT_NE(table.find("| FVP (ours) | 2 |"), std::string::npos);
  EXPECT_NE(table.find("sizes.png: not drawn: size distribution figure"), std::string::npos)
      << table;
  // With gnuplot back, a resume draws it.
  ExperimentOptions resume = options(out, 2);
  resume.resume = true;
  runExperiment(resume, fakeTrial, nullptr);
  EXPECT_TRUE(fs::exists(out / "sizes.png"));
  EXPECT_NE(slurp(out / "table1.md").find("Size distributions: sizes.png."), std::string::npos);
}

TEST(Experiment, AnOutputPathThatIsARegularFileIsAnErrorBeforeAnyTrial) {
  const fs::path dir = freshDir("out_is_file");
  fs::create_directories(dir);
  writeText(dir / "file", "x");
  int calls = 0;
  const std::string error = errorOf([&] {
    runExperiment(
        options(dir / "file", 1), [&](const TrialOptions& o) { return ++calls, fakeTrial(o); },
        nullptr);
  });
  EXPECT_NE(error.find("--out '" + (dir / "file").string() + "': exists and is not a directory"),
            std::string::npos)
      << error;
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(slurp(dir / "file"), "x");
}

}  // namespace
}  // namespace fvp::trials
