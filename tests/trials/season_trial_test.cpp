// A simulated season (trials/season_trial.h): visits of one tree on two days, each a trial of
// the grown world; with a fixed clock the season repeats exactly; the season experiment keeps
// finished seasons only on --resume and only with the same settings and days; a later visit
// starts from the one before it. One view a cluster keeps it short.
#include "fvp/trials/season_trial.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace fvp::trials {
namespace {

class SeasonTrial : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("fvp_season_trial_test_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "tree.yaml") << "cluster_count: 2\nleaf_count: 10\nmin_radius_m: 0.003\n"
                                         "max_radius_m: 0.005\n";
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  SeasonExperimentOptions options(const std::string& out) const {
    SeasonExperimentOptions o;
    o.season.visit.world_config = dir_ / "tree.yaml";
    o.season.visit.backend = accel::BackendChoice::kCpu;
    o.season.visit.clock = robot::sim::SimClock::Mode::kFixed;
    o.season.visit.max_views = 1;
    o.season.days = {0.0, 5.0};
    o.seasons = 1;
    o.first_seed = 3;
    o.out_dir = dir_ / out;
    return o;
  }

  static nlohmann::json withoutWallTime(nlohmann::json line) {
    for (auto& v : line["visits"]) v.erase("wall_time_s");
    return line;
  }

  std::filesystem::path dir_;
};

TEST_F(SeasonTrial, RepeatsExactlyAndResumesOnlyWhatItWouldRun) {
  const SeasonExperimentOptions first = options("a");
  const nlohmann::json summary = runSeasonExperiment(first);
  EXPECT_EQ(summary["seasons"], 1);
  const std::filesystem::path season = first.out_dir / "season-3";
  for (const char* file : {"day-0/result.json", "day-5/result.json", "season.json",
                           "season_score.json", "../summary.json", "../table.md"})
    EXPECT_TRUE(std::filesystem::exists(season / file)) << file;
  const std::vector<nlohmann::json> lines = readSeasons(first.out_dir);
  ASSERT_EQ(lines.size(), 1u);
  const nlohmann::json& line = lines.front();
  ASSERT_EQ(line["visits"].size(), 2u);
  EXPECT_EQ(line["visits"][1]["day"], 5.0);
  // The later visit saw the grown tree: its truth is of day 5.
  std::ifstream day5(season / "day-5/result.json");
  const nlohmann::json day5_result = nlohmann::json::parse(day5);
  EXPECT_EQ(day5_result["settings"]["season_day"], 5.0);
  // ...and started from the visit before it: each cluster remembered its fruitlets and views.
  EXPECT_EQ(day5_result["remembered_visit"], (season / "day-0").string());
  ASSERT_EQ(day5_result["clusters"].size(), 2u);
  for (const auto& c : day5_result["clusters"]) {
    EXPECT_GT(c["memory"]["fruitlets"].get<int>(), 0) << c["memory"].dump();
    EXPECT_GT(c["memory"]["views"].get<int>(), 0) << c["memory"].dump();
  }
  EXPECT_EQ(line["settings"]["remember_visits"], true);
  EXPECT_GT(line["score"]["fruitlets"].get<int>(), 0);
  // Every visit placed its clusters in their tags' frames (the start view sees each tag).
  std::ifstream season_json(season / "season.json");
  const nlohmann::json analysis = nlohmann::json::parse(season_json);
  ASSERT_EQ(analysis["clusters"].size(), 2u);
  for (const auto& c : analysis["clusters"]) {
    EXPECT_EQ(c["visits_with_tag"], 2) << c.dump();
    EXPECT_FALSE(c["fruitlets"].empty()) << c.dump();
  }

  // The same season again, elsewhere: the same line, wall times aside.
  SeasonTrialOptions again = first.season;
  again.visit.seed = 3;
  again.out_dir = dir_ / "b";
  EXPECT_EQ(withoutWallTime(runSeasonTrial(again)), withoutWallTime(line));

  // A season cut short keeps its finished visits on resume: rescored from them, the same.
  std::filesystem::remove(season / "season_score.json");
  std::filesystem::remove(season / "day-5" / "result.json");
  SeasonExperimentOptions cut = first;
  cut.resume = true;
  runSeasonExperiment(cut);
  EXPECT_EQ(withoutWallTime(readSeasons(first.out_dir).front()), withoutWallTime(line));
  // Kept, not run again: a mark put in day 0's result comes back in the season's line.
  std::filesystem::remove(season / "season_score.json");
  nlohmann::json day0 = nlohmann::json::parse(std::ifstream(season / "day-0/result.json"));
  day0["views"] = 999;
  std::ofstream(season / "day-0/result.json") << day0.dump();
  runSeasonExperiment(cut);
  EXPECT_EQ(readSeasons(first.out_dir).front()["visits"][0]["views"], 999);

  // Finished seasons: kept on --resume, an error without it or with other days.
  EXPECT_THROW(runSeasonExperiment(first), std::runtime_error);
  SeasonExperimentOptions resume = first;
  resume.resume = true;
  EXPECT_EQ(runSeasonExperiment(resume)["seasons"], 1);
  resume.season.days = {0.0, 6.0};
  try {
    runSeasonExperiment(resume);
    FAIL() << "resumed a season of other days";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("days"), std::string::npos) << e.what();
  }
}

