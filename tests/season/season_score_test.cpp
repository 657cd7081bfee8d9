// A simulated season's score against the world's truth (trials/season_score.h), on visits whose
// results are made from the truth itself: a robot that sizes every fruitlet exactly scores
// perfectly, and each way of being wrong is counted where it happens.
#include "fvp/trials/season_score.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "fvp/host/season/season_visit.h"

namespace fvp::trials {
namespace {

using robot::sim::World;
using robot::sim::WorldConfig;

WorldConfig seasonTree(double day) {
  WorldConfig c;
  c.cluster_count = 4;
  c.min_radius_m = 0.003;
  c.max_radius_m = 0.005;
  c.season_day = day;
  return c;
}

nlohmann::json vec(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

/// A tree result whose every cluster sized each of its fruitlets at its true size plus
/// error_mm, in order; the truth entries name detection j for fruitlet j.
nlohmann::json exactResult(const World& world, double error_mm = 0.0) {
  nlohmann::json result = {{"clusters", nlohmann::json::array()}};
  for (const auto& c : world.clusters()) {
    nlohmann::json cluster = {{"tag_id", c.tag.tag_id},
                              {"sized_fruitlets", nlohmann::json::array()},
                              {"fruitlets", nlohmann::json::array()}};
    nlohmann::json T = nlohmann::json::array();
    for (int r = 0; r < 4; ++r) {
      nlohmann::json row = nlohmann::json::array();
      for (int k = 0; k < 4; ++k) row.push_back(c.tag.T_world_tag.matrix()(r, k));
      T.push_back(row);
    }
    cluster["T_world_tag"] = T;
    for (std::size_t j = 0; j < c.fruitlet_indices.size(); ++j) {
      const auto& f = world.fruitlets()[c.fruitlet_indices[j]];
      cluster["sized_fruitlets"].push_back(
          {{"center_tag_m", vec(c.tag.T_world_tag.inverse() * f.center_m)},
           {"size_mm", f.gtSizeMm() + error_mm},
           {"support", {{"size_stderr_mm", 0.05}}}});
      cluster["fruitlets"].push_back({{"gt_center_m", vec(f.center_m)},
                                      {"gt_size_mm", f.gtSizeMm()},
                                      {"matched", true},
                                      {"detection", j}});
    }
    result["clusters"].push_back(cluster);
  }
  return result;
}

struct Season {
  std::vector<World> worlds;
  std::vector<nlohmann::json> results;
  host::season::SeasonAnalysis analysis;

  Season(std::uint64_t seed, const std::vector<double>& days) {
    for (const double d : days) worlds.push_back(World::generate(seasonTree(d), seed));
    for (const World& w : worlds) results.push_back(exactResult(w));
  }
  nlohmann::json score(double caliper_sigma_mm = 0.01) {
    std::vector<host::season::SeasonVisit> visits;
    for (std::size_t v = 0; v < results.size(); ++v)
      visits.push_back(host::season::parseSeasonVisit(results[v].dump(), "visit",
                                                      worlds[v].config().season_day));
    analysis = host::season::analyzeSeason(visits);
    SeasonScoreInput in;
    in.analysis = &analysis;
    for (std::size_t v = 0; v < results.size(); ++v) {
      in.visit_results.push_back(&results[v]);
      in.visit_worlds.push_back(&worlds[v]);
    }
    in.caliper_sigma_mm = caliper_sigma_mm;
    return scoreSeason(in);
  }
};

TEST(SeasonScore, ExactSizesScorePerfectly) {
  std::size_t fallen = 0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    Season season(seed, {0.0, 4.0, 7.0});
    const nlohmann::json s = season.score();
    SCOPED_TRACE("seed " + std::to_string(seed) + ": " + s.dump());
    EXPECT_EQ(s["association"]["links_correct"], s["association"]["links_made"]);
    EXPECT_EQ(s["association"]["truth_links_found"], s["association"]["truth_links"]);
    EXPECT_GT(s["association"]["truth_links"].get<int>(), 0);
    EXPECT_EQ(s["gone"]["reported_gone"], s["gone"]["fallen_sized"]);
    EXPECT_EQ(s["gone"]["wrongly_gone"], 0);
    fallen += s["gone"]["fallen_sized"].get<std::size_t>();
    EXPECT_LT(s["growth"]["mae_mm_per_day"].get<double>(), 1e-9);
    EXPECT_EQ(s["fate"]["robot"]["f1_drops"], 1.0);
    EXPECT_EQ(s["fate"]["robot"]["undecided"], 0);
    EXPECT_EQ(s["fate"]["calipers"]["f1_drops"], 1.0);
    EXPECT_NEAR(s["fruit_set_percent"]["robot"].get<double>(),
                s["fruit_set_percent"]["truth"].get<double>(), 0.5);
  }
  EXPECT_GT(fallen, 0u) << "no fruitlet fell in these seasons: the gone score went untested";
}

TEST(SeasonScore, ABiasEveryVisitSharesIsNotErrorBetweenVisits) {
  const auto spread = [](const nlohmann::json& growth) {
    return std::sqrt(growth["size_deviation_ss_mm2"].get<double>() /
                     growth["size_deviation_dof"].get<double>());
  };
  Season season(2, {0.0, 4.0, 7.0});
  for (std::size_t v = 0; v < season.worlds.size(); ++v)
    season.results[v] = exactResult(season.worlds[v], 0.3);
  nlohmann::json s = season.score();
  ASSERT_GT(s["growth"]["size_deviation_dof"].get<int>(), 0);
  EXPECT_LT(spread(s["growth"]), 1e-9) << "0.3 mm on every visit cancels in every slope";
  EXPECT_NEAR(s["growth"]["stated_standard_error_ss_mm2"].get<double>() /
                  s["growth"]["size_deviation_dof"].get<double>(),
              0.05 * 0.05, 1e-12);
  // +0.3 mm on day 4 only: over three sizes the deviations are +0.2, -0.1, -0.1 (or +0.15,
  // -0.15 over two), never zero.
  season.results[1] = exactResult(season.worlds[1], 0.6);
  s = season.score();
  EXPECT_GT(spread(s["growth"]), 0.1);
  EXPECT_LT(spread(s["growth"]), 0.3);
}

/// Uniform in [0, 1) and standard normal (Box-Muller) from raw engine bits: the same draws
/// with any standard library.
double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}
double standardNormal(std::mt19937_64& rng) {
  const double u1 = uniform01(rng) + 0x1.0p-54;  // never 0
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * uniform01(rng));
}

