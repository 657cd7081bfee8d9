#include "fvp/host/sizing/fruitlet_sizer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>

#include "fvp/host/sizing/point_filters.h"

namespace fvp::host::sizing {
namespace {

// The hull runs through the centres of the segment's boundary pixels, inside the true
// silhouette: measured ~0.6 px short across on rendered spheres (docs/design.md section 10).
constexpr double kHullShortfallPx = 0.6;
// TSDF zero crossings per voxel face of surface, averaged over a sphere's normals.
constexpr double kSurfaceCrossingsPerVoxelFace = 1.5;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Connected fruitlet segments of one image (8-connected).
ViewSegments segment(const cv::Mat& mask) {
  ViewSegments s;
  cv::Mat binary = mask != 0;
  cv::connectedComponentsWithStats(binary, s.labels, s.stats, s.centroids, 8, CV_32S);
  return s;
}

/// An instance segmentation's segments: one per instance id (its pixels need not be
/// connected: a stem may cross a fruitlet), numbered 1.. in order of first pixel.
ViewSegments segmentInstances(const cv::Mat& instances) {
  ViewSegments s;
  s.labels = cv::Mat(instances.size(), CV_32S, cv::Scalar(0));
  std::map<int, int> label_of;
  struct Extent {
    int x0 = std::numeric_limits<int>::max(), y0 = std::numeric_limits<int>::max();
    int x1 = -1, y1 = -1, area = 0;
    double sum_x = 0.0, sum_y = 0.0;
  };
  std::vector<Extent> extents(1);
  for (int y = 0; y < instances.rows; ++y)
    for (int x = 0; x < instances.cols; ++x) {
      const int id = instances.at<std::uint16_t>(y, x);
      if (id == 0) continue;
      auto [it, added] = label_of.emplace(id, int(extents.size()));
      if (added) extents.emplace_back();
      Extent& e = extents[std::size_t(it->second)];
      e.x0 = std::min(e.x0, x), e.y0 = std::min(e.y0, y);
      e.x1 = std::max(e.x1, x), e.y1 = std::max(e.y1, y);
      ++e.area, e.sum_x += x, e.sum_y += y;
      s.labels.at<int>(y, x) = it->second;
    }
  s.stats = cv::Mat(int(extents.size()), cv::CC_STAT_MAX, CV_32S, cv::Scalar(0));
  s.centroids = cv::Mat(int(extents.size()), 2, CV_64F, cv::Scalar(0));
  for (int l = 1; l < int(extents.size()); ++l) {
    const Extent& e = extents[std::size_t(l)];
    s.stats.at<int>(l, cv::CC_STAT_LEFT) = e.x0;
    s.stats.at<int>(l, cv::CC_STAT_TOP) = e.y0;
    s.stats.at<int>(l, cv::CC_STAT_WIDTH) = e.x1 - e.x0 + 1;
    s.stats.at<int>(l, cv::CC_STAT_HEIGHT) = e.y1 - e.y0 + 1;
    s.stats.at<int>(l, cv::CC_STAT_AREA) = e.area;
    s.centroids.at<double>(l, 0) = e.sum_x / e.area;
    s.centroids.at<double>(l, 1) = e.sum_y / e.area;
  }
  return s;
}

/// Max valid disparity in the (2h+1)^2 window at (u, v); 0 when none.
double windowMaxDisparity(const cv::Mat& disparity, int u, int v, int h) {
  double best = 0.0;
  for (int y = std::max(0, v - h); y <= std::min(disparity.rows - 1, v + h); ++y) {
    const float* d = disparity.ptr<float>(y);
    for (int x = std::max(0, u - h); x <= std::min(disparity.cols - 1, u + h); ++x)
      if (std::isfinite(d[x]) && d[x] > best) best = d[x];
  }
  return best;
}

/// Eq. 4 in one image on the segment a cluster falls on (view and shared flag left to the
/// caller); nothing when the cluster is not visible there or the disparity window is
/// invalid or saturated (counted).
std::optional<ImageSize> measureImage(const SizingView& view, const ViewSegments& segments,
                                      int best, double visible, const SizingConfig& config,
                                      SizingEvents& events) {
  const StereoIntrinsics& in = view.intrinsics;
  const cv::Mat& labels = segments.labels;
  if (best == 0 || visible < config.min_visible_fraction) {
    ++events.not_visible;
    return std::nullopt;
  }
  const cv::Mat& stats = segments.stats;
  const int x0 = stats.at<int>(best, cv::CC_STAT_LEFT), y0 = stats.at<int>(best, cv::CC_STAT_TOP);
  const int w = stats.at<int>(best, cv::CC_STAT_WIDTH), h = stats.at<int>(best, cv::CC_STAT_HEIGHT);
  if (stats.at<int>(best, cv::CC_STAT_AREA) < config.min_segment_pixels) {
    ++events.not_visible;
    return std::nullopt;
  }
  // Hull of the segment's pixel centres (as cv2.fitEllipse on the hull in the authors' code).
  std::vector<cv::Point> pixels;
  for (int y = y0; y < y0 + h; ++y)
    for (int x = x0; x < x0 + w; ++x)
      if (labels.at<int>(y, x) == best) pixels.emplace_back(x, y);
  std::vector<cv::Point> hull;
  cv::convexHull(pixels, hull);
  if (hull.size() < 5) {
    ++events.not_visible;
    return std::nullopt;
  }
  const cv::RotatedRect ellipse = cv::fitEllipse(hull);
  const double minor_px = std::min(ellipse.size.width, ellipse.size.height);
  const double major_px = std::max(ellipse.size.width, ellipse.size.height);
  const cv::Point2d c(segments.centroids.at<double>(best, 0),
                      segments.centroids.at<double>(best, 1));
  const double d_max = windowMaxDisparity(view.disparity_px, int(std::lround(c.x)),
                                          int(std::lround(c.y)), config.disparity_window_half_px);
  if (!(d_max > 0.0) || in.fx_px * in.baseline_m / d_max > config.max_depth_m) {
    ++events.invalid_disparity_windows;
    return std::nullopt;
  }
  if (d_max >= config.saturated_disparity_px) {
    ++events.saturated_windows;
    return std::nullopt;
  }
  ImageSize s;
  s.minor_axis_px = minor_px;
  s.max_disparity_px = d_max;
  s.visible_fraction = visible;
  s.axis_ratio = major_px > 0 ? minor_px / major_px : 0.0;
  s.ellipse_center_px = {ellipse.center.x, ellipse.center.y};
  s.ellipse_axes_px = {ellipse.size.width, ellipse.size.height};
  s.ellipse_angle_deg = ellipse.angle;
  s.touches_border = x0 <= 0 || y0 <= 0 || x0 + w >= labels.cols || y0 + h >= labels.rows;
  s.size_paper_mm = 1000.0 * minor_px * in.baseline_m / d_max;
  const double m = minor_px + kHullShortfallPx;
  const double z_near = in.fx_px * in.baseline_m / d_max;
  s.size_ours_mm = 1000.0 * m * z_near / (in.fx_px - 0.5 * m);
  return s;
}

/// DetectionSupport::view_evidence_points and view_agreement of one detection's points.
void measureViewAgreement(const std::vector<Eigen::Vector3f>& points,
                          const std::vector<SizingView>& views, const SizingConfig& config,
                          DetectionSupport& support) {
  std::size_t seen = 0, seen_past = 0, on_fruitlet = 0;
  const double tolerance_px = config.view_agreement_disparity_px;
  for (const SizingView& view : views) {
    const cv::Mat& disparity = view.disparity_px;
    const cv::Mat& mask = view.fruitlet_mask;
    if (disparity.empty() || disparity.type() != CV_32F) continue;
    const bool has_mask = mask.type() == CV_8U && mask.size() == disparity.size();
    const Eigen::Isometry3d T_camera_world = view.T_world_camera.inverse();
    const double fb = view.intrinsics.fx_px * view.intrinsics.baseline_m;
    for (const auto& p_world : points) {
      const Eigen::Vector3d p = T_camera_world * p_world.cast<double>();
      const auto px = view.intrinsics.project(p);  // nothing behind the camera
      if (!px) continue;
      const int u = int(std::lround(px->x())), v = int(std::lround(px->y()));
      if (u < 0 || v < 0 || u >= disparity.cols || v >= disparity.rows) continue;
      const double expected_px = fb / p.z();
      bool matches = false, any_valid = false, all_farther = true, fruitlet = false;
      for (int y = std::max(0, v - 1); y <= std::min(disparity.rows - 1, v + 1); ++y)
        for (int x = std::max(0, u - 1); x <= std::min(disparity.cols - 1, u + 1); ++x) {
          const float d = disparity.at<float>(y, x);
          if (has_mask && mask.at<std::uint8_t>(y, x) != 0) fruitlet = true;
          if (!std::isfinite(d) || !(d > 0.0f)) continue;
          any_valid = true;
          matches |= std::abs(d - expected_px) <= tolerance_px;
          all_farther &= d < expected_px - tolerance_px;
        }
      if (matches) {
        ++seen;
        if (fruitlet) ++on_fruitlet;
      } else if (any_valid && all_farther) {
        ++seen_past;
      }
    }
  }
  support.view_evidence_points = seen + seen_past;
  support.view_agreement = support.view_evidence_points > 0
                               ? double(on_fruitlet) / double(support.view_evidence_points)
                               : -1.0;
}

/// Both estimators, the support and the support rule's requirement from a cluster's
/// measured images (their shared flags set); nothing for a cluster no image sized.
void aggregate(FruitletEstimate& f, const SizingConfig& config) {
  if (f.per_image.empty()) return;
  std::vector<double> all, good;
  f.size_paper_mm = 0.0;
  f.support.own_segment_images = 0;
  for (auto& s : f.per_image) {
    f.size_paper_mm = std::max(f.size_paper_mm, s.size_paper_mm);
    all.push_back(s.size_ours_mm);
    s.well_seen = s.visible_fraction >= config.well_seen_fraction && !s.touches_border &&
                  !s.shared_segment && s.axis_ratio >= config.min_axis_ratio;
    if (s.well_seen) good.push_back(s.size_ours_mm);
    if (!s.shared_segment) ++f.support.own_segment_images;
  }
  f.support.sized_images = int(f.per_image.size());
  f.support.well_seen_images = int(good.size());
  const bool every_segment_shared = f.support.own_segment_images == 0;
  if (!good.empty()) {
    f.size_ours_mm = median(good);
    f.size_source = SizeSource::kWellSeenImages;
  } else if (every_segment_shared && f.sphere_radius_m > 0.0) {  // the sphere was accepted
    // In every image the fruitlet's segment is merged with another's: each hull measures
    // both; its 3-D surface measures it alone. (Cut or border segments measure less of it,
    // and their median stays the estimate.)
    f.size_ours_mm = 2000.0 * f.sphere_radius_m;
    f.size_source = SizeSource::kSphereFit;
  } else {
    f.size_ours_mm = median(all);
    f.size_source = SizeSource::kAllImages;
  }
  f.support.size_stderr_mm = -1.0;
  if (good.size() >= 2) {
    std::vector<double> deviations;
    for (double v : good) deviations.push_back(std::abs(v - f.size_ours_mm));
    f.support.size_stderr_mm =
        1.2533 * 1.4826 * median(deviations) / std::sqrt(double(good.size()));
  }
  if (config.estimator == SizingEstimator::kPaper) {
    f.center_m = f.centroid_m;
    f.size_mm = f.size_paper_mm;
  } else {
    f.center_m = f.sphere_center_m;
    f.size_mm = f.size_ours_mm;
  }
  // The support rule's requirement, on our size for either estimator (the paper's maximum
  // would ask more of the same points).
  const double radius_m = 0.0005 * f.size_ours_mm;
  f.support.required_area_fraction =
      f.size_source == SizeSource::kSphereFit
          ? std::max(config.min_support_area_fraction, config.sphere_fit_support_area_fraction)
          : config.min_support_area_fraction;
  f.support.required_points = kSurfaceCrossingsPerVoxelFace * f.support.required_area_fraction *
                              4.0 * M_PI * radius_m * radius_m /
                              (config.surface_voxel_size_m * config.surface_voxel_size_m);
}

// sizeFruitlets' first stage: the surface points in the ROI voxels, outliers removed, into
// result.points and their DBSCAN labels (merged clusters and instances split); returns the
// points of each cluster.
std::map<int, std::vector<Eigen::Vector3f>> clusterSurfacePoints(
    const std::vector<SizingView>& views, const std::vector<Eigen::Vector3f>& surface_points_m,
    const std::function<bool(const Eigen::Vector3f&)>& in_roi_voxel, const SizingConfig& config,
    SizingResult& result) {
  result.surface_points = surface_points_m.size();
  std::vector<Eigen::Vector3f> roi;
  for (const auto& p : surface_points_m)
    if (!in_roi_voxel || in_roi_voxel(p)) roi.push_back(p);
  result.in_roi_points = roi.size();
  for (std::size_t i :
       statisticalOutlierInliers(roi, config.outlier_neighbours, config.outlier_std_ratio))
    result.points.push_back(roi[i]);
  result.inlier_points = result.points.size();
  result.labels = dbscan(result.points, config.dbscan_eps_m, config.dbscan_min_samples);
  if (config.split_merged_clusters) {
    ClusterSplitConfig split;
    split.min_cluster_points = config.min_cluster_points;
    result.events.clusters_split_off = splitMergedClusters(result.points, result.labels, split);
  }
  if (config.use_instances)
    result.events.instance_parts_split_off =
        splitByInstances(result.points, result.labels, views, config.instance_split);

  std::map<int, std::vector<Eigen::Vector3f>> clusters;
  for (std::size_t i = 0; i < result.points.size(); ++i)
    if (result.labels[i] != kDbscanNoise) clusters[result.labels[i]].push_back(result.points[i]);
  return clusters;
}

// sizeFruitlets' later stages over the clusters of enough points: where each falls in every
// image, its own measurements, then the support and overlap rules, which drop and merge
// detections, each time sizing the kept ones again.
class DetectionSizer {
 public:
  DetectionSizer(const std::vector<SizingView>& views,
                 const std::vector<std::shared_ptr<const ViewSegments>>& given_segments,
                 const SizingConfig& config, std::map<int, std::vector<Eigen::Vector3f>> clusters,
                 SizingResult& result)
      : views_(views), config_(config), clusters_(std::move(clusters)), result_(result) {
    own_segments_.reserve(views.size());  // segments_ points into it: never reallocated
    for (std::size_t i = 0; i < views.size(); ++i) {
      const ViewSegments* given = i < given_segments.size() ? given_segments[i].get() : nullptr;
      if (!given) own_segments_.push_back(segmentsOf(views[i]));
      segments_.push_back(given ? given : &own_segments_.back());
    }
    for (auto& [label, pts] : clusters_) {
      if (int(pts.size()) < config.min_cluster_points) {
        ++result.events.small_clusters;
        continue;
      }
      sized_.emplace_back(label, &pts);
    }
    falls_.assign(sized_.size(), std::vector<Fall>(views.size()));
    measured_.resize(sized_.size());
    with_instances_ = config.use_instances &&
                      std::any_of(views.begin(), views.end(),
                                  [](const auto& v) { return !v.fruitlet_instances.empty(); });
    instance_of_.resize(sized_.size());
    dropped_.assign(sized_.size(), false);
    marks_segments_.assign(sized_.size(), true);
    merged_into_.assign(sized_.size(), 0);
    estimates_.resize(sized_.size());
  }

