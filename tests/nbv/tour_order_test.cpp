// The tour's cluster order on constructed layouts: every stop once, never longer than nearest
// next, optimal where it can be checked by trying every order, and bad matrices refused.
#include "fvp/host/nbv/tour_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <stdexcept>

namespace fvp::host::nbv {
namespace {

/// Costs between points on a line (node 0 first): |x_a - x_b|.
Eigen::MatrixXd onALine(const std::vector<double>& x) {
  const auto n = Eigen::Index(x.size());
  Eigen::MatrixXd cost(n, n);
  for (Eigen::Index a = 0; a < n; ++a)
    for (Eigen::Index b = 0; b < n; ++b)
      cost(a, b) = std::abs(x[std::size_t(a)] - x[std::size_t(b)]);
  return cost;
}

/// Asymmetric random costs (an arm's times differ by direction), seeded.
Eigen::MatrixXd randomCosts(std::size_t stops, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.5, 10.0);
  const auto n = Eigen::Index(stops + 1);
  Eigen::MatrixXd cost(n, n);
  for (Eigen::Index a = 0; a < n; ++a)
    for (Eigen::Index b = 0; b < n; ++b) cost(a, b) = a == b ? 0.0 : u(rng);
  return cost;
}

double bruteForceBest(const Eigen::MatrixXd& cost) {
  std::vector<std::size_t> order(std::size_t(cost.rows()) - 1);
  std::iota(order.begin(), order.end(), 1);
  double best = openTourCost(cost, order);
  while (std::next_permutation(order.begin(), order.end()))
    best = std::min(best, openTourCost(cost, order));
  return best;
}

void expectEveryStopOnce(const std::vector<std::size_t>& order, std::size_t stops) {
  std::vector<std::size_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::size_t> expected(stops);
  std::iota(expected.begin(), expected.end(), 1);
  EXPECT_EQ(sorted, expected);
}

TEST(TourOrder, BeatsNearestNextWhereGreedIsShortSighted) {
  // From 0 the nearest is 1, then -2, then 4: 1 + 3 + 6 = 10. Going to -2 first: 2 + 3 + 3 = 8.
  const Eigen::MatrixXd cost = onALine({0.0, 1.0, -2.0, 4.0});
  EXPECT_EQ(nearestNextTour(cost), (std::vector<std::size_t>{1, 2, 3}));
  const std::vector<std::size_t> order = shortestOpenTour(cost);
  EXPECT_EQ(order, (std::vector<std::size_t>{2, 1, 3}));
  EXPECT_DOUBLE_EQ(openTourCost(cost, order), 8.0);
}

TEST(TourOrder, OptimalAgainstBruteForceAndNeverLongerThanNearestNext) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const std::size_t stops = 1 + seed % 8;  // 1..8: brute force is 40320 orders at most
    const Eigen::MatrixXd cost = randomCosts(stops, seed);
    const std::vector<std::size_t> order = shortestOpenTour(cost);
    expectEveryStopOnce(order, stops);
    EXPECT_NEAR(openTourCost(cost, order), bruteForceBest(cost), 1e-9) << "seed " << seed;
  }
  for (const std::size_t stops : {kExactTourMaxStops, kExactTourMaxStops + 1, std::size_t(40)}) {
    const Eigen::MatrixXd cost = randomCosts(stops, unsigned(stops));
    const std::vector<std::size_t> order = shortestOpenTour(cost);
    expectEveryStopOnce(order, stops);
    EXPECT_LE(openTourCost(cost, order), openTourCost(cost, nearestNextTour(cost)) + 1e-9)
        << stops << " stops";
  }
}

TEST(TourOrder, BeyondTheExactLimitTwoOptMendsAGreedyTour) {
  // 14 stops on a line: six near on the right and one far, seven on the left. Nearest next
  // runs right to 6, back across to -7.5, then out to 20 (47); left first is 35.
  std::vector<double> x = {0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 20.0};
  for (double l = -1.5; l >= -7.5; l -= 1.0) x.push_back(l);
  const Eigen::MatrixXd cost = onALine(x);
  ASSERT_GT(std::size_t(cost.rows()) - 1, kExactTourMaxStops);
  EXPECT_DOUBLE_EQ(openTourCost(cost, nearestNextTour(cost)), 47.0);
  const std::vector<std::size_t> order = shortestOpenTour(cost);
  expectEveryStopOnce(order, x.size() - 1);
  EXPECT_LT(openTourCost(cost, order), 47.0 - 1e-9);
}

TEST(TourOrder, NoStopsNoOrderAndBadCostsRefused) {
  EXPECT_TRUE(shortestOpenTour(Eigen::MatrixXd::Zero(1, 1)).empty());
  EXPECT_THROW(shortestOpenTour(Eigen::MatrixXd::Zero(2, 3)), std::invalid_argument);
  Eigen::MatrixXd cost = onALine({0.0, 1.0, 2.0});
  cost(1, 2) = -1.0;
  EXPECT_THROW(shortestOpenTour(cost), std::invalid_argument);
  cost(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(nearestNextTour(cost), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::host::nbv