/// Tracks of three sizes whose errors are a track's bias plus N(0, se^2 + floor^2), with
/// stated errors se of 0.05-0.4 mm.
std::vector<std::vector<SizeError>> simulatedTracks(double floor_mm, std::size_t count) {
  std::mt19937_64 rng(7);
  std::vector<std::vector<SizeError>> tracks(count);
  for (auto& track : tracks) {
    const double b = -1.0 + 2.0 * uniform01(rng);
    for (int k = 0; k < 3; ++k) {
      const double se = 0.05 + 0.35 * uniform01(rng);
      track.push_back({b + std::hypot(se, floor_mm) * standardNormal(rng), se});
    }
  }
  return tracks;
}

TEST(SeasonScore, TheFloorFitFindsWhatTheStatedErrorsLack) {
  for (const double floor_mm : {0.1, 0.2, 0.4}) {
    const double fit = sizeErrorFloorFit(simulatedTracks(floor_mm, 4000));
    EXPECT_NEAR(fit, floor_mm, 0.1 * floor_mm) << "floor " << floor_mm;
  }
  // Stated errors that are right: the spread is what they say, the floor (near) none (its
  // sampling spread over 4000 tracks is about 0.01 mm).
  EXPECT_LT(sizeErrorFloorFit(simulatedTracks(0.0, 4000)), 0.05);
  // A bias a track's sizes share cancels.
  auto tracks = simulatedTracks(0.2, 2000);
  const double before = sizeErrorFloorFit(tracks);
  for (auto& t : tracks)
    for (auto& e : t) e.error_mm += 5.0;
  EXPECT_NEAR(sizeErrorFloorFit(tracks), before, 1e-6);
}

TEST(SeasonScore, TheFloorFitNeedsTracksOfTwoSizes) {
  EXPECT_TRUE(std::isnan(sizeErrorFloorFit({})));
  EXPECT_TRUE(std::isnan(sizeErrorFloorFit({{{0.1, 0.1}}, {{0.3, 0.2}}})));
  EXPECT_EQ(sizeErrorFloorFit({{{0.0, 0.1}, {0.0, 0.1}}}), 0.0);
  EXPECT_THROW(sizeErrorFloorFit({{{0.0, 0.0}, {0.1, 0.1}}}), std::invalid_argument);
  EXPECT_THROW(sizeErrorFloorFit({{{NAN, 0.1}, {0.1, 0.1}}}), std::invalid_argument);
  EXPECT_THROW(sizeErrorFloorFit({{{0.0, 1e200}, {0.1, 0.1}}}), std::invalid_argument);
  EXPECT_THROW(sizeErrorFloorFit({{{1e300, 0.1}, {0.1, 0.1}}}), std::invalid_argument);
}