  // Which segment of each image every cluster falls on, first for all clusters, so that a
  // segment two clusters fall on (touching fruitlets merged in 2-D) is known.
  void measureAll() {
    for (std::size_t ci = 0; ci < sized_.size(); ++ci) {
      computeFalls(ci);
      measure(ci, result_.events);
    }
  }

  void applyRules();

  /// The kept detections that were sized, into result.fruitlets.
  void keepSized() {
    for (std::size_t ci = 0; ci < sized_.size(); ++ci) {
      if (dropped_[ci]) continue;
      FruitletEstimate& f = estimates_[ci];
      if (f.per_image.empty()) {
        ++result_.events.unsized_clusters;
        continue;
      }
      measureViewAgreement(*sized_[ci].second, views_, config_, f.support);
      if (deniedByTheViews(f)) {
        ++result_.events.denied_by_views;
        result_.unsupported.push_back(std::move(f));
        continue;
      }
      if (f.per_image.size() == 1) ++result_.events.single_image_fruitlets;
      if (!(f.sphere_radius_m > 0.0)) ++result_.events.failed_sphere_fits;
      result_.fruitlets.push_back(std::move(f));
    }
  }

 private:
  struct Fall {
    bool in_image = false;
    int segment = 0;
    double visible = 0.0;
  };

