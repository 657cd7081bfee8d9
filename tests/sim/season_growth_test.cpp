// Worlds that grow (docs/simulation.md "A season"): the day-0 world is the one generate always
// gave, fruitlets grow by their curves, abscising ones fall off, neighbours press but do not
// pass through each other, leaves keep off the fruitlets, tags and start views stay.
#include "fvp/robot/sim/season_growth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "fvp/host/core/segment_distance.h"
#include "fvp/robot/sim/world.h"

namespace fvp::robot::sim {
namespace {

constexpr int kSeeds = 12;

// A four-cluster tree whose fruitlets start near 6 mm, as a thinning season's do.
WorldConfig seasonTree(double day) {
  WorldConfig c;
  c.cluster_count = 4;
  c.min_radius_m = 0.003;
  c.max_radius_m = 0.005;
  c.season_day = day;
  return c;
}

TEST(SeasonGrowth, DayZeroIsTheWorldGenerateAlwaysGave) {
  WorldConfig seasonal = seasonTree(0.0);
  seasonal.abscission_probability = 0.9;
  seasonal.min_fastest_growth_mm_per_day = 0.1;
  WorldConfig plain = seasonTree(0.0);
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const World a = World::generate(seasonal, seed), b = World::generate(plain, seed);
    ASSERT_EQ(a.fruitlets().size(), b.fruitlets().size());
    for (std::size_t i = 0; i < a.fruitlets().size(); ++i) {
      EXPECT_EQ(a.fruitlets()[i].center_m, b.fruitlets()[i].center_m);
      EXPECT_EQ(a.fruitlets()[i].radius_m, b.fruitlets()[i].radius_m);
      EXPECT_EQ(a.fruitlets()[i].identity, static_cast<int>(i));
    }
    ASSERT_EQ(a.leaves().size(), b.leaves().size());
    for (std::size_t l = 0; l < a.leaves().size(); ++l)
      EXPECT_TRUE(a.leaves()[l].T_world_leaf.isApprox(b.leaves()[l].T_world_leaf, 0.0));
  }
}

TEST(SeasonGrowth, CurvesFollowTheModel) {
  const WorldConfig config = seasonTree(0.0);
  int non_kings = 0, abscising = 0;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const World world = World::generate(config, seed);
    const SeasonGrowth& season = world.seasonGrowth();
    EXPECT_GE(season.fastest_mm_per_day, config.min_fastest_growth_mm_per_day);
    EXPECT_LE(season.fastest_mm_per_day, config.max_fastest_growth_mm_per_day);
    ASSERT_EQ(season.fruitlets.size(), world.fruitlets().size());
    std::map<int, int> kings;
    for (const GrowthCurve& c : season.fruitlets) {
      const double share = c.rate_mm_per_day / season.fastest_mm_per_day;
      if (c.king) {
        ++kings[c.cluster];
        EXPECT_FALSE(c.abscises);
        EXPECT_GE(share, kMinKingShare);
        for (int i : world.clusters()[c.cluster].fruitlet_indices)  // the largest on day 0
          EXPECT_LE(world.fruitlets()[i].radius_m, world.fruitlets()[c.identity].radius_m);
      } else {
        ++non_kings;
        abscising += c.abscises;
      }
      if (c.abscises) {
        EXPECT_LE(share, kMaxAbscisingShare);
        EXPECT_GE(c.stops_growing_day, kMinStopsGrowingDay);
        EXPECT_LE(c.stops_growing_day, kMaxStopsGrowingDay);
        EXPECT_GE(c.falls_off_day, c.stops_growing_day);
        EXPECT_LE(c.falls_off_day, kMaxFallsOffDay);
        EXPECT_EQ(c.grownMm(20.0), c.grownMm(c.stops_growing_day));  // growth stops
      } else {
        EXPECT_GE(share, kMinPersistingShare);
        EXPECT_LE(share, 1.0);
        EXPECT_TRUE(c.onTree(60.0));
      }
    }
    EXPECT_EQ(kings.size(), world.clusters().size());
    for (const auto& [cluster, count] : kings) EXPECT_EQ(count, 1) << "cluster " << cluster;
  }
  // The share bound to drop is the config's (binomial: about 190 draws, 4 sigma).
  const double share = double(abscising) / non_kings;
  EXPECT_NEAR(share, config.abscission_probability, 4.0 * std::sqrt(0.6 * 0.4 / non_kings));
}

