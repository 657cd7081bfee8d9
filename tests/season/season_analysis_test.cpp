// A season from visits as results hold them: the visit reader, the tracks across visits,
// fates and fruit set by hand (tests/season/data: a tree of two clusters on days 0 and 4).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "fvp/host/season/season_analysis.h"

namespace fvp::host::season {
namespace {

const std::string kData = std::string(FVP_SOURCE_DIR) + "/tests/season/data/";

std::string errorOf(const std::string& text) {
  try {
    parseSeasonVisit(text, "visit.json", 0.0);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(SeasonVisit, ReadsATreesClustersInTheTagsFrame) {
  const SeasonVisit v = readSeasonVisit(kData + "tree_day0.json", 0.0);
  ASSERT_EQ(v.clusters.size(), 2u);
  EXPECT_EQ(v.clusters[0].tag_id, 3);
  EXPECT_EQ(v.clusters[1].tag_id, 5);
  ASSERT_EQ(v.clusters[0].fruitlets.size(), 3u);
  EXPECT_NEAR(v.clusters[0].fruitlets[1].at.center_tag_m.x(), 0.012, 1e-12);
  EXPECT_DOUBLE_EQ(v.clusters[0].fruitlets[2].standard_error_mm, 0.25);
  EXPECT_TRUE(std::isnan(v.clusters[1].fruitlets[1].standard_error_mm));  // null: unknown
}

TEST(SeasonVisit, OneClusterAndAClusterWithoutItsTag) {
  const SeasonVisit one = parseSeasonVisit(
      R"({"T_world_tag": {}, "sized_fruitlets": [{"center_tag_m": [0, 0, 0.05], "size_mm": 7}]})",
      "result.json", 2.0);
  ASSERT_EQ(one.clusters.size(), 1u);
  EXPECT_EQ(one.clusters[0].tag_id, 0);
  EXPECT_EQ(one.clusters[0].fruitlets.size(), 1u);
  const SeasonVisit unseen = parseSeasonVisit(
      R"({"clusters": [{"tag_id": 2, "sized_fruitlets": []}, {"tag_id": 4}]})", "r.json", 0.0);
  ASSERT_EQ(unseen.clusters.size(), 1u);  // the second was never run
  EXPECT_FALSE(unseen.clusters[0].tag_seen);
}

TEST(SeasonVisit, BadVisitsNameTheFileAndTheField) {
  EXPECT_EQ(errorOf("[1]"),
            "visit.json: the document: expected an object (a result.json or fruitlets.json)");
  EXPECT_NE(errorOf("{").find("visit.json: not JSON"), std::string::npos);
  EXPECT_EQ(errorOf(R"({"T_world_tag": {}, "sized_fruitlets": [{"size_mm": 7}]})"),
            "visit.json: sized_fruitlets[0].center_tag_m: expected the centre in the tag's frame");
  EXPECT_EQ(
      errorOf(
          R"({"T_world_tag": {}, "sized_fruitlets": [{"center_tag_m": [0, 0], "size_mm": 7}]})"),
      "visit.json: sized_fruitlets[0].center_tag_m: expected an array of 3 numbers");
  EXPECT_EQ(
      errorOf(
          R"({"T_world_tag": {}, "sized_fruitlets": [{"center_tag_m": [0, 0, 0], "size_mm": -1}]})"),
      "visit.json: sized_fruitlets[0].size_mm: expected a size > 0");
  EXPECT_EQ(errorOf(R"({"clusters": [{"tag_id": -3, "T_world_tag": {}, "sized_fruitlets": []}]})"),
            "visit.json: clusters[0].tag_id: expected a tag id (an integer >= 0)");
  EXPECT_EQ(errorOf(R"({"clusters": 3})"),
            "visit.json: clusters: expected an array (a tree's clusters)");
  EXPECT_THROW(readSeasonVisit(kData + "no_such_visit.json", 0.0), std::runtime_error);
  EXPECT_EQ(
      errorOf(R"({"clusters": [{"tag_id": 1, "T_world_tag": {}, "sized_fruitlets": []},
                                     {"tag_id": 1, "T_world_tag": {}, "sized_fruitlets": []}]})"),
      "visit.json: clusters[1].tag_id: expected a tag of its own (clusters[0] has tag 1 too)");
  EXPECT_EQ(errorOf(R"({"T_world_tag": {}, "sized_fruitlets": [{"center_tag_m": [0, 0, 0],
                        "size_mm": 7, "support": {"size_stderr_mm": -0.2}}]})"),
            "visit.json: sized_fruitlets[0].support.size_stderr_mm: expected -1 or 0 (unknown) "
            "or a standard error from 1e-6 to 1000 mm");
  EXPECT_EQ(errorOf(R"({"T_world_tag": {}, "sized_fruitlets": [{"center_tag_m": [0, 0, 0],
                        "size_mm": 7, "support": 3}]})"),
            "visit.json: sized_fruitlets[0].support: expected an object");
  EXPECT_EQ(errorOf(R"({"T_world_tag": {}, "sized_fruitlets": [{"center_tag_m": [0, 0, 0],
                        "size_mm": 7, "support": {"well_seen_images": 2.5}}]})"),
            "visit.json: sized_fruitlets[0].support.well_seen_images: expected a count of images "
            "(an integer from 0 to 2147483647)");
  EXPECT_EQ(errorOf(R"({"T_world_tag": {}, "sized_fruitlets": [{"center_tag_m": [0, 0, 0],
                        "size_mm": 7, "support": {"well_seen_images": -1}}]})"),
            "visit.json: sized_fruitlets[0].support.well_seen_images: expected a count of images "
            "(an integer from 0 to 2147483647)");
  EXPECT_EQ(errorOf(R"({"T_world_tag": {}, "sized_fruitlets": [{"center_tag_m": [0, 0, 0],
                        "size_mm": 7, "support": {"size_stderr_mm": 1e200}}]})"),
            "visit.json: sized_fruitlets[0].support.size_stderr_mm: expected -1 or 0 (unknown) "
            "or a standard error from 1e-6 to 1000 mm");
  std::string crowded = R"({"T_world_tag": {}, "sized_fruitlets": [)";
  for (int i = 0; i < 65; ++i)
    crowded += std::string(i ? "," : "") + R"({"center_tag_m": [0, 0, 0], "size_mm": 7})";
  EXPECT_EQ(errorOf(crowded + "]}"),
            "visit.json: sized_fruitlets: expected at most 64 fruitlets in a cluster");
}

