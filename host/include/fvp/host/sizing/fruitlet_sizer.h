// Fruitlet sizing (paper, "Fruitlet Sizing", Figure 5; docs/design.md sections 1 and 10): surface
// points -> keep those in ROI-occupied fine voxels -> statistical outlier removal -> DBSCAN
// -> for each cluster and each captured image: reproject, take the fruitlet segment it falls
// on, convex hull, least-squares ellipse, Eq. 4 (size = minor axis * baseline / max
// disparity in a window at the segment's centre).
//
// Two estimators from the same per-image measurements (both are always computed and kept):
// - paper: the cluster's centroid, and the largest per-image Eq. 4 size;
// - ours (default): corrects Eq. 4's two known biases (the hull runs through boundary-pixel
//   centres, ~0.6 px short across; the window's maximum disparity is the nearest surface, the
//   fruit's widest section is ~r farther: s = m z / (f - m / 2)), takes the median over the
//   images where the segment is well seen (mostly unoccluded, off the image border, not
//   shared with another cluster, round as a fruitlet projects) instead
//   of the maximum, which turns per-image noise into an upward bias, and places the centre by
//   a sphere fit to the surface points instead of the one-sided centroid. Where its segment
//   merges with a neighbour's in every view, the sphere fit's diameter is its size.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "fvp/host/core/stereo_intrinsics.h"
#include "fvp/host/sizing/instance_split.h"
#include "fvp/host/sizing/sizing_view.h"
#include "fvp/host/sizing/sphere_ransac.h"

