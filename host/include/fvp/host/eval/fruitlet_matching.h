// Scoring against ground truth (docs/design.md section 9): a one-to-one assignment of detected
// fruitlet centres to ground-truth centres closer than the gate (5 mm), maximising the number
// of matched pairs and, among those, minimising the summed distance; then Match Percent,
// MAE, MAPE and precision.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

namespace fvp::host::eval {

inline constexpr double kDefaultMatchGateM = 0.005;

/// detection_of_gt[g]: index of the detection matched to ground-truth fruitlet g, or -1.
/// Exact for up to 16 ground-truth fruitlets (a cluster holds 3-6) and 63 detections with
/// 16 of them (assignOneToOne's bounds); greedy by distance beyond that.
std::vector<int> matchFruitlets(const std::vector<Eigen::Vector3d>& detections_m,
                                const std::vector<Eigen::Vector3d>& ground_truth_m,
                                double gate_m = kDefaultMatchGateM);

struct SizeMetrics {
  std::size_t ground_truth = 0, detections = 0, matched = 0;
  double match_percent = 0.0;                  ///< matched / ground truth
  std::optional<double> mae_mm, mape_percent;  ///< over matched pairs; none without pairs
  std::optional<double> precision_percent;     ///< matched / detections; none without detections
};

/// Metrics of one matched set (pooled sums let callers combine trials: see accumulate).
SizeMetrics sizeMetrics(const std::vector<double>& gt_size_mm,
                        const std::vector<double>& est_size_mm,
                        const std::vector<int>& detection_of_gt, std::size_t detections);

}  // namespace fvp::host::eval