// Tag 3: fruitlets grew 3.6 and 3.2 mm and one 0.4 mm in 4 days; tag 5: one grew 3.0 mm, one
// fell off. Reference: the fastest fifth of 4 rates, the fastest alone, 0.9 mm/day.
TEST(SeasonAnalysis, TwoVisitsOfATreeByHand) {
  SeasonConfig stated_errors_alone;
  stated_errors_alone.size_error_floor_mm = 0.0;
  const SeasonAnalysis s = analyzeSeason({readSeasonVisit(kData + "tree_day4.json", 4.0),
                                          readSeasonVisit(kData + "tree_day0.json", 0.0)},
                                         stated_errors_alone);
  EXPECT_EQ(s.days, (std::vector<double>{0.0, 4.0}));  // in day order
  ASSERT_EQ(s.clusters.size(), 2u);
  ASSERT_EQ(s.tracks.size(), 5u);
  EXPECT_NEAR(s.reference_mm_per_day, 0.9, 1e-12);
  EXPECT_NEAR(s.threshold_mm_per_day, 0.45, 1e-12);
  const auto rate = [&](std::size_t t) { return s.tracks[t].rate.mm_per_day; };
  EXPECT_NEAR(rate(0), 0.9, 1e-12);
  EXPECT_NEAR(rate(1), 0.8, 1e-12);
  EXPECT_NEAR(rate(2), 0.1, 1e-12);
  EXPECT_NEAR(s.tracks[2].rate.standard_error_mm_per_day, std::sqrt(0.0625 + 0.04) / 4, 1e-12);
  EXPECT_EQ(s.tracks[0].fate.fate, Fate::kPersists);
  EXPECT_EQ(s.tracks[2].fate.fate, Fate::kAbscises);
  EXPECT_NEAR(rate(3), 0.75, 1e-12);
  EXPECT_TRUE(s.tracks[4].gone);
  EXPECT_GT(s.tracks[0].sizes[1].association_confidence, 0.99);
  EXPECT_EQ(s.clusters[0].fruit_set.persisting, 2u);
  EXPECT_EQ(s.clusters[0].fruit_set.abscising, 1u);
  EXPECT_NEAR(s.clusters[0].fruit_set.percent, 100.0 * 2 / 3, 0.01);
  EXPECT_EQ(s.clusters[1].fruit_set.gone, 1u);
  EXPECT_NEAR(s.clusters[1].fruit_set.percent, 50.0, 0.01);
  EXPECT_NEAR(s.fruit_set.percent, 60.0, 0.01);
  const nlohmann::json j = seasonJson(s, {});
  EXPECT_EQ(j["format"], 1);
  EXPECT_EQ(j["clusters"][1]["fruitlets"][1]["fate"], "gone");
  EXPECT_EQ(j["clusters"][0]["fruitlets"][2]["fate"], "abscises");
  // A rate weighted by the sizes' own errors: a standard error, normal (no degrees of freedom).
  EXPECT_TRUE(
      j["clusters"][0]["fruitlets"][2]["growth_rate_standard_error_mm_per_day"].is_number());
  EXPECT_TRUE(j["clusters"][0]["fruitlets"][2]["growth_rate_degrees_of_freedom"].is_null());
  EXPECT_EQ(j["clusters"][0]["fruitlets"][0]["sizes"].size(), 2u);
  EXPECT_TRUE(j["clusters"][0]["fruitlets"][0]["sizes"][0]["association_confidence"].is_null());
}

