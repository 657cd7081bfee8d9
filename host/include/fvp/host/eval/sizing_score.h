// A sizing result scored against ground truth, as result.json and fruitlets.json hold it:
// every ground-truth fruitlet with its match, the detections, the metrics (docs/design.md
// section 9), for the chosen estimator and for the other one on the same measurements.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fvp/host/eval/fruitlet_matching.h"
#include "fvp/host/eval/ground_truth.h"
#include "fvp/host/sizing/fruitlet_sizer.h"

namespace fvp::host::eval {

/// {"fruitlets": [{"gt_center_m", "gt_size_mm", "matched", "est_center_m", "est_size_mm",
/// "center_error_mm"}], "detections", "metrics": {"match_percent", "mae_mm", "mape_percent",
/// "precision_percent"}} for one estimator's centres and sizes.
nlohmann::json scoreSizing(const sizing::SizingResult& sizing,
                           const std::vector<GroundTruthFruitlet>& truth,
                           sizing::SizingEstimator estimator);

/// {"match_percent", "mae_mm", "mape_percent", "precision_percent"} (null where undefined).
nlohmann::json metricsJson(const SizeMetrics& metrics);

/// The metrics of scored fruitlets pooled from several scorings (the clusters of a tree):
/// scoreSizing's "fruitlets" entries, concatenated, and the detections of all of them.
nlohmann::json pooledMetricsJson(const nlohmann::json& fruitlets, std::size_t detections);

/// The scored default estimator plus "fruitlets_<other>_sizing", "metrics_<other>_sizing",
/// "sizing_estimator" (truth may be empty: then only detections).
nlohmann::json scoreBothEstimators(const sizing::SizingResult& sizing,
                                   const std::vector<GroundTruthFruitlet>& truth,
                                   sizing::SizingEstimator estimator);

/// Every detection with both estimators' sizes and every per-image measurement, and the
/// chain's counts and expected events: "sized_fruitlets" and "sizing_stats".
nlohmann::json sizingDetails(const sizing::SizingResult& sizing);

}  // namespace fvp::host::eval
