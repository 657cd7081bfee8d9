// The experiment runner with a deterministic stand-in for the trial (a real trial takes
// minutes): pooled metrics by hand, resume after an interruption, shard + merge equals one
// run, and clear errors for corrupt files and unwritable directories.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "fvp/robot/sim/experiment.h"

namespace fvp::robot::sim {
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

}  // namespace
}  // namespace fvp::robot::sim