TEST(SeasonVisit, TheImageCountIsReadWhereTheResultGivesIt) {
  const SeasonVisit v = parseSeasonVisit(
      R"({"T_world_tag": {}, "sized_fruitlets": [
            {"center_tag_m": [0, 0, 0], "size_mm": 7,
             "support": {"well_seen_images": 5, "size_stderr_mm": 0.2}},
            {"center_tag_m": [0, 0.02, 0], "size_mm": 6}]})",
      "result.json", 0.0);
  ASSERT_EQ(v.clusters.at(0).fruitlets.size(), 2u);
  EXPECT_EQ(v.clusters[0].fruitlets[0].well_seen_images, 5);
  EXPECT_EQ(v.clusters[0].fruitlets[1].well_seen_images, -1);
}

// The floor adds to each stated error in quadrature: track 2's sizes state 0.25 and 0.2 mm.
TEST(SeasonAnalysis, TheSizeErrorFloorWidensEveryStatedError) {
  const std::vector<SeasonVisit> visits = {readSeasonVisit(kData + "tree_day0.json", 0.0),
                                           readSeasonVisit(kData + "tree_day4.json", 4.0)};
  SeasonConfig config;
  config.size_error_floor_mm = 0.0;
  const double bare = analyzeSeason(visits, config).tracks[2].rate.standard_error_mm_per_day;
  EXPECT_NEAR(bare, std::sqrt(0.0625 + 0.04) / 4, 1e-12);
  config.size_error_floor_mm = 0.3;
  const SeasonAnalysis s = analyzeSeason(visits, config);
  EXPECT_NEAR(s.tracks[2].rate.standard_error_mm_per_day, std::sqrt(0.0625 + 0.04 + 2 * 0.09) / 4,
              1e-12);
  EXPECT_NEAR(s.tracks[2].rate.mm_per_day, 0.1, 1e-12);
  EXPECT_EQ(seasonJson(s, config)["config"]["size_error_floor_mm"], 0.3);
  for (const double bad : {-0.1, 1001.0, double(NAN), double(INFINITY)}) {
    config.size_error_floor_mm = bad;
    EXPECT_THROW(analyzeSeason(visits, config), std::invalid_argument) << bad;
  }
}

