// Parameters of world generation (docs/design.md section 8). Every field is a documented YAML
// key of the same name; the defaults reproduce the paper's protocol. The keys, their units
// and ranges are listed in robot/sim/config/world_default.yaml and docs/simulation.md.
//
// API CONTRACT: the fields below are the minimum; more may be added (documented).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace fvp::robot::sim {

/// The last day a season may be visited (season_day's range): by then the fruitlets are
/// apples and the thinning decision long made.
inline constexpr double kMaxSeasonDay = 60.0;

struct WorldConfig {
  // Cluster
  int min_fruitlets = 3;
  int max_fruitlets = 6;
  double min_radius_m = 0.003;  ///< r ~ U(min_radius_m, max_radius_m)
  double max_radius_m = 0.008;
  double min_elongation = 0.85;  ///< e ~ U(min_elongation, max_elongation)
  double max_elongation = 1.15;
  double cluster_spread_m = 0.03;  ///< fruitlet centres within this of the cluster centre
  double min_gap_m = 0.001;        ///< fruitlets at least this far apart (surface to surface)
  // Leaves
  int leaf_count = 30;
  double min_leaf_length_m = 0.04, max_leaf_length_m = 0.08;
  double min_leaf_width_m = 0.02, max_leaf_width_m = 0.04;
  double leaf_region_m = 0.15;       ///< leaves placed within this of the cluster centre
  double max_leaf_curl_per_m = 6.0;  ///< curled leaves: z = c x^2, |c| ~ U(0, this); half are flat
  /// Fraction of the leaves placed between the start view and the cluster (the rest fill the
  /// leaf region uniformly), so the cluster starts substantially occluded.
  double front_leaf_fraction = 0.3;
  // AprilTag
  int tag_id = 0;
  double tag_size_m = 0.03;
  /// Tag centre to cluster centre, ~ U(min, max). A grower hangs the tag at a consistent
  /// spot beside the cluster, so the Cluster Region placed from it can be tight.
  double min_tag_distance_m = 0.065;
  double max_tag_distance_m = 0.075;
  double max_tag_tilt_deg = 5.0;  ///< random tilt of the tag away from facing the start view
  /// Side of the cluster the tag hangs on, along the fruiting branch: +1 right of it as the
  /// start view sees it, -1 left, 0 either side at random (the Cluster Region placed from the
  /// tag must then be about twice as large).
  int tag_side = 1;
  // Tree
  double trunk_radius_m = 0.05;
  double trunk_height_m = 2.0;
  double cluster_height_m = 1.0;  ///< height of the fruiting branch above the trunk base
  double branch_radius_m = 0.01;  ///< the fruiting branch
  int extra_branch_count = 3;     ///< further branches (background clutter)
  // Clusters (a tree rather than one cluster; docs/simulation.md "Worlds of several clusters")
  /// Clusters on the tree, each on its own fruiting branch with its own tag (tag_id + k)
  /// and leaf_count leaves; 1 is the paper's world.
  int cluster_count = 1;
  /// Cluster centres at least this far apart (several clusters only).
  double min_cluster_spacing_m = 0.2;
  /// Fruiting branches leave the trunk within cluster_height_m +- half this (several
  /// clusters only; one cluster's branch leaves at cluster_height_m).
  double cluster_height_spread_m = 0.3;
  // Start view
  double start_view_distance_m = 0.3;
  // Pose errors (docs/simulation.md "Pose errors"): the camera renders from the true pose and
  // the robot is told another. All 0: exact poses (the paper's simulation).
  double hand_eye_translation_sigma_m = 0.0;  ///< per axis, fixed per trial
  double hand_eye_rotation_sigma_deg = 0.0;   ///< per rotation-vector component, per trial
  /// Per-axis RMS of the arm's smooth, position-dependent positioning error (the absolute
  /// accuracy of an uncalibrated arm).
  double arm_position_error_m = 0.0;
  double view_translation_sigma_m = 0.0;  ///< per axis, each view (repeatability)
  double view_rotation_sigma_deg = 0.0;   ///< per rotation-vector component, each view
  // Stereo calibration (docs/simulation.md "Stereo calibration"); 0: a perfect rig.
  double stereo_baseline_error = 0.0;  ///< true baseline / nominal - 1 (0.005: 0.5 % longer)
  /// A point's row in the right image minus its row in the left, after rectification.
  double stereo_vertical_misalignment_px = 0.0;
  // Wind (docs/simulation.md "Wind"): between views leaves and fruitlets move; ground truth
  // is the rest pose. 0: a still canopy.
  /// RMS displacement of a leaf's tip as it turns about its attachment, each view.
  double wind_leaf_tip_m = 0.0;
  /// Largest displacement of a fruitlet swinging on its stem (horizontal), each view.
  double wind_fruitlet_swing_m = 0.0;
  // Appearance and segmentation (docs/simulation.md "Appearance and segmentation").
  /// Fraction of fruitlets painted a leaf-like green (real fruitlets at thinning time are
  /// green); the HSV segmentation cannot see those, the segmentation model can.
  double fruitlet_green_fraction = 0.0;
  /// 1: the camera hands over a fruitlet mask from a segmentation model standing in for a
  /// trained network (the renderer's instance masks with the errors below) and HSV does
  /// not run; 0: no mask (HSV segmentation, the paper's).
  int segmentation_model = 0;
  /// 1: the model's mask is an instance segmentation (CV_16U, one id per fruitlet), as
  /// Mask R-CNN or YOLOv8-seg hand over; 0: a binary mask (touching fruitlets merge).
  int segmentation_instances = 1;
  /// RMS of the mask boundary's displacement, pixels (smooth along the boundary).
  double segmentation_boundary_px = 0.0;
  /// Probability that a visible fruitlet is missing from a view's mask.
  double segmentation_miss_rate = 0.0;
  /// Mean number of false fruitlet blobs on leaves per view (Poisson).
  double segmentation_false_blobs = 0.0;
  /// Ambient light (docs/simulation.md "Ambient light"): the sun's irradiance in units of the
  /// flash's at its full-scale distance (0: the flash alone); its direction is drawn per
  /// trial, and the sky adds kSkyToSunRatio of it as diffuse light.
  double sun_strength = 0.0;
  // A season (docs/simulation.md "A season"): the world as it has grown season_day days after
  // the first visit; 0 is the world as generated. The growth draws come from a stream of
  // their own, so the day-0 world is the same for any season keys.
  double season_day = 0.0;
  /// The diameter growth rate of the season's fastest-growing fruitlets, drawn per world
  /// (every cluster of a tree shares the weather): about 1 mm a day in a warm week, 0.4 in a
  /// cold one.
  double min_fastest_growth_mm_per_day = 0.4;
  double max_fastest_growth_mm_per_day = 1.0;
  /// The chance that a fruitlet other than its cluster's king (its largest) is bound to drop.
  double abscission_probability = 0.6;
  /// How the world is meant to be run, not how it is built: 1 = with view registration
  /// (`fvp run --register-views`), what a preset with pose errors needs; a run that says
  /// --register-views or --no-register-views decides itself.
  int run_register_views = 0;

