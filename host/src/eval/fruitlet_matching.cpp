#include "fvp/host/eval/fruitlet_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fvp/host/core/one_to_one_assignment.h"

namespace fvp::host::eval {

std::vector<int> matchFruitlets(const std::vector<Eigen::Vector3d>& detections_m,
                                const std::vector<Eigen::Vector3d>& ground_truth_m, double gate_m) {
  // Detections are the rows, ground truth the columns (exact up to 16 of them).
  const std::vector<int> truth_of_detection =
      assignOneToOne(detections_m.size(), ground_truth_m.size(), [&](std::size_t d, std::size_t g) {
        const double e = (detections_m[d] - ground_truth_m[g]).norm();
        return e < gate_m ? e : std::numeric_limits<double>::infinity();
      });
  std::vector<int> detection_of_gt(ground_truth_m.size(), -1);
  for (std::size_t d = 0; d < truth_of_detection.size(); ++d)
    if (truth_of_detection[d] >= 0) detection_of_gt[std::size_t(truth_of_detection[d])] = int(d);
  return detection_of_gt;
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
