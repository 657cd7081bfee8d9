// The per-view mapping session (docs/design.md section 5): one stereo view at a time through
// perception into the maps, so that the trial loop, `fvp map` and capture replay share one
// path. The session owns the perception pipeline, the Cluster Region (from the first view
// whose AprilTag is detected) and the map engine, created once the region is known. Views
// seen before that are kept and integrated, in order, as soon as the region is known.
#pragma once

#include <cstddef>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fvp/host/core/cluster_region.h"
#include "fvp/host/core/labeled_clouds.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/perception/stereo_frame.h"
#include "fvp/host/session/cluster_pose_graph.h"
#include "fvp/host/session/view_registration.h"
#include "fvp/host/sizing/fruitlet_sizer.h"
#include "fvp/host/tsdf/tsdf_volume.h"

namespace fvp::accel {
class Backend;
}

namespace fvp::host {

/// What one view did. scan stays empty until the view is in the map: a view seen before
/// the region was known gets its scan when a later view detects the tag (see views()).
struct ViewResult {
  std::size_t index = 0;  ///< position of the view in the session
  Eigen::Isometry3d T_world_camera_told = Eigen::Isometry3d::Identity();  ///< the frame's pose
  bool tag_detected = false;
  std::optional<TagDetection> tag;  ///< the cluster's tag as this view saw it
  std::size_t roi_points = 0, other_points = 0;
  double perceive_s = 0.0;  ///< wall time of the perception pipeline alone
  PerceptionStats perception;
  bool integrated = false;  ///< the view's clouds are in the map
  map::ScanStats scan;
  /// Earlier views this call integrated (the region became known with this view).
  std::size_t earlier_views_integrated = 0;
  /// TSDF integration of this view's ROI depth (0 without a TSDF), and of every view again
  /// when this view's solve moved them (ViewRegistrationConfig::refuse_tsdf_beyond_m).
  double tsdf_s = 0.0;
  /// With view registration on and the region known: the alignment tried for this view.
  std::optional<RegistrationResult> registration;
};

class MappingSession {
 public:
  /// engine: "grid" (needs backend, which must outlive the session) or "octomap" (backend
  /// ignored). Throws std::invalid_argument for an unknown engine, a grid engine without a
  /// backend or a bad config, before any view is processed.
  MappingSession(PerceptionConfig perception, std::string engine, map::MapConfig map_config,
                 accel::Backend* backend);

  /// Perceives one view and integrates it (and any views kept from before the region was
  /// known) into the map. perceived (optional) receives the view's perception result (the
  /// mask and disparity that TSDF integration and sizing use), its clouds moved out. Those
  /// images (and a frame's instance mask) are the session's own from then on: read them, do
  /// not change their pixels.
  ViewResult addView(const StereoFrame& frame, PerceptionResult* perceived = nullptr);

  /// Null / empty until a view's tag was detected.
  const std::optional<ClusterRegion>& region() const { return region_; }
  /// The tag's pose in the maps' frame: as the view that placed the region saw it, or with
  /// the pose graph its estimate from every view that saw it; empty until the region is
  /// placed, or when no tag was seen.
  const std::optional<Eigen::Isometry3d>& T_world_tag() const { return T_world_tag_; }
  map::MapEngine* map() { return map_.get(); }
  const map::MapEngine* map() const { return map_.get(); }
  /// Every view so far, with the scans of views integrated after they were added.
  const std::vector<ViewResult>& views() const { return views_; }
  /// Views waiting for the region.
  std::size_t pendingViews() const { return pending_.size(); }
  const PerceptionPipeline& perception() const { return perception_; }

  /// From now on every view is kept for sizing (its fruitlet mask, disparity, intrinsics and
  /// pose) and its ROI depth is fused into a TSDF over the Cluster Region's cube (on the
  /// session's backend; a cpu backend of its own without one), from the view whose tag
  /// places the region on, earlier views included.
  void enableTsdf(const tsdf::TsdfConfig& config = {});
  /// Aligns each view's points in the Cluster Region to the earlier views' before fusing it
  /// (view_registration.h); the first views, up to the one that places the region, anchor
  /// the model. Off unless called. Throws std::invalid_argument for a bad config.
  void enableViewRegistration(const ViewRegistrationConfig& config = {});
  bool tsdfEnabled() const { return tsdf_config_.has_value(); }
  /// Null until enableTsdf() was called and the region is known.
  const tsdf::TsdfVolume* tsdf() const { return tsdf_.get(); }
  /// The TSDF's surface points; empty while there is no TSDF.
  std::vector<Eigen::Vector3f> surfacePoints() const;
  /// The TSDF's zero level set as a mesh (marching cubes); empty while there is no TSDF.
  tsdf::TriangleMesh surfaceMesh() const;
  const std::vector<sizing::SizingView>& sizingViews() const { return sizing_views_; }
  /// How often the TSDF was fused again (ViewRegistrationConfig::refuse_tsdf_beyond_m).
  std::size_t tsdfRefusions() const { return tsdf_refusions_; }
  /// The sizing chain on the session's TSDF surface and views, keeping surface points in
  /// ROI-occupied fine voxels. Needs enableTsdf(); without a map no point is kept. With view
  /// registration and its correct_anchor_offset, the detections' positions (centres) are
  /// moved by anchorOffset().shift_m, back into the world as well as the views tell; the
  /// maps, the TSDF and the clustered points stay in the registered maps' frame.
  sizing::SizingResult sizeFruitlets(const sizing::SizingConfig& config) const;
  /// The same, every position in the registered maps' frame (what a rule that compares
  /// sizings over time needs: the offset's estimate changes as views arrive).
  sizing::SizingResult sizeFruitletsInMapFrame(const sizing::SizingConfig& config) const;

