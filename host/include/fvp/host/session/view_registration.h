// Registration of each view to the views before it (docs/sizing.md "Registering views"): a
// robot's told camera poses are off by its hand-eye calibration and arm accuracy, about a
// millimetre, the size of the sizing error budget, and the error differs from view to view.
// Before a view is fused, its points in the Cluster Region are aligned to a model of the
// earlier views' points there by point-to-plane ICP; the correction is applied only
// when it is small (a calibration error, not a wrong match), enough pairs support it and it
// lowers their RMS. Expected outcomes are statuses, never exceptions.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_set>
#include <vector>

#include "fvp/host/session/cluster_pose_graph.h"

namespace fvp::host {

struct ViewRegistrationConfig {
  /// Both clouds are thinned to one point per voxel of this size: the fine map's 1 mm.
  double voxel_m = 0.001;
  /// Pairs farther apart than this are not the same surface: views taken from opposite
  /// sides disagree by up to twice a calibrated robot's 1-2 mm pose error, plus a voxel.
  double max_pair_distance_m = 0.005;
  int max_iterations = 30;
  /// A correction that moves the view's points farther than this, or turns them more, is a
  /// wrong match rather than a calibration error: not applied.
  double max_translation_m = 0.008;
  double max_rotation_deg = 0.5;
  /// false: translation only. A camera's rotation error of a few tenths of a degree moves
  /// the cluster 0.3 m away by ~1 mm as a whole but its 6.5 cm region by only ~0.2 mm
  /// relative to itself, below the 1 mm voxel: a translation captures it, and three degrees
  /// of freedom are better constrained by a partial overlap than six (which, tried first,
  /// turned views by 1-1.5 degrees where the true error was 0.18).
  bool estimate_rotation = false;
  /// Fewer pairs than this constrain six degrees of freedom too weakly to trust.
  std::size_t min_pairs = 300;
  /// The pairs' RMS must fall by at least this fraction.
  double min_rms_reduction = 0.1;
  /// Report positions corrected by the estimated offset of the anchor's frame from the world
  /// (estimateAnchorOffset) rather than in the anchor's frame.
  bool correct_anchor_offset = true;
  /// The estimate's prior on the hand-eye term, per axis: a calibrated arm's hand-eye
  /// residual seen at the cluster, a millimetre or two (the field preset's 1.5 mm per axis,
  /// and 0.3 degrees turning points 0.3 m away by 1.6 mm, about 2.2 mm together). Measured
  /// on 10 field worlds, 1-3 mm gave the same.
  double hand_eye_prior_sigma_m = 0.002;
  /// true: each view is placed where the cluster's pose graph (cluster_pose_graph.h) puts it
  /// (the told pose, the hand-eye error the views have told so far, the tag and the earlier
  /// views' alignments), then aligned from there; an alignment the graph does not expect is
  /// not applied (kDisagrees), and the maps' frame error is the graph's. false: each view is
  /// aligned from its told pose and the frame's error is estimateAnchorOffset's.
  bool use_pose_graph = true;
  PoseGraphConfig pose_graph;
  /// With the pose graph: once the graph, solved after a view, moves an earlier view's
  /// placement by more than this since the view was fused into the TSDF, the TSDF is fused
  /// again from every view where the graph now places it (its time charged as the view's
  /// TSDF time). A view fused a millimetre off its neighbours blurs the fruitlet's surface,
  /// and its sphere's centre with it. 0: off (each view stays where it was first fused).
  double refuse_tsdf_beyond_m = 0.00025;

  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
};

enum class RegistrationStatus {
  kApplied,
  kNoModel,        ///< no earlier view to align to (the first views)
  kTooFewPairs,    ///< fewer than min_pairs pairs within max_pair_distance_m
  kBeyondBounds,   ///< the correction was larger than a calibration error
  kNoImprovement,  ///< the pairs' RMS did not fall by min_rms_reduction
  /// The alignment moved the view farther from where the pose graph placed it than the
  /// graph's uncertainty allows: a wrong match, not applied (the graph's placement stands).
  kDisagrees,
};
std::string toString(RegistrationStatus status);

struct RegistrationResult {
  RegistrationStatus status = RegistrationStatus::kNoModel;
  /// World-frame correction: p_aligned = correction * p (identity unless applied; with the
  /// pose graph, the whole placement the view was fused with).
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  double translation_m = 0.0;  ///< how far the correction moves the view's centroid
  /// The correction's displacement of the view's centroid (with rotation estimated, the
  /// correction's translation is the world origin's, a metre away).
  Eigen::Vector3d centroid_shift_m = Eigen::Vector3d::Zero();
  double rotation_deg = 0.0;
  double rms_before_m = 0.0, rms_after_m = 0.0;
  std::size_t pairs = 0;
  int iterations = 0;
  /// With the pose graph: where the graph placed the view before it was aligned, and the
  /// whole translation its points were fused with (the graph's placement and the alignment's
  /// refinement; `correction` is this translation).
  std::optional<Eigen::Vector3d> predicted_m;
  Eigen::Vector3d placement_m = Eigen::Vector3d::Zero();
};

/// A view as registration left it: the orientation it was told and what registration did.
struct RegisteredView {
  Eigen::Matrix3d R_world_camera = Eigen::Matrix3d::Identity();
  RegistrationResult registration;
};

/// Where the registered maps (the anchor views' frame) sit off the world, at the cluster.
struct AnchorOffset {
  /// What to add to a registered position to put it in the world: the anchor's error.
  Eigen::Vector3d shift_m = Eigen::Vector3d::Zero();
  /// The hand-eye term: the constant camera-frame displacement of points at the cluster.
  Eigen::Vector3d hand_eye_m = Eigen::Vector3d::Zero();
  std::size_t views = 0;  ///< views whose offset from the anchor is known
  /// False (and the shift zero) with fewer than two views, a fit that failed, or a shift
  /// beyond max_shift_m: nothing to correct by.
  bool valid = false;
};

/// The anchor's error at the cluster from the corrections registration measured
/// (docs/sizing.md "Where the registered map sits"). View k's error there is
/// e_k = R_k u + a_k: a hand-eye error displaces the cluster by a constant u in the camera's
/// frame (R_k its told orientation), the arm's error a_k varies from view to view. Its
/// correction is c_k = e_k - e_anchor, so c_k = R_k u - e_anchor + noise. Least squares over
/// the views whose offset is known (the anchors and views that needed none, kNoModel and
/// kNoImprovement, with c = 0; the aligned ones, kApplied), with a Gaussian prior of
/// hand_eye_prior_sigma_m per axis on u and the noise's variance estimated from the fit's
/// residuals, gives e_anchor; where the views' directions cannot tell u apart, the prior
/// keeps it small and the estimate falls back to the views' mean frame. Views that could not
/// be aligned (kTooFewPairs, kBeyondBounds) are left out; each correction is taken where it
/// moved the view's points (RegistrationResult::centroid_shift_m). The noise is floored at
/// registration's own precision (kMinCorrectionNoiseM). With fewer than four views,
/// u = 0 (too few residuals to estimate the noise from): the views' mean frame. Invalid with
/// fewer than two views or a shift over max_shift_m (a calibration is not that far off).
AnchorOffset estimateAnchorOffset(const std::vector<RegisteredView>& views,
                                  double hand_eye_prior_sigma_m, double max_shift_m);

/// Registration's own precision per axis: exact views' corrections agree with the true ones
/// to about 0.2 mm (view_registration_test.cpp).
inline constexpr double kMinCorrectionNoiseM = 0.0002;

class ViewRegistration {
 public:
  explicit ViewRegistration(ViewRegistrationConfig config = {});
  const ViewRegistrationConfig& config() const { return config_; }

  /// The correction that aligns view_points_m (world frame, as the told pose put them) to the
  /// model; the model is not changed.
  RegistrationResult align(const std::vector<Eigen::Vector3f>& view_points_m) const;
  /// Adds points (aligned) to the model, one per voxel.
  void addToModel(const std::vector<Eigen::Vector3f>& points_m);
  std::size_t modelSize() const { return model_.size(); }

 private:
  ViewRegistrationConfig config_;
  std::vector<Eigen::Vector3f> model_;
  std::unordered_set<std::uint64_t> model_voxels_;
};

}  // namespace fvp::host