  void computeFalls(std::size_t ci);
  void measure(std::size_t ci, SizingEvents& events);

  // Sizes a kept cluster from its images, an image's segment shared when another cluster
  // that still marks segments falls on it.
  FruitletEstimate sizeKept(std::size_t ci) const {
    FruitletEstimate f = measured_[ci];
    for (auto& s : f.per_image) {
      const auto vi = std::size_t(s.view);
      const int segment_label = falls_[ci][vi].segment;
      s.shared_segment = false;
      for (std::size_t other = 0; other < sized_.size(); ++other)
        s.shared_segment |= other != ci && marks_segments_[other] &&
                            falls_[other][vi].segment == segment_label &&
                            falls_[other][vi].visible >= config_.min_visible_fraction;
    }
    aggregate(f, config_);
    f.support.merged_detections = merged_into_[ci];
    return f;
  }

  // The agreement rule (SizingConfig::min_view_agreement_registered).
  bool deniedByTheViews(const FruitletEstimate& f) const {
    constexpr int kImagesThatAgreeOrReveal = 2;
    return config_.registered_views && config_.min_view_agreement_registered > 0.0 &&
           f.support.view_agreement >= 0.0 &&
           f.support.view_agreement < config_.min_view_agreement_registered &&
           f.support.well_seen_images < kImagesThatAgreeOrReveal;
  }

