// A sizing result scored against ground truth, as result.json and fruitlets.json hold it:
// every ground-truth fruitlet with its match, the detections, the metrics (docs/design.md
// section 9), for the chosen estimator and for the other one on the same measurements.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <optional>
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

/// Adds to sizingDetails' output the cluster tag's pose, "T_world_tag": {"translation_m",
/// "quaternion_wxyz"}, and each sized fruitlet's centre in the tag's frame, "center_tag_m":
/// the frame in which a later visit finds the same fruitlets (docs/season.md). Nothing is
/// added without a tag pose. The tag was seen in the registered maps' frame (the anchor
/// view's), so the centres are taken back into it first by the anchor shift the sizing
/// applied (MappingSession::appliedAnchorShift_m): tag and fruitlets then share the anchor
/// view's pose error, which cancels in the tag's frame.
void addTagFrame(nlohmann::json& details, const std::optional<Eigen::Isometry3d>& T_world_tag,
                 const Eigen::Vector3d& applied_anchor_shift_m = Eigen::Vector3d::Zero());

}  // namespace fvp::host::eval
