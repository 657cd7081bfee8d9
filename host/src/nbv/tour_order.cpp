#include "fvp/host/nbv/tour_order.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace fvp::host::nbv {
namespace {

void checkCost(const Eigen::MatrixXd& cost) {
  if (cost.rows() != cost.cols() || cost.rows() < 1)
    throw std::invalid_argument("tour order: expected a square cost matrix with the start node");
  if (!cost.allFinite() || (cost.array() < 0.0).any())
    throw std::invalid_argument("tour order: expected finite costs >= 0");
}

/// Held-Karp over the stops 1..n: best[subset][last] is the least cost of a path from node 0
/// through exactly `subset` (bit s-1 for stop s) ending at `last`.
std::vector<std::size_t> exactTour(const Eigen::MatrixXd& cost) {
  const std::size_t n = std::size_t(cost.rows()) - 1;
  const std::size_t subsets = std::size_t(1) << n;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> best(subsets * n, kInf);
  std::vector<std::uint8_t> previous(subsets * n, 0);
  const auto at = [n](std::size_t subset, std::size_t last) { return subset * n + last; };
  for (std::size_t s = 0; s < n; ++s)
    best[at(std::size_t(1) << s, s)] = cost(0, Eigen::Index(s + 1));
  for (std::size_t subset = 1; subset < subsets; ++subset)
    for (std::size_t last = 0; last < n; ++last) {
      const double here = best[at(subset, last)];
      if (!((subset >> last) & 1) || here == kInf) continue;
      for (std::size_t next = 0; next < n; ++next) {
        if ((subset >> next) & 1) continue;
        const std::size_t grown = subset | (std::size_t(1) << next);
        const double via = here + cost(Eigen::Index(last + 1), Eigen::Index(next + 1));
        if (via < best[at(grown, next)]) {
          best[at(grown, next)] = via;
          previous[at(grown, next)] = std::uint8_t(last);
        }
      }
    }
  std::size_t subset = subsets - 1, last = 0;
  for (std::size_t s = 1; s < n; ++s)
    if (best[at(subset, s)] < best[at(subset, last)]) last = s;
  std::vector<std::size_t> order;
  while (subset != 0) {
    order.push_back(last + 1);
    const std::size_t before = previous[at(subset, last)];
    subset &= ~(std::size_t(1) << last);
    last = before;
  }
  std::reverse(order.begin(), order.end());
  return order;
}

/// Reverses stretches of the order while that shortens the path (costs may be asymmetric,
/// so each candidate is priced whole).
void improveByTwoOpt(const Eigen::MatrixXd& cost, std::vector<std::size_t>& order) {
  double best = openTourCost(cost, order);
  for (bool improved = true; improved;) {
    improved = false;
    for (std::size_t i = 0; i + 1 < order.size(); ++i)
      for (std::size_t j = i + 1; j < order.size(); ++j) {
        std::reverse(order.begin() + std::ptrdiff_t(i), order.begin() + std::ptrdiff_t(j) + 1);
        const double c = openTourCost(cost, order);
        if (c < best - 1e-12) {
          best = c;
          improved = true;
        } else {
          std::reverse(order.begin() + std::ptrdiff_t(i), order.begin() + std::ptrdiff_t(j) + 1);
        }
      }
  }
}

}  // namespace

double openTourCost(const Eigen::MatrixXd& cost, const std::vector<std::size_t>& order) {
  double total = 0.0;
  std::size_t here = 0;
  for (const std::size_t stop : order) {
    total += cost(Eigen::Index(here), Eigen::Index(stop));
    here = stop;
  }
  return total;
}

std::vector<std::size_t> nearestNextTour(const Eigen::MatrixXd& cost) {
  checkCost(cost);
  const std::size_t n = std::size_t(cost.rows()) - 1;
  std::vector<bool> visited(n + 1, false);
  std::vector<std::size_t> order;
  std::size_t here = 0;
  for (std::size_t step = 0; step < n; ++step) {
    std::size_t next = 0;
    for (std::size_t s = 1; s <= n; ++s)
      if (!visited[s] && (next == 0 || cost(Eigen::Index(here), Eigen::Index(s)) <
                                           cost(Eigen::Index(here), Eigen::Index(next))))
        next = s;
    visited[next] = true;
    order.push_back(next);
    here = next;
  }
  return order;
}

std::vector<std::size_t> shortestOpenTour(const Eigen::MatrixXd& cost) {
  checkCost(cost);
  const std::size_t n = std::size_t(cost.rows()) - 1;
  if (n == 0) return {};
  if (n <= kExactTourMaxStops) return exactTour(cost);
  std::vector<std::size_t> order = nearestNextTour(cost);
  improveByTwoOpt(cost, order);
  return order;
}

}  // namespace fvp::host::nbv
