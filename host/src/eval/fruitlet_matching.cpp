#include "fvp/host/eval/fruitlet_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fvp::host::eval {

std::vector<int> matchFruitlets(const std::vector<Eigen::Vector3d>& detections_m,
                                const std::vector<Eigen::Vector3d>& ground_truth_m, double gate_m) {
  const std::size_t G = ground_truth_m.size(), D = detections_m.size();
  std::vector<int> match(G, -1);
  if (G == 0 || D == 0) return match;
  const auto dist = [&](std::size_t d, std::size_t g) {
    return (detections_m[d] - ground_truth_m[g]).norm();
  };
  if (G > 16) {  // greedy: closest pairs first
    std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
    for (std::size_t d = 0; d < D; ++d)
      for (std::size_t g = 0; g < G; ++g)
        if (dist(d, g) < gate_m) pairs.emplace_back(dist(d, g), d, g);
    std::sort(pairs.begin(), pairs.end());
    std::vector<char> used(D, 0);
    for (const auto& [e, d, g] : pairs)
      if (!used[d] && match[g] < 0) used[d] = 1, match[g] = int(d);
    return match;
  }
  // DP over detections with the set of ground-truth fruitlets taken: (matches, -distance).
  struct Cell {
    int matches = -1;
    double distance = 0.0;
  };
  const std::size_t S = std::size_t{1} << G;
  std::vector<std::vector<Cell>> dp(D + 1, std::vector<Cell>(S));
  std::vector<std::vector<int>> choice(D + 1, std::vector<int>(S, -1));
  dp[0][0] = {0, 0.0};
  const auto better = [](const Cell& a, const Cell& b) {
    return a.matches > b.matches || (a.matches == b.matches && a.distance < b.distance);
  };
  for (std::size_t d = 0; d < D; ++d)
    for (std::size_t s = 0; s < S; ++s) {
      if (dp[d][s].matches < 0) continue;
      if (better(dp[d][s], dp[d + 1][s]) || dp[d + 1][s].matches < 0) {
        dp[d + 1][s] = dp[d][s];
        choice[d + 1][s] = -1;
      }
      for (std::size_t g = 0; g < G; ++g) {
        if (s & (std::size_t{1} << g)) continue;
        const double e = dist(d, g);
        if (!(e < gate_m)) continue;
        const std::size_t t = s | (std::size_t{1} << g);
        const Cell c{dp[d][s].matches + 1, dp[d][s].distance + e};
        if (dp[d + 1][t].matches < 0 || better(c, dp[d + 1][t])) {
          dp[d + 1][t] = c;
          choice[d + 1][t] = int(g);
        }
      }
    }
  std::size_t best = 0;
  for (std::size_t s = 0; s < S; ++s)
    if (dp[D][s].matches >= 0 && better(dp[D][s], dp[D][best])) best = s;
  for (std::size_t d = D, s = best; d > 0; --d) {
    const int g = choice[d][s];
    if (g >= 0) {
      match[g] = int(d - 1);
      s &= ~(std::size_t{1} << g);
    }
  }
  return match;
}

SizeMetrics sizeMetrics(const std::vector<double>& gt_size_mm,
                        const std::vector<double>& est_size_mm,
                        const std::vector<int>& detection_of_gt, std::size_t detections) {
  if (gt_size_mm.size() != detection_of_gt.size())
    throw std::invalid_argument("sizeMetrics: one match entry per ground-truth fruitlet expected");
  SizeMetrics m;
  m.ground_truth = gt_size_mm.size();
  m.detections = detections;
  double abs_sum = 0.0, pct_sum = 0.0;
  for (std::size_t g = 0; g < gt_size_mm.size(); ++g) {
    const int d = detection_of_gt[g];
    if (d < 0) continue;
    if (std::size_t(d) >= est_size_mm.size())
      throw std::invalid_argument("sizeMetrics: match names a detection without a size");
    ++m.matched;
    const double e = std::abs(est_size_mm[d] - gt_size_mm[g]);
    abs_sum += e;
    pct_sum += 100.0 * e / gt_size_mm[g];
  }
  m.match_percent = m.ground_truth ? 100.0 * m.matched / m.ground_truth : 0.0;
  if (m.matched) {
    m.mae_mm = abs_sum / m.matched;
    m.mape_percent = pct_sum / m.matched;
  }
  if (detections) m.precision_percent = 100.0 * m.matched / detections;
  return m;
}

}  // namespace fvp::host::eval
