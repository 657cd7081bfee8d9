// One estimate of where a cluster's views really were (docs/sizing.md "The cluster's pose
// graph"): the robot's told poses are off by its hand-eye calibration (one rigid error in the
// camera's frame, the same in every view) and its arm's absolute accuracy (a world-frame
// offset that differs from view to view). Every view is a prior on both; each view that sees
// the cluster's AprilTag measures its pose relative to the tag (the tag's corners in the
// image), and each view aligned to the earlier views' points (view_registration.h) measures
// its offset relative to theirs. The graph is solved with Ceres after every view, so a view
// is placed where all of these agree, not where one alignment to the views before it put it:
// an alignment that slid into a wrong match is outvoted, and the hand-eye error, once the
// views' directions tell it, is taken out of every view before it is aligned.
//
// Model: view k's true pose is T_k = Trans(a_k) * T_told_k * H with H = (R(w), t) the
// hand-eye error and a_k the arm's offset; to first order, a point the told pose put at the
// cluster's centre is off the truth by e_k = a_k + R_told_k (w x q_k + t), q_k the centre in
// the view's camera frame. A view's placement C_k is the translation its points were moved by
// when fused; the fused maps' frame is off the world by the mean of e_j - C_j over the views
// in them, the error every reported position carries unless it is corrected.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <vector>

#include "fvp/host/core/stereo_intrinsics.h"
#include "fvp/host/perception/tag_detection.h"

namespace fvp::host {

struct PoseGraphConfig {
  /// The hand-eye calibration's accuracy, per axis (a prior on H). Defaults: a calibrated
  /// UR5e's residuals (Enebuse et al. 2022), as the field preset's sources.
  double hand_eye_translation_sigma_m = 0.0015;
  double hand_eye_rotation_sigma_deg = 0.3;
  /// The arm's absolute positioning accuracy per axis (a prior on each a_k): 0.2-2 mm for
  /// 6-axis arms; a UR5 measured to ISO 9283 about 1 mm (Semjon et al. 2024).
  double arm_position_sigma_m = 0.001;
  /// One alignment's precision per axis: exact views' corrections agree with the true ones to
  /// about 0.2 mm (view_registration_test.cpp); 0.3 mm allows for the earlier views' own spread.
  double alignment_sigma_m = 0.0003;
  /// A detected tag corner's pixel error: libapriltag's corners on the simulator's 1440x1080
  /// renders, measured on exact-pose views (cluster_pose_graph_test.cpp), with margin.
  double tag_corner_sigma_px = 0.5;
  /// Residuals beyond this many sigmas are down-weighted (Huber), and a view whose alignment
  /// or tag residual, as an RMS per component, lies beyond it counts as disagreeing with the
  /// rest (a view whose alignment was refused, RegistrationStatus::kDisagrees, is placed
  /// where the graph predicts it and so does not).
  double outlier_sigmas = 3.0;

  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
};

/// One view as the graph holds it.
struct PoseGraphView {
  Eigen::Isometry3d T_world_camera_told = Eigen::Isometry3d::Identity();
  std::optional<TagDetection> tag;  ///< the cluster's tag, when the view saw it
  StereoIntrinsics intrinsics;
  /// Placed: fused into the maps with its points moved by placement_m.
  bool placed = false;
  Eigen::Vector3d placement_m = Eigen::Vector3d::Zero();
  /// The views its alignment was measured against (the maps it was aligned to); empty when
  /// it was not aligned.
  std::vector<std::size_t> aligned_to;
};

/// What the graph says of one view after a solve.
struct PoseGraphViewEstimate {
  /// Normalised residuals (in sigmas, RMS over the factor's components); negative: no factor.
  double alignment_sigmas = -1.0;
  double tag_sigmas = -1.0;
  bool disagrees = false;  ///< a residual beyond outlier_sigmas
};

class ClusterPoseGraph {
 public:
  /// tag_size_m: the edge of the tag's black square (TagDetection's frame).
  ClusterPoseGraph(PoseGraphConfig config, double tag_size_m);
  const PoseGraphConfig& config() const { return config_; }

  /// The cluster's centre, where errors are measured: before it is set nothing is solved.
  void setClusterCentre(const Eigen::Vector3d& centre_m) { centre_m_ = centre_m; }
  bool hasClusterCentre() const { return centre_m_.has_value(); }

  /// Adds a view (not yet placed); returns its index. A tag of another id than the first
  /// one seen is left out.
  std::size_t addView(const Eigen::Isometry3d& T_world_camera_told,
                      const std::optional<TagDetection>& tag, const StereoIntrinsics& intrinsics);
  /// Records where view k was fused: its points moved by placement_m, aligned against the
  /// views in aligned_to (empty: not aligned, no measurement).
  void place(std::size_t k, const Eigen::Vector3d& placement_m,
             std::vector<std::size_t> aligned_to);

  /// Solves for the hand-eye error, every view's arm offset and the tag's pose.
  void solve();
  /// The placement that puts view k where the placed views say it belongs (the fused maps'
  /// frame) as of the last solve: e_k minus the maps' frame error.
  Eigen::Vector3d predictedPlacement(std::size_t k) const;
  /// Per axis, the standard deviation of predictedPlacement(k) from the last solve's
  /// linearisation (the hand-eye error's and the arm offsets' uncertainty together).
  Eigen::Vector3d predictedPlacementSigma(std::size_t k) const;
  /// The fused maps' frame error: what to add to a position in the maps to put it in the
  /// world, as the views tell (zero with no placed view).
  Eigen::Vector3d mapFrameError_m() const;
  /// The hand-eye error's displacement of the cluster's centre, in the camera frame.
  Eigen::Vector3d handEyeAtCentre_m() const;
  /// The tag's pose in the world as estimated; empty until a view saw the tag.
  std::optional<Eigen::Isometry3d> T_world_tag() const;

  std::size_t size() const { return views_.size(); }
  std::size_t placedViews() const;
  const PoseGraphView& view(std::size_t k) const { return views_.at(k); }
  const PoseGraphViewEstimate& estimate(std::size_t k) const { return estimates_.at(k); }

 private:
  Eigen::Vector3d errorAtCentre(std::size_t k) const;
  Eigen::Vector3d centreInCamera(std::size_t k) const;

  PoseGraphConfig config_;
  double tag_size_m_;
  std::optional<Eigen::Vector3d> centre_m_;
  std::vector<PoseGraphView> views_;
  std::vector<PoseGraphViewEstimate> estimates_;
  // Parameters: the hand-eye rotation vector and translation, the tag's pose (rotation
  // vector, translation; world), and each view's arm offset.
  Eigen::Vector3d hand_eye_rotation_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d hand_eye_translation_m_ = Eigen::Vector3d::Zero();
  std::optional<Eigen::Matrix<double, 6, 1>> tag_pose_;
  std::optional<int> tag_id_;  ///< the tag the graph follows: the first one a view saw
  std::vector<Eigen::Vector3d> arm_offsets_m_;
  // Marginal covariance of (w, t, a_0..a_n) from the last solve.
  Eigen::MatrixXd covariance_;
};

}  // namespace fvp::host