  /// With view registration on: where the registered maps (the anchor views' frame) sit off
  /// the world, from the corrections registration applied (view_registration.h,
  /// estimateAnchorOffset); with ViewRegistrationConfig::correct_anchor_offset,
  /// sizeFruitlets() reports positions moved by its shift. Zero without registration.
  AnchorOffset anchorOffset() const;
  /// The cluster's pose graph (registration with use_pose_graph); null otherwise.
  const ClusterPoseGraph* poseGraph() const { return pose_graph_ ? &*pose_graph_ : nullptr; }
  /// Whether sizeFruitlets() reports positions corrected by anchorOffset().
  bool correctsAnchorOffset() const {
    return registration_ && registration_->config().correct_anchor_offset;
  }
  /// The shift sizeFruitlets() moves positions by: anchorOffset().shift_m when it corrects
  /// them, else zero.
  Eigen::Vector3d appliedAnchorShift_m() const {
    return correctsAnchorOffset() ? anchorOffset().shift_m : Eigen::Vector3d::Zero();
  }

  /// Hands the map over (or the carried one it never needed: no view showed its tag); the
  /// session is done with it.
  std::unique_ptr<map::MapEngine> releaseMap() && {
    return map_ ? std::move(map_) : std::move(carried_map_);
  }
  /// The map of an earlier session (the previous cluster of a run over a tree) to carry on
  /// with: when this session's region becomes known, the map's fine map moves to it and
  /// its coarse map keeps what was seen (MapEngine::moveToRegion). The map's config is
  /// used as it is. Call before the region is known; throws std::invalid_argument for
  /// another engine than the session's, std::logic_error when the session has a map.
  void carryOnWith(std::unique_ptr<map::MapEngine> map);

 private:
  void integrate(std::size_t index, const LabeledClouds& clouds);
  /// The clouds' points inside the Cluster Region (none before it is known).
  std::vector<Eigen::Vector3f> pointsInRegion(const LabeledClouds& clouds) const;
  static void moveClouds(LabeledClouds& clouds, const Eigen::Isometry3d& T);
  /// Registration of a view once the region is known: where it is fused (the correction its
  /// clouds were moved by is applied to them here).
  RegistrationResult registerView(std::size_t index, LabeledClouds& clouds);
  /// T_world_tag_ from the pose graph's estimate, when it has one.
  void refreshTagFromPoseGraph();
  /// An empty TSDF over the Cluster Region's cube (the region must be known).
  std::unique_ptr<tsdf::TsdfVolume> newTsdf() const;
  /// Fuses sizing_views_[i] into the TSDF; returns the seconds it took.
  double integrateTsdf(std::size_t sizing_view);
  /// ViewRegistrationConfig::refuse_tsdf_beyond_m: fuses the TSDF again with every view
  /// where the pose graph now places it, when one has moved that far; the seconds it took.
  double refuseTsdfWhereViewsMoved();

  PerceptionPipeline perception_;
  std::string engine_;
  map::MapConfig map_config_;
  accel::Backend* backend_;
  std::optional<ClusterRegion> region_;
  std::optional<Eigen::Isometry3d> T_world_tag_;
  std::unique_ptr<map::MapEngine> map_;
  std::unique_ptr<map::MapEngine> carried_map_;  ///< until the region is known
  std::vector<ViewResult> views_;
  // Clouds of views seen before the region was known, with the index of their view.
  std::vector<std::pair<std::size_t, LabeledClouds>> pending_;
  std::optional<tsdf::TsdfConfig> tsdf_config_;
  std::optional<ViewRegistration> registration_;
  std::optional<ClusterPoseGraph> pose_graph_;
  std::unique_ptr<tsdf::TsdfVolume> tsdf_;
  std::vector<sizing::SizingView> sizing_views_;
  /// The segments of sizing_views_, each computed by the first sizing that reads it (the
  /// masks do not change: addView).
  std::vector<std::shared_ptr<const sizing::ViewSegments>> viewSegments() const;
  mutable std::mutex segments_mutex_;
  mutable std::vector<std::shared_ptr<const sizing::ViewSegments>> view_segments_;
  std::size_t tsdf_refusions_ = 0;
};

}  // namespace fvp::host
