// The gated one-to-one assignment against brute force over every assignment.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "fvp/host/core/one_to_one_assignment.h"

namespace fvp::host {
namespace {

struct Score {
  int pairs = 0;
  double cost = 0.0;
};

// Every assignment of rows to distinct columns or none: the most pairs, then the least cost.
Score bruteForce(std::size_t rows, std::size_t columns,
                 const std::function<double(std::size_t, std::size_t)>& cost) {
  Score best;
  std::vector<char> used(columns, 0);
  std::function<void(std::size_t, Score)> visit = [&](std::size_t r, Score s) {
    if (r == rows) {
      if (s.pairs > best.pairs || (s.pairs == best.pairs && s.cost < best.cost)) best = s;
      return;
    }
    visit(r + 1, s);
    for (std::size_t c = 0; c < columns; ++c) {
      const double e = cost(r, c);
      if (used[c] || !std::isfinite(e)) continue;
      used[c] = 1;
      visit(r + 1, {s.pairs + 1, s.cost + e});
      used[c] = 0;
    }
  };
  visit(0, {});
  return best;
}

TEST(OneToOneAssignment, MatchesBruteForceOnRandomGatedCosts) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t rows = trial % 7, columns = (trial / 7) % 7;
    std::vector<std::vector<double>> table(rows, std::vector<double>(columns));
    for (auto& row : table)
      for (double& e : row)
        e = unit(rng) < 0.4 ? std::numeric_limits<double>::infinity() : unit(rng);
    const auto cost = [&](std::size_t r, std::size_t c) { return table[r][c]; };
    const std::vector<int> column_of_row = assignOneToOne(rows, columns, cost);
    ASSERT_EQ(column_of_row.size(), rows);
    Score got;
    std::vector<char> used(columns, 0);
    for (std::size_t r = 0; r < rows; ++r) {
      const int c = column_of_row[r];
      if (c < 0) continue;
      ASSERT_LT(std::size_t(c), columns);
      ASSERT_FALSE(used[std::size_t(c)]) << "column " << c << " twice, trial " << trial;
      ASSERT_TRUE(std::isfinite(table[r][std::size_t(c)])) << "a gated pair, trial " << trial;
      used[std::size_t(c)] = 1;
      got.pairs += 1, got.cost += table[r][std::size_t(c)];
    }
    const Score best = bruteForce(rows, columns, cost);
    EXPECT_EQ(got.pairs, best.pairs) << "trial " << trial;
    EXPECT_NEAR(got.cost, best.cost, 1e-12) << "trial " << trial;
  }
}

TEST(OneToOneAssignment, MorePairsBeatLessCostAndBeyondSixteenColumnsIsGreedy) {
  // Row 0 alone would take column 0 (cost 0.1); pairing both rows needs it to take column 1.
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<std::vector<double>> table = {{0.1, 0.9}, {0.2, inf}};
  const auto cost = [&](std::size_t r, std::size_t c) { return table[r][c]; };
  EXPECT_EQ(assignOneToOne(2, 2, cost), (std::vector<int>{1, 0}));
  // Beyond the exact limit: closest first, so row 0 keeps column 0 and row 1 goes unpaired.
  const auto wide = [&](std::size_t r, std::size_t c) { return c < 2 ? table[r][c] : inf; };
  EXPECT_EQ(assignOneToOne(2, kExactAssignmentMaxColumns + 1, wide), (std::vector<int>{0, -1}));
  // Too many rows for the exact search's memory: greedy, still one to one.
  const auto many = [](std::size_t r, std::size_t c) { return double((r * 7 + c * 3) % 11); };
  const std::vector<int> big = assignOneToOne(100, kExactAssignmentMaxColumns, many);
  std::vector<int> seen(kExactAssignmentMaxColumns, 0);
  for (const int c : big) {
    if (c >= 0) {
      EXPECT_EQ(seen[std::size_t(c)]++, 0);
    }
  }
  EXPECT_EQ(std::count(big.begin(), big.end(), -1), 100 - int(kExactAssignmentMaxColumns));
  EXPECT_TRUE(assignOneToOne(0, 3, cost).empty());
  EXPECT_EQ(assignOneToOne(2, 0, cost), (std::vector<int>{-1, -1}));
}

}  // namespace
}  // namespace fvp::host
