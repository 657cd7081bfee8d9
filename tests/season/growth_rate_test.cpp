// Growth rates by hand, and their standard errors' coverage over many simulated fruitlets.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "fvp/host/season/growth_rate.h"

namespace fvp::host::season {
namespace {

TEST(GrowthRate, TwoSizesByHand) {
  const GrowthRate r = fitGrowthRate({{0.0, 6.0, 0.3}, {4.0, 9.2, 0.4}});
  EXPECT_NEAR(r.mm_per_day, 0.8, 1e-12);
  EXPECT_NEAR(r.standard_error_mm_per_day, std::sqrt(0.09 + 0.16) / 4.0, 1e-12);
  EXPECT_EQ(r.sizes, 2u);
  // Unknown errors: the slope, and no standard error from two points.
  const GrowthRate bare = fitGrowthRate({{0.0, 6.0}, {4.0, 9.2}});
  EXPECT_NEAR(bare.mm_per_day, 0.8, 1e-12);
  EXPECT_TRUE(std::isnan(bare.standard_error_mm_per_day));
}

TEST(GrowthRate, ThreeSizesUnweightedAndWeightedByHand) {
  // Days 0, 4, 7; sizes off a 1 mm/day line by +0.1, -0.2, +0.1.
  const GrowthRate r = fitGrowthRate({{0.0, 6.1}, {4.0, 9.8}, {7.0, 13.1}});
  const double d_mean = 11.0 / 3.0;
  const double s_dd = std::pow(0 - d_mean, 2) + std::pow(4 - d_mean, 2) + std::pow(7 - d_mean, 2);
  const double s_mean = (6.1 + 9.8 + 13.1) / 3.0;
  const double s_ds = (0 - d_mean) * (6.1 - s_mean) + (4 - d_mean) * (9.8 - s_mean) +
                      (7 - d_mean) * (13.1 - s_mean);
  EXPECT_NEAR(r.mm_per_day, s_ds / s_dd, 1e-12);
  double rss = 0.0;
  for (const auto& [d, s] : {std::pair{0.0, 6.1}, {4.0, 9.8}, {7.0, 13.1}})
    rss += std::pow(s - (s_mean + r.mm_per_day * (d - d_mean)), 2);
  EXPECT_NEAR(r.standard_error_mm_per_day, std::sqrt(rss / 1.0 / s_dd), 1e-12);
  // Equal known errors: the same slope, the error from them.
  const GrowthRate w = fitGrowthRate({{0.0, 6.1, 0.2}, {4.0, 9.8, 0.2}, {7.0, 13.1, 0.2}});
  EXPECT_NEAR(w.mm_per_day, r.mm_per_day, 1e-12);
  EXPECT_NEAR(w.standard_error_mm_per_day, 0.2 / std::sqrt(s_dd), 1e-12);
}

TEST(GrowthRate, NoSpanNoRateAndBadInputIsRefused) {
  EXPECT_TRUE(std::isnan(fitGrowthRate({}).mm_per_day));
  EXPECT_TRUE(std::isnan(fitGrowthRate({{3.0, 7.0, 0.2}}).mm_per_day));
  EXPECT_TRUE(std::isnan(fitGrowthRate({{3.0, 7.0}, {3.0, 7.4}}).mm_per_day));
  EXPECT_THROW(fitGrowthRate({{0.0, NAN}, {1.0, 7.0}}), std::invalid_argument);
  EXPECT_THROW(fitGrowthRate({{INFINITY, 6.0}, {1.0, 7.0}}), std::invalid_argument);
  EXPECT_THROW(fitGrowthRate({{0.0, 6.0, 0.0}, {1.0, 7.0, 0.2}}), std::invalid_argument);
  EXPECT_THROW(fitGrowthRate({{0.0, 6.0, -0.1}, {1.0, 7.0, 0.2}}), std::invalid_argument);
  // A standard error so small its weight would overflow.
  EXPECT_THROW(fitGrowthRate({{0.0, 6.0, 1e-200}, {1.0, 7.0, 0.2}}), std::invalid_argument);
}

// The stated standard error covers the true rate as often as it says: 95 % intervals over
// 4000 simulated fruitlets (visits on days 0, 4, 7; sizing errors 0.2-0.5 mm, known).
TEST(GrowthRate, TheStandardErrorCoversTheTruthAtItsStatedLevel) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> rate_of(0.0, 1.2), sigma_of(0.2, 0.5);
  std::normal_distribution<double> unit;
  int covered = 0, normal = 0;
  const int fruitlets = 4000;
  for (int i = 0; i < fruitlets; ++i) {
    const double rate = rate_of(rng);
    std::vector<SizeOnDay> sizes;
    for (const double day : {0.0, 4.0, 7.0}) {
      const double sigma = sigma_of(rng);
      sizes.push_back({day, 6.0 + rate * day + sigma * unit(rng), sigma});
    }
    const GrowthRate r = fitGrowthRate(sizes);
    normal += std::isinf(r.degrees_of_freedom);
    covered += std::abs(r.mm_per_day - rate) <=
               rateIntervalHalfWidth(0.95, r.degrees_of_freedom) * r.standard_error_mm_per_day;
  }
  EXPECT_EQ(normal, fruitlets);  // sizes with their own errors: the normal
  const double share = double(covered) / fruitlets;
  EXPECT_GT(share, 0.935);
  EXPECT_LT(share, 0.965);
}

// Without the sizes' own errors the residuals estimate the standard error: with three sizes
// from one degree of freedom, so (estimate - truth) / standard error follows Student's t with
// one degree, whose 95 % interval is 12.71 standard errors each side. Read as normal (1.96)
// the interval holds the truth for about 70 % of fruitlets.
TEST(GrowthRate, AResidualStandardErrorCoversTheTruthThroughStudentsT) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> rate_of(0.0, 1.2);
  std::normal_distribution<double> unit;
  const int fruitlets = 4000;
  int covered_t = 0, covered_normal = 0;
  for (int i = 0; i < fruitlets; ++i) {
    const double rate = rate_of(rng);
    std::vector<SizeOnDay> sizes;
    for (const double day : {0.0, 4.0, 7.0})
      sizes.push_back({day, 6.0 + rate * day + 0.35 * unit(rng)});  // errors not stated
    const GrowthRate r = fitGrowthRate(sizes);
    ASSERT_EQ(r.degrees_of_freedom, 1.0) << "fruitlet " << i;
    const double error = std::abs(r.mm_per_day - rate);
    covered_t +=
        error <= rateIntervalHalfWidth(0.95, r.degrees_of_freedom) * r.standard_error_mm_per_day;
    covered_normal += error <= 1.96 * r.standard_error_mm_per_day;
  }
  EXPECT_GT(double(covered_t) / fruitlets, 0.935);
  EXPECT_LT(double(covered_t) / fruitlets, 0.965);
  EXPECT_LT(double(covered_normal) / fruitlets, 0.8);
}