/// A season's line as summarizeSeasons reads it: one visit, and a score whose growth holds
/// the given sizes (each {track, size_mm, truth_mm, standard_error_mm}).
nlohmann::json seasonLine(const nlohmann::json& sizes) {
  const nlohmann::json confusion = {
      {"true_drops", 1}, {"false_drops", 0}, {"missed_drops", 0}, {"true_stays", 3}};
  return {{"visits",
           {{{"sim_time_s", 100.0},
             {"gt_fruitlets", 4},
             {"matched", 4},
             {"detections", 4},
             {"mae_mm", 0.2}}}},
          {"score",
           {{"association", {{"links_made", 2}, {"links_correct", 2}}},
            {"gone", {{"fallen_sized", 1}, {"reported_gone", 1}}},
            {"growth",
             {{"tracks_scored", 2},
              {"mae_mm_per_day", 0.05},
              {"size_error_floor_fit_mm", 0.5},
              {"sizes", sizes}}},
            {"fate", {{"robot", confusion}, {"calipers", confusion}}},
            {"fruit_set_percent", {{"truth", 75.0}, {"robot", 70.0}, {"calipers", 75.0}}}}}};
}

nlohmann::json sizeRecord(std::size_t track, double error_mm, nlohmann::json se_mm) {
  return {{"track", track},
          {"size_mm", 6.0 + error_mm},
          {"truth_mm", 6.0},
          {"standard_error_mm", std::move(se_mm)}};
}

TEST(SeasonSummary, FitsTheFloorOverEverySeasonsSizes) {
  // Season A: track 0 deviates by 0.2 mm (stated 0.1); track 1 lacks a standard error and is
  // left out. Season B: the same deviation, and a line scored before sizes were recorded.
  const nlohmann::json a = seasonLine({sizeRecord(0, 0.2, 0.1), sizeRecord(0, -0.2, 0.1),
                                       sizeRecord(1, 0.3, nullptr), sizeRecord(1, 0.0, 0.1)});
  const nlohmann::json b = seasonLine({sizeRecord(0, 0.2, 0.1), sizeRecord(0, -0.2, 0.1)});
  nlohmann::json old = seasonLine({});
  old["score"]["growth"].erase("sizes");
  const nlohmann::json summary = summarizeSeasons({a, b, old});
  EXPECT_EQ(summary["size_error_floor_fit_tracks"], 2);
  // Two tracks of deviation +-0.2 about their means, one dof each: 2 * 0.08 / (0.01 + f^2) = 2.
  EXPECT_NEAR(summary["size_error_floor_fit_mm"].get<double>(), std::sqrt(0.07), 1e-6);
  EXPECT_NEAR(summarizeSeasons({a})["size_error_floor_fit_mm"].get<double>(), std::sqrt(0.07),
              1e-6);
  EXPECT_TRUE(summarizeSeasons({old})["size_error_floor_fit_mm"].is_null());
  EXPECT_NE(seasonTable(summary).find("the floor that would account for them: 0.26 mm"),
            std::string::npos)
      << seasonTable(summary);
}

TEST(SeasonDays, AreCheckedNamingTheDay) {
  EXPECT_THROW(checkSeasonDays({0.0}), std::invalid_argument);
  EXPECT_THROW(checkSeasonDays({0.0, 4.0, 4.0}), std::invalid_argument);
  EXPECT_THROW(checkSeasonDays({0.0, 61.0}), std::invalid_argument);
  EXPECT_THROW(checkSeasonDays({-1.0, 4.0}), std::invalid_argument);
  EXPECT_NO_THROW(checkSeasonDays({0.0, 3.5, 7.0}));
  try {
    checkSeasonDays({0.0, 7.0, 4.0});
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("4"), std::string::npos);
  }
}

}  // namespace
}  // namespace fvp::trials