TEST(SeasonAnalysis, AVisitWithoutTheTagLeavesTheFruitletsAndTwoOnOneDayAreRefused) {
  const SeasonVisit day0 = readSeasonVisit(kData + "tree_day0.json", 0.0);
  SeasonVisit blind = readSeasonVisit(kData + "tree_day4.json", 4.0);
  blind.clusters[1].tag_seen = false;
  blind.clusters[1].fruitlets.clear();
  const SeasonAnalysis s = analyzeSeason({day0, blind});
  EXPECT_EQ(s.clusters[1].visits_without_tag, 1u);
  EXPECT_FALSE(s.tracks[3].gone);  // not looked at: not gone, and no rate (unknown)
  EXPECT_EQ(s.tracks[3].fate.fate, Fate::kUnknown);
  EXPECT_THROW(analyzeSeason({day0, day0}), std::invalid_argument);
}

// A fruitlet the later visit did not find is gone only when that visit looked at the cluster
// until its own stop held: not when the automatic stop's budget, no reachable view or a view
// cap cut it short (season 1's second visit reached two of its clusters for two views).
TEST(SeasonAnalysis, AVisitCutShortDoesNotMakeFruitletsGone) {
  const auto visit = [](double day, const std::string& rule, const std::string& reason,
                        const std::string& fruitlets) {
    return parseSeasonVisit(
        R"({"stop": {"rule": ")" + rule +
            R"("}, "clusters": [{"tag_id": 1, "T_world_tag": {}, "stop_reason": )" + reason +
            R"(, "sized_fruitlets": [)" + fruitlets + "]}]}",
        "day" + std::to_string(int(day)), day);
  };
  const std::string a0 = R"({"center_tag_m": [0, 0, 0.05], "size_mm": 7})";
  const std::string b0 = R"({"center_tag_m": [-0.02, 0, 0.05], "size_mm": 6})";
  const std::string a4 = R"({"center_tag_m": [0, 0, 0.05], "size_mm": 9})";
  const SeasonVisit first = visit(0, "auto", R"("cluster_done")", a0 + "," + b0);
  EXPECT_TRUE(first.clusters[0].searched);
  const auto goneOf = [&](const SeasonVisit& later) {
    const SeasonAnalysis s = analyzeSeason({first, later});
    int gone = 0;
    for (const FruitletTrack& t : s.tracks) gone += t.gone;
    return gone;
  };
  EXPECT_EQ(goneOf(visit(4, "auto", R"("cluster_done")", a4)), 1);
  EXPECT_EQ(goneOf(visit(4, "budget", R"("budget")", a4)), 1);  // the paper's whole budget
  EXPECT_EQ(goneOf(visit(4, "auto", R"(null)", a4)), 1);        // not said: as before
  for (const std::string reason : {R"("budget")", R"("no_reachable_view")", R"("max_views")"}) {
    const SeasonVisit cut = visit(4, "auto", reason, a4);
    EXPECT_FALSE(cut.clusters[0].searched) << reason;
    EXPECT_EQ(goneOf(cut), 0) << reason;
  }
  // Cut short after a search that did not find it: still gone.
  const SeasonAnalysis s = analyzeSeason(
      {first, visit(4, "auto", R"("cluster_done")", a4), visit(7, "auto", R"("budget")", "")});
  int gone = 0;
  for (const FruitletTrack& t : s.tracks) gone += t.gone;
  EXPECT_EQ(gone, 1);
  // A fruitlet first found on the second visit is not made unconfirmed by a third cut short.
  const std::string b4 = R"({"center_tag_m": [0.02, 0, 0.05], "size_mm": 7})";
  const SeasonAnalysis later = analyzeSeason({visit(0, "auto", R"("cluster_done")", a0),
                                              visit(4, "auto", R"("cluster_done")", a4 + "," + b4),
                                              visit(7, "auto", R"("budget")", a4)});
  int unconfirmed = 0;
  for (const FruitletTrack& t : later.tracks) unconfirmed += t.unconfirmed;
  EXPECT_EQ(unconfirmed, 0);
  EXPECT_NE(errorOf(R"({"stop": "budget", "T_world_tag": {}, "sized_fruitlets": []})").find("stop"),
            std::string::npos);
  EXPECT_NE(
      errorOf(
          R"({"clusters": [{"tag_id": 1, "T_world_tag": {}, "stop_reason": 3, "sized_fruitlets": []}]})")
          .find("clusters[0].stop_reason"),
      std::string::npos);
  EXPECT_NE(errorOf(R"({"stop": {"rule": 1}, "T_world_tag": {}, "sized_fruitlets": []})")
                .find("stop.rule"),
            std::string::npos);
}