TEST(SeasonGrowth, ALaterDayIsTheSameTreeGrown) {
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const World day0 = World::generate(seasonTree(0.0), seed);
    const World day7 = World::generate(seasonTree(7.0), seed);
    const SeasonGrowth& season = day0.seasonGrowth();
    std::size_t on_tree = 0;
    for (const GrowthCurve& c : season.fruitlets) on_tree += c.onTree(7.0);
    ASSERT_EQ(day7.fruitlets().size(), on_tree) << "seed " << seed;
    for (std::size_t i = 0; i < day7.fruitlets().size(); ++i) {
      const Fruitlet& f = day7.fruitlets()[i];
      const Fruitlet& f0 = day0.fruitlets()[f.identity];
      const GrowthCurve& c = season.fruitlets[f.identity];
      EXPECT_EQ(f.index, static_cast<int>(i));
      EXPECT_NEAR(f.gtSizeMm(), f0.gtSizeMm() + c.grownMm(7.0), 1e-9);
      // Stems droop (a push off a plate or branch may move it a little more).
      EXPECT_NEAR(f.center_m.z(), f0.center_m.z() - kStemDroopMPerMm * c.grownMm(7.0), 0.002);
      // Within what the association allows a fruitlet to move between visits.
      EXPECT_LT((f.center_m - f0.center_m).norm(), 0.008) << "seed " << seed << " fruitlet " << i;
    }
    for (const FruitletCluster& c : day7.clusters()) {
      EXPECT_TRUE(c.tag.T_world_tag.isApprox(day0.clusters()[c.index].tag.T_world_tag, 0.0));
      EXPECT_TRUE(
          c.T_world_start_camera.isApprox(day0.clusters()[c.index].T_world_start_camera, 0.0));
      for (std::size_t a = 0; a < c.fruitlet_indices.size(); ++a) {
        const Fruitlet& fa = day7.fruitlets()[c.fruitlet_indices[a]];
        EXPECT_EQ(season.fruitlets[fa.identity].cluster, c.index);
        for (std::size_t b = a + 1; b < c.fruitlet_indices.size(); ++b) {
          const Fruitlet& fb = day7.fruitlets()[c.fruitlet_indices[b]];
          EXPECT_GE((fa.center_m - fb.center_m).norm() + kMaxPressM + 1e-6,
                    fa.boundingRadius_m() + fb.boundingRadius_m())
              << "seed " << seed << ": fruitlets pass through each other";
        }
      }
    }
    for (const Leaf& leaf : day7.leaves())
      for (const Fruitlet& f : day7.fruitlets())
        EXPECT_GE(leaf.distanceLowerBound_m(f.center_m),
                  f.boundingRadius_m() + day7.config().min_gap_m - 1e-12)
            << "seed " << seed << " leaf " << leaf.index;
  }
}

// Two weeks of the fastest growth the keys allow: every fruitlet clear of every tag plate and
// branch, and of every other fruitlet but for the press.
TEST(SeasonGrowth, GrownFruitletsKeepOffPlatesBranchesAndEachOther) {
  WorldConfig config = seasonTree(14.0);
  config.min_fastest_growth_mm_per_day = config.max_fastest_growth_mm_per_day = 1.5;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const World world = World::generate(config, seed);
    for (const Fruitlet& f : world.fruitlets()) {
      const double reach = f.boundingRadius_m() + config.min_gap_m - 1e-9;
      for (const FruitletCluster& c : world.clusters()) {
        const Eigen::Vector3d q = c.tag.T_world_tag.inverse() * f.center_m;
        const double h = 0.5 * c.tag.plate_size_m;
        const Eigen::Vector3d off(std::max(std::abs(q.x()) - h, 0.0),
                                  std::max(std::abs(q.y()) - h, 0.0), q.z());
        EXPECT_GE(off.norm(), reach) << "seed " << seed << ": a fruitlet in tag " << c.tag.tag_id;
      }
      for (const BranchSegment& b : world.branches())
        EXPECT_GE(host::pointSegmentDistance(f.center_m, b.start_m, b.end_m), reach + b.radius_m)
            << "seed " << seed << ": a fruitlet in a branch";
      for (const Fruitlet& g : world.fruitlets()) {
        if (g.index > f.index) {
          EXPECT_GE((f.center_m - g.center_m).norm() + kMaxPressM + 1e-6,
                    f.boundingRadius_m() + g.boundingRadius_m())
              << "seed " << seed;
        }
      }
    }
  }
}

TEST(SeasonGrowth, TheGroundTruthCarriesTheSeason) {
  const World day4 = World::generate(seasonTree(4.0), 3);
  const nlohmann::json truth = nlohmann::json::parse(day4.groundTruthJson());
  ASSERT_TRUE(truth.contains("season"));
  EXPECT_EQ(truth["season"]["day"], 4.0);
  EXPECT_EQ(truth["season"]["fruitlets"].size(), day4.seasonGrowth().fruitlets.size());
  for (std::size_t i = 0; i < day4.fruitlets().size(); ++i)
    EXPECT_EQ(truth["fruitlets"][i]["identity"], day4.fruitlets()[i].identity);
  EXPECT_EQ(truth["config"]["season_day"], 4.0);
}

TEST(SeasonGrowth, EachVisitDrawsItsOwnErrors) {
  EXPECT_EQ(visitSeed(17, 0.0), 17u);
  EXPECT_NE(visitSeed(17, 4.0), 17u);
  EXPECT_NE(visitSeed(17, 4.0), visitSeed(17, 7.0));
  EXPECT_NE(visitSeed(17, 4.0), visitSeed(18, 4.0));
  EXPECT_EQ(visitSeed(17, 4.0), visitSeed(17, 4.0));
}

TEST(SeasonGrowth, TheSeasonKeysAreChecked) {
  WorldConfig c;
  c.max_fastest_growth_mm_per_day = 0.2;  // below the minimum's 0.4
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = WorldConfig{};
  c.season_day = -1.0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = WorldConfig{};
  c.abscission_probability = 1.5;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::robot::sim