  static double supportRatio(const FruitletEstimate& f) {
    return f.support.required_points > 0.0 ? double(f.points) / f.support.required_points
                                           : INFINITY;
  }
  // Against the quarter every detection must show, whatever sized it.
  double quarterRatio(const FruitletEstimate& f) const {
    if (!(config_.min_support_area_fraction > 0.0)) return double(INFINITY);
    return supportRatio(f) * f.support.required_area_fraction / config_.min_support_area_fraction;
  }

  void drop(std::size_t ci, bool unconfirmed) {
    estimates_[ci].support.unconfirmed = unconfirmed;
    dropped_[ci] = true;
    marks_segments_[ci] = estimates_[ci].support.own_segment_images > 0;
    measureViewAgreement(*sized_[ci].second, views_, config_, estimates_[ci].support);
    result_.unsupported.push_back(std::move(estimates_[ci]));
  }

  // The worst-supported kept and sized detection under `ratio` < 1, every kept one sized
  // again first.
  template <typename Ratio>
  std::optional<std::size_t> worstUnder(const Ratio& ratio) {
    std::optional<std::size_t> worst;
    double worst_ratio = 1.0;
    for (std::size_t ci = 0; ci < sized_.size(); ++ci) {
      if (dropped_[ci]) continue;
      estimates_[ci] = sizeKept(ci);
      const FruitletEstimate& f = estimates_[ci];
      if (f.per_image.empty()) continue;  // unsized: dropped below, not by the rule
      if (const double r = ratio(f); r < worst_ratio) worst = ci, worst_ratio = r;
    }
    return worst;
  }