TEST(GrowthRate, TheRateErrorsDistributionByHand) {
  EXPECT_NEAR(rateIntervalHalfWidth(0.95, std::numeric_limits<double>::infinity()), 1.959964, 1e-6);
  EXPECT_NEAR(rateIntervalHalfWidth(0.95, 1.0), 12.706205, 1e-5);
  EXPECT_NEAR(rateIntervalHalfWidth(0.95, 2.0), 4.302653, 1e-5);
  EXPECT_NEAR(rateErrorCdf(0.0, 1.0), 0.5, 1e-12);
  EXPECT_NEAR(rateErrorCdf(1.0, 1.0), 0.75, 1e-12);  // Cauchy: 1/2 + atan(1)/pi
  EXPECT_NEAR(rateErrorCdf(1.959964, std::numeric_limits<double>::infinity()), 0.975, 1e-6);
  EXPECT_THROW(rateErrorCdf(0.0, 0.0), std::invalid_argument);
  EXPECT_THROW(rateErrorCdf(0.0, std::nan("")), std::invalid_argument);
  EXPECT_THROW(rateIntervalHalfWidth(1.0, 3.0), std::invalid_argument);
  EXPECT_THROW(rateIntervalHalfWidth(0.95, -1.0), std::invalid_argument);
  EXPECT_THROW(rateErrorCdf(NAN, 1.0), std::invalid_argument);
  EXPECT_EQ(rateErrorCdf(INFINITY, 1.0), 1.0);
  EXPECT_EQ(rateErrorCdf(-INFINITY, std::numeric_limits<double>::infinity()), 0.0);
  // A level whose upper quantile 0.5 + level / 2 would round to 1.
  EXPECT_GT(
      rateIntervalHalfWidth(std::nextafter(1.0, 0.0), std::numeric_limits<double>::infinity()),
      8.0);
}

}  // namespace
}  // namespace fvp::host::season