TEST(SeasonAnalysis, OneSightingBetweenTheFirstAndLastVisitIsUnconfirmedNotGone) {
  // Fruitlet A on every visit; B only on day 4 (a false blob, most likely: no fruitlet appears
  // after bloom); C only on day 0 (fell off, or hidden since: gone).
  const auto visit = [](double day, const std::string& fruitlets) {
    return parseSeasonVisit(R"({"T_world_tag": {}, "sized_fruitlets": [)" + fruitlets + "]}",
                            "day" + std::to_string(int(day)), day);
  };
  const std::string a0 = R"({"center_tag_m": [0, 0, 0.05], "size_mm": 7})";
  const std::string c0 = R"({"center_tag_m": [-0.02, 0, 0.05], "size_mm": 6})";
  const SeasonAnalysis s = analyzeSeason(
      {visit(0, a0 + "," + c0),
       visit(
           4,
           R"({"center_tag_m": [0, 0, 0.05], "size_mm": 9}, {"center_tag_m": [0.02, 0, 0.05], "size_mm": 7})"),
       visit(7, R"({"center_tag_m": [0, 0, 0.05], "size_mm": 11})")});
  ASSERT_EQ(s.tracks.size(), 3u);
  int unconfirmed = 0, gone = 0;
  for (const FruitletTrack& t : s.tracks) {
    unconfirmed += t.unconfirmed;
    gone += t.gone;
    if (t.unconfirmed) {
      EXPECT_EQ(t.sizes.front().day, 4.0);
    }
    if (t.gone) {
      EXPECT_EQ(t.sizes.front().day, 0.0);
    }
  }
  EXPECT_EQ(unconfirmed, 1);
  EXPECT_EQ(gone, 1);
  EXPECT_EQ(s.fruit_set.unconfirmed, 1u);
  EXPECT_EQ(s.fruit_set.gone, 1u);
  EXPECT_EQ(s.fruit_set.persisting, 1u);
  // A stays, C dropped; B not counted. A's rate rests on three sizes with no standard error
  // (residuals, one degree of freedom), so it stays with Student's t probability, not 1.
  const auto a = std::find_if(s.tracks.begin(), s.tracks.end(),
                              [](const FruitletTrack& t) { return !t.gone && !t.unconfirmed; });
  ASSERT_NE(a, s.tracks.end());
  ASSERT_EQ(a->rate.degrees_of_freedom, 1.0);
  const double a_stays = rateErrorCdf(
      (a->rate.mm_per_day - s.threshold_mm_per_day) / a->rate.standard_error_mm_per_day, 1.0);
  EXPECT_GT(a_stays, 0.9);
  EXPECT_LT(a_stays, 0.99);
  EXPECT_NEAR(s.fruit_set.percent, 100.0 * a_stays / 2.0, 1e-9);
  int residual_rates = 0;
  const nlohmann::json j = seasonJson(s, {});
  for (const auto& f : j["clusters"][0]["fruitlets"])
    residual_rates += f["growth_rate_degrees_of_freedom"] == 1.0;
  EXPECT_EQ(residual_rates, 1);
}

}  // namespace
}  // namespace fvp::host::season