TEST(SeasonScore, EachSizeIsRecordedWithItsTruth) {
  Season season(2, {0.0, 4.0, 7.0});
  season.results[1] = exactResult(season.worlds[1], 0.3);
  const nlohmann::json s = season.score();
  const nlohmann::json& sizes = s["growth"]["sizes"];
  ASSERT_FALSE(sizes.empty());
  for (const nlohmann::json& r : sizes) {
    const double error = r["size_mm"].get<double>() - r["truth_mm"].get<double>();
    EXPECT_NEAR(error, r["day"] == 4.0 ? 0.3 : 0.0, 1e-9) << r.dump();
    EXPECT_EQ(r["standard_error_mm"], 0.05);
    EXPECT_EQ(r["well_seen_images"], -1) << "the results here do not say";
  }
  // Deviations of +-0.2/0.1 mm against a stated 0.05: the floor makes up the difference.
  EXPECT_GT(s["growth"]["size_error_floor_fit_mm"].get<double>(), 0.05);
}

TEST(SeasonScore, AWrongLinkIsCounted) {
  Season season(2, {0.0, 4.0, 7.0});
  // On day 4 the result's truth says cluster 0's first two detections are each other's
  // fruitlet: the tracks, made by position, now link each to the wrong one.
  auto& truth = season.results[1]["clusters"][0]["fruitlets"];
  ASSERT_GE(truth.size(), 2u);
  std::swap(truth[0]["gt_center_m"], truth[1]["gt_center_m"]);
  const nlohmann::json s = season.score();
  const int made = s["association"]["links_made"], correct = s["association"]["links_correct"];
  // Each swapped fruitlet's link into day 4 and out of it (where it is still on the tree).
  EXPECT_GE(made - correct, 2);
  EXPECT_LE(made - correct, 4);
  EXPECT_LT(s["association"]["truth_links_found"].get<int>(),
            s["association"]["truth_links"].get<int>());
}

TEST(SeasonScore, AFruitletMissedOnTheLastVisitIsWronglyGone) {
  Season season(3, {0.0, 7.0});
  // Day 7 misses cluster 1's first fruitlet (on the tree that day) altogether.
  const World& day7 = season.worlds[1];
  const int identity = day7.fruitlets()[day7.clusters()[1].fruitlet_indices[0]].identity;
  auto& c = season.results[1]["clusters"][1];
  c["sized_fruitlets"].erase(0);
  c["fruitlets"].erase(0);
  for (auto& f : c["fruitlets"]) f["detection"] = f["detection"].get<int>() - 1;
  const nlohmann::json s = season.score();
  // Its track ends on day 0, so it is reported gone though it hangs on: predicted to drop.
  EXPECT_EQ(s["gone"]["wrongly_gone"], 1);
  if (!day7.seasonGrowth().fruitlets[identity].abscises) {
    EXPECT_EQ(s["fate"]["robot"]["false_drops"], 1);
    EXPECT_LT(s["fate"]["robot"]["f1_drops"].get<double>(), 1.0);
  }
}

TEST(SeasonScore, ASpuriousDetectionsLinkIsCountedApart) {
  Season season(1, {0.0, 4.0});
  // A false blob on a leaf, sized on both days at one place in tag 0's frame, matched to no
  // fruitlet: the analysis links it, and the score keeps that link out of the association's.
  for (auto& result : season.results)
    result["clusters"][0]["sized_fruitlets"].push_back({{"center_tag_m", {0.0, 0.05, 0.01}},
                                                        {"size_mm", 7.0},
                                                        {"support", {{"size_stderr_mm", 0.05}}}});
  const nlohmann::json s = season.score();
  EXPECT_EQ(s["association"]["links_with_spurious"], 1);
  EXPECT_EQ(s["association"]["links_correct"], s["association"]["links_made"]);
  EXPECT_EQ(s["association"]["truth_links_found"], s["association"]["truth_links"]);
}

TEST(SeasonScore, AWorldOfAnotherDayIsRefused) {
  Season season(1, {0.0, 4.0});
  season.worlds[1] = World::generate(seasonTree(5.0), 1);
  EXPECT_THROW(season.score(), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::trials