namespace fvp::host::sizing {

enum class SizingEstimator { kOurs, kPaper };
const char* toString(SizingEstimator estimator);
/// "ours" or "paper"; throws std::invalid_argument otherwise.
SizingEstimator parseSizingEstimator(std::string_view name);

struct SizingConfig {
  SizingEstimator estimator = SizingEstimator::kOurs;
  int outlier_neighbours = 20;
  double outlier_std_ratio = 2.0;
  /// DBSCAN over 0.5 mm surface points: 2 mm separates fruitlets that do not touch (the
  /// authors' 1 cm merges neighbours in a cluster, which lie within a few mm).
  double dbscan_eps_m = 0.002;
  int dbscan_min_samples = 10;
  int min_cluster_points = 30;  ///< smaller clusters are dropped (counted)
  /// Split DBSCAN clusters that hold more than one fruitlet (sphere_ransac.h): touching
  /// fruitlets, bridged by stereo points at the depth edges between them, merge otherwise.
  bool split_merged_clusters = true;
  /// Where the views carry instance ids (instance_split.h): split DBSCAN clusters that fall
  /// on two instances or more, and merge overlapping detections that fall on one.
  bool use_instances = true;
  InstanceSplitConfig instance_split;
  int disparity_window_half_px = 5;     ///< Eq. 4's square window: (2h+1)^2 pixels
  double saturated_disparity_px = 318;  ///< window maxima at or above: rejected
  /// Window maxima implying a depth beyond this are invalid (SGBM speckles where the window
  /// holds almost no disparity: 1.4 px, 38 m away, once made Eq. 4 read 1 m).
  double max_depth_m = 1.0;
  double min_visible_fraction = 0.2;  ///< of in-image points on the segment, to use an image
  double well_seen_fraction = 0.6;    ///< ours: images used for the median
  /// Ours: minor / major axis at least this (a fruitlet's e <= 1.15 projects rounder; a
  /// segment cut by an occluder or two fruitlets merged in 2-D does not).
  double min_axis_ratio = 0.8;
  int min_segment_pixels = 12;
  /// The support rule (docs/sizing.md, "Which detections are fruitlets"): a detection of
  /// radius r must show surface over at least this fraction of its sphere, 4 pi r^2. A
  /// quarter is pi r^2, the area of its own silhouette disc: half the hemisphere one
  /// unoccluded view sees. Phantoms (mask pixels that bled onto the leaf behind a fruitlet,
  /// small clusters of stereo points at depth edges) show a few percent of the sphere their
  /// size implies. 0 keeps every detection.
  double min_support_area_fraction = 0.25;
  /// The support rule for a detection sized by its sphere fit alone (every image's segment
  /// shared, SizeSource::kSphereFit): its size is then read off 3-D points only, and a sphere
  /// fitted to a cap smaller than a hemisphere extrapolates its diameter from the cap's
  /// curvature; once the points span a hemisphere they span the diameter itself. So it must
  /// show at least half its sphere (docs/sizing.md, "Sized by its 3-D surface alone"). The
  /// larger of the two fractions applies; 0 asks no more than min_support_area_fraction.
  double sphere_fit_support_area_fraction = 0.5;
  /// The surface points' spacing: the TSDF voxel (MappingSession sets its own). Zero
  /// crossings between face neighbours number (|n_x| + |n_y| + |n_z|) per voxel face on a
  /// surface of normal n: 1.5 on average over a sphere.
  double surface_voxel_size_m = 0.0005;
  /// The overlap rule (docs/sizing.md, "One fruitlet seen twice"): two detections whose
  /// spheres (our size, the sphere fit's centre) overlap by more than this fraction of the
  /// smaller radius are merged. Touching fruitlets overlap by 0; neighbours' measured centres
  /// err by up to ~1 mm each, half the radius of the smallest fruitlet. INFINITY: never.
  double max_detection_overlap_fraction = 0.5;
  /// The views' agreement (DetectionSupport::view_agreement): a view sees a point where its
  /// measured disparity within a pixel of the point's projection matches the point's own
  /// within this. SGBM resolves whole pixels (refined to 1/16); the fused surface is the
  /// average of many views: 1 px is 1.6 mm of depth at 0.3 m with the default rig.
  double view_agreement_disparity_px = 1.0;
  /// The agreement rule (docs/sizing.md, "Whether the views agree it is a fruitlet"): with
  /// views placed by the cluster's pose graph (registered_views), a detection that most of
  /// the views' evidence denies (view_agreement below this) and that fewer than two images
  /// size well (one image is one sample of its error) is not reported. Without
  /// registration a 1-2 mm pose error moves a point's projection past the pixel of
  /// tolerance, so the rule waits for registered views. 0: off.
  double min_view_agreement_registered = 0.5;
  /// Set by MappingSession: the views were placed by its pose graph.
  bool registered_views = false;
  void validate() const;
};

struct ImageSize {
  int view = 0;
  double size_paper_mm = 0.0;  ///< Eq. 4 as the paper
  double size_ours_mm = 0.0;   ///< with the hull and depth corrections
  double minor_axis_px = 0.0, max_disparity_px = 0.0;
  double visible_fraction = 0.0;  ///< of the cluster's in-image points on the segment
  bool touches_border = false;
  bool shared_segment = false;  ///< another cluster falls on the same segment
  double axis_ratio = 0.0;      ///< minor / major axis of the fitted ellipse
  /// The fitted ellipse (cv::fitEllipse on the segment's hull), in the image's pixels: its
  /// centre, full axis lengths (width, height before rotation) and rotation in degrees.
  std::array<double, 2> ellipse_center_px{}, ellipse_axes_px{};
  double ellipse_angle_deg = 0.0;
  /// Mostly visible, off the border, its own segment, round: one of ours' median's images.
  bool well_seen = false;
};

/// Where our estimator's size came from.
enum class SizeSource {
  kWellSeenImages,  ///< the median over the well-seen images
  kSphereFit,       ///< every segment merged with another's: the sphere fit's diameter
  kAllImages,       ///< neither: the median over every image that gave a size
};
const char* toString(SizeSource source);

/// What a detection rests on (every detection reports it).
struct DetectionSupport {
  int sized_images = 0;         ///< images that gave a size
  int own_segment_images = 0;   ///< of which no other detection fell on its segment
  int well_seen_images = 0;     ///< of which well seen (ours: the median's images)
  double sphere_rms_mm = -1.0;  ///< RMS distance of its points to its sphere; -1 without one
  /// The surface points the support rule asks of a fruitlet of its size (points must reach it).
  double required_points = 0.0;
  /// The fraction of its sphere required_points stands for: min_support_area_fraction, or
  /// sphere_fit_support_area_fraction when its size came from the sphere fit alone.
  double required_area_fraction = 0.0;
  /// Ours' confidence: the standard error of the median of its well-seen images' sizes
  /// (1.2533 x 1.4826 MAD / sqrt(n)); -1 with fewer than two.
  double size_stderr_mm = -1.0;
  int merged_detections = 0;  ///< detections the overlap rule merged into this one
  /// Whether the views that see its surface call it fruitlet. Over every view and point: a
  /// view sees the point where a measured disparity within a pixel of its projection
  /// matches the point's, and sees past it where every one is smaller (a farther surface
  /// shows through: the point is not there). Occluded points say nothing. Agreement: the
  /// seen points on fruitlet pixels (within a pixel, the masks' boundary) over the seen and
  /// seen-past ones; -1 when no view gave evidence. A fruitlet's surface agrees with the
  /// masks wherever it is seen; a leaf patch that a mask bled onto, or stereo points in the
  /// air at a depth edge, are seen as leaf or seen through from other directions.
  std::size_t view_evidence_points = 0;  ///< (point, view) pairs seen or seen past
  double view_agreement = -1.0;
  /// Dropped by the hemisphere rule alone: it shows the quarter, but its size is a sphere fit
  /// to less than a hemisphere. A view from another side confirms a real fruitlet (more of its
  /// surface, or its outline apart from the neighbour's); the loop may look for one.
  bool unconfirmed = false;
};

struct FruitletEstimate {
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  ///< the chosen estimator's
  double size_mm = 0.0;                                ///< the chosen estimator's
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero(), sphere_center_m = Eigen::Vector3d::Zero();
  double sphere_radius_m = 0.0;  ///< 0 when the sphere fit failed
  double size_paper_mm = 0.0, size_ours_mm = 0.0;
  SizeSource size_source = SizeSource::kWellSeenImages;
  std::size_t points = 0;
  DetectionSupport support;
  std::vector<ImageSize> per_image;
};

/// Expected events, counted.
struct SizingEvents {
  std::size_t small_clusters = 0;  ///< clusters under min_cluster_points (dropped)
  std::size_t invalid_disparity_windows = 0;
  std::size_t saturated_windows = 0;
  std::size_t not_visible = 0;  ///< (cluster, image) pairs: no segment under the points
  std::size_t single_image_fruitlets = 0;
  std::size_t unsized_clusters = 0;    ///< no image gave a size (dropped)
  std::size_t failed_sphere_fits = 0;  ///< centre fell back to the centroid
  std::size_t clusters_split_off = 0;  ///< parts of DBSCAN clusters split off (one per fruitlet)
  std::size_t instance_parts_split_off = 0;  ///< parts split off by the views' instances
  std::size_t unsupported_detections = 0;    ///< dropped: too little surface, or denied_by_views
  std::size_t denied_by_views = 0;           ///< of them, by the agreement rule (registered views)
  std::size_t overlapping_detections_merged = 0;  ///< one fruitlet seen twice (overlap rule)
};

struct SizingResult {
  std::vector<FruitletEstimate> fruitlets;
  /// Sized detections the support rule dropped, with their support (for reports).
  std::vector<FruitletEstimate> unsupported;
  SizingEvents events;
  std::size_t surface_points = 0, in_roi_points = 0, inlier_points = 0;
  std::vector<Eigen::Vector3f> points;  ///< after the ROI and outlier filters
  std::vector<int> labels;              ///< DBSCAN label per point (-1 noise)
};

/// The whole chain. in_roi_voxel: whether a point lies in an ROI-occupied fine voxel (null:
/// keep every point).
SizingResult sizeFruitlets(const std::vector<SizingView>& views,
                           const std::vector<Eigen::Vector3f>& surface_points_m,
                           const std::function<bool(const Eigen::Vector3f&)>& in_roi_voxel,
                           const SizingConfig& config);

/// The same, with the views' segments from a caller that keeps them (a session computes each
/// view's once, segmentsOf): segments[i] those of views[i]; a view past the end of segments,
/// or with a null entry, is segmented here.
SizingResult sizeFruitlets(const std::vector<SizingView>& views,
                           const std::vector<std::shared_ptr<const ViewSegments>>& segments,
                           const std::vector<Eigen::Vector3f>& surface_points_m,
                           const std::function<bool(const Eigen::Vector3f&)>& in_roi_voxel,
                           const SizingConfig& config);

/// Moves the detections' centres (kept and unsupported) by shift_m; sizes and the clustered
/// points are unchanged.
void translateDetections(SizingResult& result, const Eigen::Vector3d& shift_m);

/// A distinct colour per DBSCAN label (grey for noise), for clusters.ply.
std::vector<std::array<std::uint8_t, 3>> clusterColours(const std::vector<int>& labels);

}  // namespace fvp::host::sizing