  /// Reads a YAML file; missing keys keep their defaults; unknown keys, wrong types and
  /// out-of-range values throw std::invalid_argument naming the file and the key.
  static WorldConfig fromYamlFile(const std::filesystem::path& path);
  /// Throws std::invalid_argument naming the first bad key and its expected range.
  void validate(const std::string& source = "world config") const;
  /// This config with the magnitudes of one group of simulated errors times factor (>= 0),
  /// for sweeps (docs/simulation.md "Sweeping an error"): pose (hand_eye_*,
  /// arm_position_error_m, view_*), stereo (stereo_*), wind (wind_*), segmentation
  /// (segmentation_boundary_px, _miss_rate, _false_blobs; not the switches segmentation_model
  /// and fruitlet_green_fraction), light (sun_strength), or all. Throws std::invalid_argument
  /// for an unknown group, a bad factor, or a factor that takes a magnitude out of its key's
  /// range (naming the key, the value, the limit and the largest factor that fits): a
  /// clamped magnitude would be a sweep point at another factor than the one recorded.
  WorldConfig withErrorsScaled(const std::string& group, double factor) const;
  /// The groups withErrorsScaled takes, "all" last.
  static const std::vector<std::string>& errorGroups();
  /// Every YAML key, in declaration order (the same names as the fields).
  static const std::vector<std::string>& keyNames();
  /// The config as a JSON object text {key: value, ...} (for ground truth and results).
  std::string toJson() const;

  /// Field by field (defaulted in world_config.cpp: the C++17 ROS layer includes this header).
  friend bool operator==(const WorldConfig&, const WorldConfig&);
};

}  // namespace fvp::robot::sim
