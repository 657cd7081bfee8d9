// The order of a tour's clusters: the open path from where the arm is through every cluster's
// start view that takes the least time (docs/nbv-loop.md, "A tree"). Exact for the trees a
// grower samples (up to kExactTourMaxStops clusters, Held-Karp dynamic programming), nearest
// next improved by 2-opt beyond; never longer than nearest next.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace fvp::host::nbv {

/// Held-Karp keeps a cost per (subset, last stop): 2^n n entries, 12 stops 49k, well under a
/// millisecond; beyond that 2-opt from nearest next.
inline constexpr std::size_t kExactTourMaxStops = 12;

/// cost(i, j): the cost from node i to node j (seconds, or metres, any one unit; need not be
/// symmetric). Node 0 is where the path starts; the stops are 1..n. Returns the stops in
/// visit order, each once. Throws std::invalid_argument for a matrix that is not square or
/// holds a negative or non-finite cost.
std::vector<std::size_t> shortestOpenTour(const Eigen::MatrixXd& cost);

/// The stop order nearest next takes: from node 0, always the cheapest stop not yet visited
/// (the first on a tie). The baseline shortestOpenTour never exceeds.
std::vector<std::size_t> nearestNextTour(const Eigen::MatrixXd& cost);

/// The cost of visiting the stops in this order from node 0.
double openTourCost(const Eigen::MatrixXd& cost, const std::vector<std::size_t>& order);

}  // namespace fvp::host::nbv
