// The growth-rate model's fates and fruit set on constructed samples.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "fvp/host/season/fruitlet_fate.h"

namespace fvp::host::season {
namespace {

GrowthRate rateOf(double mm_per_day, double se = NAN) {
  GrowthRate r;
  r.mm_per_day = mm_per_day;
  r.standard_error_mm_per_day = se;
  r.sizes = 2;
  return r;
}

TEST(FruitletFate, HalfTheFastestFifthsRateDecidesByHand) {
  // Ten fruitlets: the fastest fifth (2) grow 1.1 and 1.0 mm/day, so the threshold is 0.525.
  std::vector<GrowthRate> rates;
  for (const double r : {1.0, 0.9, 0.95, 0.3, 0.2, 0.8, 1.1, 0.53, 0.52, 0.0})
    rates.push_back(rateOf(r));
  const FruitSetPrediction p = predictFruitSet(rates);
  EXPECT_NEAR(p.reference_mm_per_day, 1.05, 1e-12);
  EXPECT_NEAR(p.threshold_mm_per_day, 0.525, 1e-12);
  const std::vector<Fate> expected = {
      Fate::kPersists, Fate::kPersists, Fate::kPersists, Fate::kAbscises, Fate::kAbscises,
      Fate::kPersists, Fate::kPersists, Fate::kPersists, Fate::kAbscises, Fate::kAbscises};
  for (std::size_t i = 0; i < rates.size(); ++i)
    EXPECT_EQ(p.fates[i].fate, expected[i])
        << "fruitlet " << i << ": " << toString(p.fates[i].fate);
  EXPECT_EQ(p.persisting, 6u);
  EXPECT_EQ(p.abscising, 4u);
  EXPECT_NEAR(p.fruit_set_percent, 60.0, 1e-12);  // no standard errors: certain fates
  EXPECT_NEAR(p.fruit_set_standard_error_percent, 0.0, 1e-12);
}

TEST(FruitletFate, TheRatesUncertaintyMakesTheFateAProbability) {
  // Reference 1.0 (a single fastest fruitlet of 3 at share 0.2), threshold 0.5.
  const FruitSetPrediction p =
      predictFruitSet({rateOf(1.0, 0.1), rateOf(0.5, 0.2), rateOf(0.3, 0.1)});
  EXPECT_NEAR(p.threshold_mm_per_day, 0.5, 1e-12);
  EXPECT_NEAR(p.fates[1].persist_probability, 0.5, 1e-12);  // on the threshold
  EXPECT_EQ(p.fates[1].fate, Fate::kPersists);              // "50 % or more" persists
  EXPECT_NEAR(p.fates[2].persist_probability, 0.5 * std::erfc(2.0 / std::sqrt(2.0)), 1e-12);
  EXPECT_GT(p.fates[0].persist_probability, 0.999);
  const double expected = p.fates[0].persist_probability + 0.5 + p.fates[2].persist_probability;
  EXPECT_NEAR(p.fruit_set_percent, 100.0 * expected / 3.0, 1e-9);
  EXPECT_GT(p.fruit_set_standard_error_percent, 0.0);
}

TEST(FruitletFate, AResidualRatesFateFollowsStudentsT) {
  // Fruitlet 2 is 2 standard errors below the threshold 0.5, as above, but its standard error
  // comes from the residuals of three sizes (one degree of freedom): Cauchy, 1/2 - atan(2)/pi
  // = 0.148 to persist, not the normal's 0.023.
  GrowthRate residual = rateOf(0.3, 0.1);
  residual.degrees_of_freedom = 1.0;
  const FruitSetPrediction p = predictFruitSet({rateOf(1.0, 0.1), rateOf(0.5, 0.2), residual});
  EXPECT_EQ(p.fates[2].fate, Fate::kAbscises);
  EXPECT_NEAR(p.fates[2].persist_probability, 0.5 - std::atan(2.0) / M_PI, 1e-12);
}

TEST(FruitletFate, WithoutARateOrAGrowingSampleTheFateIsUnknown) {
  const FruitSetPrediction some = predictFruitSet({rateOf(0.8), rateOf(NAN)});
  EXPECT_EQ(some.fates[1].fate, Fate::kUnknown);
  EXPECT_TRUE(std::isnan(some.fates[1].persist_probability));
  EXPECT_EQ(some.unknown, 1u);
  EXPECT_NEAR(some.fruit_set_percent, 100.0, 1e-12);
  const FruitSetPrediction none = predictFruitSet({rateOf(0.0), rateOf(-0.1)});
  EXPECT_EQ(none.unknown, 2u);
  EXPECT_TRUE(std::isnan(none.fruit_set_percent));
  EXPECT_TRUE(std::isnan(predictFruitSet({}).fruit_set_percent));
  FateConfig bad;
  bad.abscission_ratio = 0.0;
  EXPECT_THROW(predictFruitSet({rateOf(1.0)}, bad), std::invalid_argument);
  bad = {};
  bad.fastest_share = 1.5;
  EXPECT_THROW(predictFruitSet({rateOf(1.0)}, bad), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::host::season