  std::optional<std::pair<std::size_t, std::size_t>> deepestOverlap() const;
  void merge(std::size_t keep, std::size_t gone);

  const std::vector<SizingView>& views_;
  const SizingConfig& config_;
  std::map<int, std::vector<Eigen::Vector3f>> clusters_;
  SizingResult& result_;
  std::vector<ViewSegments> own_segments_;  ///< of the views that came without theirs
  std::vector<const ViewSegments*> segments_;
  std::vector<std::pair<int, std::vector<Eigen::Vector3f>*>> sized_;  // label, its points
  std::vector<std::vector<Fall>> falls_;                              // per cluster, per view
  // Each cluster's own measurements, once: its centroid and sphere, and Eq. 4 in every image
  // it is visible in. Only whether an image's segment is shared depends on which other
  // detections are kept (sizeKept).
  std::vector<FruitletEstimate> measured_;
  bool with_instances_ = false;
  std::vector<std::vector<int>> instance_of_;  // per view (dominantInstances)
  std::vector<bool> dropped_, marks_segments_;
  std::vector<int> merged_into_;
  std::vector<FruitletEstimate> estimates_;
};

void DetectionSizer::computeFalls(std::size_t ci) {
  for (std::size_t vi = 0; vi < views_.size(); ++vi) {
    const Eigen::Isometry3d T_camera_world = views_[vi].T_world_camera.inverse();
    const cv::Mat& labels = segments_[vi]->labels;
    std::map<int, int> votes;
    int in_image = 0;
    for (const auto& p : *sized_[ci].second) {
      const auto px = views_[vi].intrinsics.project(T_camera_world * p.cast<double>());
      if (!px) continue;
      const int u = int(std::lround(px->x())), v = int(std::lround(px->y()));
      if (u < 0 || v < 0 || u >= labels.cols || v >= labels.rows) continue;
      ++in_image;
      if (const int l = labels.at<int>(v, u); l > 0) ++votes[l];
    }
    int best = 0, best_votes = 0;
    for (const auto& [l, n] : votes)
      if (n > best_votes) best = l, best_votes = n;
    falls_[ci][vi] = in_image > 0 ? Fall{true, best, double(best_votes) / in_image} : Fall{};
  }
}

void DetectionSizer::measure(std::size_t ci, SizingEvents& events) {
  const std::vector<Eigen::Vector3f>& pts = *sized_[ci].second;
  if (with_instances_) instance_of_[ci] = dominantInstances(pts, views_, config_.instance_split);
  FruitletEstimate& f = measured_[ci];
  f = FruitletEstimate{};
  f.points = pts.size();
  for (const auto& p : pts) f.centroid_m += p.cast<double>();
  f.centroid_m /= double(pts.size());
  for (std::size_t vi = 0; vi < views_.size(); ++vi) {
    if (!falls_[ci][vi].in_image) continue;
    if (auto s = measureImage(views_[vi], *segments_[vi], falls_[ci][vi].segment,
                              falls_[ci][vi].visible, config_, events)) {
      s->view = int(vi);
      f.per_image.push_back(*s);
    }
  }
  f.sphere_center_m = f.centroid_m;
  Eigen::Vector3d sphere;
  double radius = 0.0;
  // Accept a sphere only of a fruitlet's size near the points (3-8 mm radius and margin).
  if (fitSphere(pts, sphere, radius) && radius > kDefaultMinFruitletRadius_m &&
      radius < kDefaultMaxFruitletRadius_m && (sphere - f.centroid_m).norm() < 0.010) {
    f.sphere_center_m = sphere;
    f.sphere_radius_m = radius;
    double sum_sq = 0.0;
    for (const auto& p : pts) {
      const double d = (p.cast<double>() - sphere).norm() - radius;
      sum_sq += d * d;
    }
    f.support.sphere_rms_mm = 1000.0 * std::sqrt(sum_sq / double(pts.size()));
  }
}

// The overlap rule: two fruitlets are firm bodies that touch but do not interpenetrate, so
// two kept spheres that overlap by more than half the smaller one's radius are one fruitlet
// seen twice (views whose poses disagree fuse its surface at two places). With instance
// masks, two whose spheres overlap at all are one fruitlet when the views see them on one
// instance (sameInstance). The pair overlapping most, if any.
std::optional<std::pair<std::size_t, std::size_t>> DetectionSizer::deepestOverlap() const {
  std::optional<std::pair<std::size_t, std::size_t>> pair;
  double deepest = 0.0;
  for (std::size_t a = 0; a < sized_.size(); ++a)
    for (std::size_t b = a + 1; b < sized_.size(); ++b) {
      if (dropped_[a] || dropped_[b]) continue;
      const FruitletEstimate &fa = estimates_[a], &fb = estimates_[b];
      // Only fitted spheres: a centroid lies inside its fruitlet, nearer the camera.
      if (fa.per_image.empty() || fb.per_image.empty() || !(fa.sphere_radius_m > 0.0) ||
          !(fb.sphere_radius_m > 0.0))
        continue;
      const double ra = 0.0005 * fa.size_ours_mm, rb = 0.0005 * fb.size_ours_mm;
      const double overlap = ra + rb - (fa.sphere_center_m - fb.sphere_center_m).norm();
      const double depth = overlap / std::min(ra, rb);
      const bool one_instance =
          with_instances_ && overlap > 0.0 && sameInstance(instance_of_[a], instance_of_[b]);
      if ((depth > config_.max_detection_overlap_fraction || one_instance) &&
          (!pair || depth > deepest))
        deepest = depth, pair = {a, b};
    }
  return pair;
}

// An overlapping pair merged into the better-supported one, its points added.
void DetectionSizer::merge(std::size_t keep, std::size_t gone) {
  if (supportRatio(estimates_[gone]) > supportRatio(estimates_[keep])) std::swap(keep, gone);
  sized_[keep].second->insert(sized_[keep].second->end(), sized_[gone].second->begin(),
                              sized_[gone].second->end());
  for (int& label : result_.labels)
    if (label == sized_[gone].first) label = sized_[keep].first;
  merged_into_[keep] += 1 + merged_into_[gone];
  dropped_[gone] = true;
  marks_segments_[gone] = false;
  ++result_.events.overlapping_detections_merged;
  computeFalls(keep);
  SizingEvents counted_already;  // both parts' images were counted when first measured
  measure(keep, counted_already);
}

void DetectionSizer::applyRules() {
  for (;;) {
    // The support rule, one detection at a time: the worst-supported one that fails is
    // dropped and the rest are sized again, since a dropped phantom (no segment of its own:
    // it lay on a fruitlet's) no longer makes that fruitlet's images shared. A dropped
    // detection that had a segment of its own keeps marking segments: it may be a real
    // fruitlet merged in 2-D with a neighbour, whose merged outline must not size the
    // neighbour. The quarter first; the hemisphere a sphere-fit size asks for only once
    // no two detections overlap, since two shells of one fruitlet (views whose poses
    // disagree) are each sized by their sphere fit until the overlap rule merges them.
    while (const auto worst =
               worstUnder([this](const FruitletEstimate& f) { return quarterRatio(f); }))
      drop(*worst, false);
    // The pair overlapping most is merged, and everything is sized again.
    if (const auto pair = deepestOverlap()) {
      merge(pair->first, pair->second);
      continue;
    }
    // The hemisphere rule (sphere_fit_support_area_fraction): a detection sized by its
    // sphere fit alone must show half its sphere. One at a time, as above.
    const auto worst = worstUnder(supportRatio);
    if (!worst) break;
    drop(*worst, true);
  }
}

}  // namespace

ViewSegments segmentsOf(const SizingView& view) {
  return view.fruitlet_instances.empty() ? segment(view.fruitlet_mask)
                                         : segmentInstances(view.fruitlet_instances);
}

const char* toString(SizingEstimator estimator) {
  return estimator == SizingEstimator::kOurs ? "ours" : "paper";
}

SizingEstimator parseSizingEstimator(std::string_view name) {
  if (name == "ours") return SizingEstimator::kOurs;
  if (name == "paper") return SizingEstimator::kPaper;
  throw std::invalid_argument("sizing estimator: expected ours or paper, got '" +
                              std::string(name) + "'");
}

const char* toString(SizeSource source) {
  switch (source) {
    case SizeSource::kWellSeenImages:
      return "well_seen_images";
    case SizeSource::kSphereFit:
      return "sphere_fit";
    case SizeSource::kAllImages:
      return "all_images";
  }
  return "unknown";
}

void SizingConfig::validate() const {
  if (outlier_neighbours < 1) throw std::invalid_argument("sizing: outlier_neighbours >= 1");
  if (!(dbscan_eps_m > 0.0)) throw std::invalid_argument("sizing: dbscan_eps_m > 0");
  if (dbscan_min_samples < 1) throw std::invalid_argument("sizing: dbscan_min_samples >= 1");
  if (disparity_window_half_px < 0) throw std::invalid_argument("sizing: window half >= 0");
  if (!(max_depth_m > 0.0)) throw std::invalid_argument("sizing: max_depth_m > 0");
  if (!(min_support_area_fraction >= 0.0) || !(min_support_area_fraction <= 1.0))
    throw std::invalid_argument("sizing: min_support_area_fraction in [0, 1]");
  if (!(sphere_fit_support_area_fraction >= 0.0) || !(sphere_fit_support_area_fraction <= 1.0))
    throw std::invalid_argument("sizing: sphere_fit_support_area_fraction in [0, 1]");
  if (!(surface_voxel_size_m > 0.0))
    throw std::invalid_argument("sizing: surface_voxel_size_m > 0");
  if (!(max_detection_overlap_fraction >= 0.0))
    throw std::invalid_argument("sizing: max_detection_overlap_fraction >= 0");
  if (!(view_agreement_disparity_px > 0.0))
    throw std::invalid_argument("sizing: view_agreement_disparity_px > 0");
  if (!(min_view_agreement_registered >= 0.0 && min_view_agreement_registered <= 1.0))
    throw std::invalid_argument("sizing: min_view_agreement_registered in [0, 1]");
  if (use_instances) instance_split.validate();
  if (split_merged_clusters && min_cluster_points < 4)
    throw std::invalid_argument("sizing: min_cluster_points >= 4 (a sphere needs 4 points)");
}

std::vector<std::array<std::uint8_t, 3>> clusterColours(const std::vector<int>& labels) {
  static constexpr std::array<std::array<std::uint8_t, 3>, 8> kPalette{{{228, 26, 28},
                                                                        {55, 126, 184},
                                                                        {77, 175, 74},
                                                                        {152, 78, 163},
                                                                        {255, 127, 0},
                                                                        {166, 86, 40},
                                                                        {247, 129, 191},
                                                                        {255, 255, 51}}};
  std::vector<std::array<std::uint8_t, 3>> out;
  out.reserve(labels.size());
  for (int label : labels)
    out.push_back(label < 0 ? std::array<std::uint8_t, 3>{128, 128, 128}
                            : kPalette[label % kPalette.size()]);
  return out;
}

void translateDetections(SizingResult& result, const Eigen::Vector3d& shift_m) {
  for (auto* list : {&result.fruitlets, &result.unsupported})
    for (FruitletEstimate& f : *list) {
      f.center_m += shift_m;
      f.centroid_m += shift_m;
      f.sphere_center_m += shift_m;
    }
}

SizingResult sizeFruitlets(const std::vector<SizingView>& views,
                           const std::vector<Eigen::Vector3f>& surface_points_m,
                           const std::function<bool(const Eigen::Vector3f&)>& in_roi_voxel,
                           const SizingConfig& config) {
  return sizeFruitlets(views, {}, surface_points_m, in_roi_voxel, config);
}

SizingResult sizeFruitlets(const std::vector<SizingView>& views,
                           const std::vector<std::shared_ptr<const ViewSegments>>& segments,
                           const std::vector<Eigen::Vector3f>& surface_points_m,
                           const std::function<bool(const Eigen::Vector3f&)>& in_roi_voxel,
                           const SizingConfig& config) {
  config.validate();
  SizingResult result;
  DetectionSizer sizer(views, segments, config,
                       clusterSurfacePoints(views, surface_points_m, in_roi_voxel, config, result),
                       result);
  sizer.measureAll();
  sizer.applyRules();
  sizer.keepSized();
  result.events.unsupported_detections = result.unsupported.size();
  return result;
}

}  // namespace fvp::host::sizing
