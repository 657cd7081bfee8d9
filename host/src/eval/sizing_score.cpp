#include "fvp/host/eval/sizing_score.h"

#include "fvp/host/eval/fruitlet_matching.h"

namespace fvp::host::eval {
namespace {

nlohmann::json vec3(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

}  // namespace

nlohmann::json scoreSizing(const sizing::SizingResult& sz,
                           const std::vector<GroundTruthFruitlet>& truth,
                           sizing::SizingEstimator estimator) {
  const bool paper = estimator == sizing::SizingEstimator::kPaper;
  std::vector<Eigen::Vector3d> detections, centres;
  std::vector<double> est_mm, gt_mm;
  for (const auto& f : sz.fruitlets) {
    detections.push_back(paper ? f.centroid_m : f.sphere_center_m);
    est_mm.push_back(paper ? f.size_paper_mm : f.size_ours_mm);
  }
  for (const auto& g : truth) {
    centres.push_back(g.center_m);
    gt_mm.push_back(g.size_mm);
  }
  const std::vector<int> match = matchFruitlets(detections, centres);
  const SizeMetrics m = sizeMetrics(gt_mm, est_mm, match, detections.size());
  nlohmann::json fruitlets = nlohmann::json::array();
  for (std::size_t g = 0; g < truth.size(); ++g) {
    nlohmann::json f = {
        {"gt_center_m", vec3(centres[g])}, {"gt_size_mm", gt_mm[g]}, {"matched", match[g] >= 0}};
    if (match[g] >= 0) {
      f["est_center_m"] = vec3(detections[match[g]]);
      f["est_size_mm"] = est_mm[match[g]];
      f["center_error_mm"] = 1000.0 * (detections[match[g]] - centres[g]).norm();
      f["detection"] = match[g];
    } else {
      f["est_center_m"] = nullptr;
      f["est_size_mm"] = nullptr;
    }
    fruitlets.push_back(f);
  }
  return {{"fruitlets", fruitlets}, {"detections", detections.size()}, {"metrics", metricsJson(m)}};
}

nlohmann::json metricsJson(const SizeMetrics& m) {
  const auto opt = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json();
  };
  return {{"match_percent", m.match_percent},
          {"mae_mm", opt(m.mae_mm)},
          {"mape_percent", opt(m.mape_percent)},
          {"precision_percent", opt(m.precision_percent)}};
}

nlohmann::json pooledMetricsJson(const nlohmann::json& fruitlets, std::size_t detections) {
  std::vector<double> gt_mm, est_mm;
  std::vector<int> detection_of_gt;
  for (const auto& f : fruitlets) {
    gt_mm.push_back(f.at("gt_size_mm").get<double>());
    const bool matched = f.at("matched").get<bool>();
    detection_of_gt.push_back(matched ? static_cast<int>(est_mm.size()) : -1);
    if (matched) est_mm.push_back(f.at("est_size_mm").get<double>());
  }
  return metricsJson(sizeMetrics(gt_mm, est_mm, detection_of_gt, detections));
}

nlohmann::json scoreBothEstimators(const sizing::SizingResult& sz,
                                   const std::vector<GroundTruthFruitlet>& truth,
                                   sizing::SizingEstimator estimator) {
  nlohmann::json out = scoreSizing(sz, truth, estimator);
  const auto other = estimator == sizing::SizingEstimator::kOurs ? sizing::SizingEstimator::kPaper
                                                                 : sizing::SizingEstimator::kOurs;
  const nlohmann::json alternative = scoreSizing(sz, truth, other);
  out["sizing_estimator"] = sizing::toString(estimator);
  out[std::string("fruitlets_") + sizing::toString(other) + "_sizing"] = alternative["fruitlets"];
  out[std::string("metrics_") + sizing::toString(other) + "_sizing"] = alternative["metrics"];
  return out;
}

namespace {

nlohmann::json detectionJson(const sizing::FruitletEstimate& f) {
  nlohmann::json per_image = nlohmann::json::array();
  for (const auto& s : f.per_image)
    per_image.push_back({{"view", s.view},
                         {"size_paper_mm", s.size_paper_mm},
                         {"size_ours_mm", s.size_ours_mm},
                         {"minor_axis_px", s.minor_axis_px},
                         {"max_disparity_px", s.max_disparity_px},
                         {"visible_fraction", s.visible_fraction},
                         {"touches_border", s.touches_border},
                         {"shared_segment", s.shared_segment},
                         {"well_seen", s.well_seen},
                         {"axis_ratio", s.axis_ratio},
                         {"ellipse",
                          {{"center_px", s.ellipse_center_px},
                           {"axes_px", s.ellipse_axes_px},
                           {"angle_deg", s.ellipse_angle_deg}}}});
  return {{"center_m", vec3(f.center_m)},
          {"size_mm", f.size_mm},
          {"centroid_m", vec3(f.centroid_m)},
          {"sphere_center_m", vec3(f.sphere_center_m)},
          {"sphere_radius_m", f.sphere_radius_m},
          {"size_source", sizing::toString(f.size_source)},
          {"size_paper_mm", f.size_paper_mm},
          {"size_ours_mm", f.size_ours_mm},
          {"points", f.points},
          {"support",
           {{"sized_images", f.support.sized_images},
            {"own_segment_images", f.support.own_segment_images},
            {"well_seen_images", f.support.well_seen_images},
            {"sphere_rms_mm", f.support.sphere_rms_mm},
            {"required_points", f.support.required_points},
            {"required_area_fraction", f.support.required_area_fraction},
            {"size_stderr_mm", f.support.size_stderr_mm},
            {"merged_detections", f.support.merged_detections},
            {"view_evidence_points", f.support.view_evidence_points},
            {"view_agreement", f.support.view_agreement},
            {"unconfirmed", f.support.unconfirmed}}},
          {"per_image", per_image}};
}

}  // namespace

nlohmann::json sizingDetails(const sizing::SizingResult& sz) {
  nlohmann::json detections = nlohmann::json::array(), unsupported = nlohmann::json::array();
  for (const auto& f : sz.fruitlets) detections.push_back(detectionJson(f));
  for (const auto& f : sz.unsupported) unsupported.push_back(detectionJson(f));
  return {{"sized_fruitlets", detections},
          {"unsupported_detections", unsupported},
          {"sizing_stats",
           {{"surface_points", sz.surface_points},
            {"in_roi_points", sz.in_roi_points},
            {"inlier_points", sz.inlier_points},
            {"events",
             {{"small_clusters", sz.events.small_clusters},
              {"invalid_disparity_windows", sz.events.invalid_disparity_windows},
              {"saturated_windows", sz.events.saturated_windows},
              {"not_visible", sz.events.not_visible},
              {"single_image_fruitlets", sz.events.single_image_fruitlets},
              {"unsized_clusters", sz.events.unsized_clusters},
              {"failed_sphere_fits", sz.events.failed_sphere_fits},
              {"clusters_split_off", sz.events.clusters_split_off},
              {"instance_parts_split_off", sz.events.instance_parts_split_off},
              {"unsupported_detections", sz.events.unsupported_detections},
              {"denied_by_views", sz.events.denied_by_views},
              {"overlapping_detections_merged", sz.events.overlapping_detections_merged}}}}}};
}

void addTagFrame(nlohmann::json& details, const std::optional<Eigen::Isometry3d>& T_world_tag,
                 const Eigen::Vector3d& applied_anchor_shift_m) {
  if (!T_world_tag) return;
  const Eigen::Quaterniond q(T_world_tag->rotation());
  details["T_world_tag"] = {{"translation_m", vec3(T_world_tag->translation())},
                            {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
  const Eigen::Isometry3d T_tag_world = T_world_tag->inverse();
  for (auto& f : details["sized_fruitlets"]) {
    const auto& c = f.at("center_m");
    const Eigen::Vector3d center_m(c.at(0).get<double>(), c.at(1).get<double>(),
                                   c.at(2).get<double>());
    f["center_tag_m"] = vec3(T_tag_world * (center_m - applied_anchor_shift_m));
  }
}

}  // namespace fvp::host::eval
