#include "fvp/host/session/mapping_session.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace fvp::host {

MappingSession::MappingSession(PerceptionConfig perception, std::string engine,
                               map::MapConfig map_config, accel::Backend* backend)
    : perception_(std::move(perception), backend),
      engine_(std::move(engine)),
      map_config_(std::move(map_config)),
      backend_(backend) {
  // The engine is only created with the region, possibly many views later: check now what
  // createMapEngine would reject then.
  map::checkMapEngineChoice(engine_, backend_);
  map_config_.validate();
}

void MappingSession::carryOnWith(std::unique_ptr<map::MapEngine> map) {
  if (!map) throw std::invalid_argument("MappingSession::carryOnWith: no map");
  if (map_ || carried_map_)
    throw std::logic_error("MappingSession::carryOnWith: the session already has a map");
  if (map->engineName() != engine_)
    throw std::invalid_argument("MappingSession::carryOnWith: the map is a '" +
                                std::string(map->engineName()) + "' engine, the session's is '" +
                                engine_ + "'");
  carried_map_ = std::move(map);
}

ViewResult MappingSession::addView(const StereoFrame& frame, PerceptionResult* perceived_out) {
  ViewResult view;
  view.index = views_.size();
  view.T_world_camera_told = frame.T_world_camera;
  const auto t0 = std::chrono::steady_clock::now();
  PerceptionResult perceived = perception_.process(frame, region_, T_world_tag_);
  view.perceive_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  view.tag_detected = perceived.tag.has_value();
  view.tag = perceived.tag;
  view.roi_points = perceived.clouds.roi_points_m.size();
  view.other_points = perceived.clouds.other_points_m.size();
  view.perception = perceived.clouds.stats;
  views_.push_back(view);

  Eigen::Isometry3d T_world_camera = frame.T_world_camera;
  if (pose_graph_) pose_graph_->addView(frame.T_world_camera, perceived.tag, frame.intrinsics);
  if (registration_ && region_) {
    const RegistrationResult r = registerView(view.index, perceived.clouds);
    views_.back().registration = r;
    T_world_camera = r.correction * T_world_camera;
    refreshTagFromPoseGraph();
  }
  if (!region_ && perceived.region) {
    region_ = perceived.region;
    if (registration_) {
      // The views up to this one anchor the model, fused as they were told.
      for (const auto& [index, clouds] : pending_)
        registration_->addToModel(pointsInRegion(clouds));
      registration_->addToModel(pointsInRegion(perceived.clouds));
    }
    if (pose_graph_) {
      pose_graph_->setClusterCentre(region_->center_m());
      for (std::size_t k = 0; k < views_.size(); ++k)
        pose_graph_->place(k, Eigen::Vector3d::Zero(), {});
      pose_graph_->solve();
    }
    if (perceived.tag) T_world_tag_ = perceived.tag->T_world_tag;
    refreshTagFromPoseGraph();
    if (carried_map_) {
      map_ = std::move(carried_map_);
      map_->moveToRegion(*region_);
    } else {
      map_ = map::createMapEngine(engine_, map_config_, *region_, backend_);
    }
    for (const auto& [index, clouds] : pending_) integrate(index, clouds);
    views_.back().earlier_views_integrated = pending_.size();
    pending_.clear();
  }
  if (map_) {
    integrate(view.index, perceived.clouds);
  } else {
    pending_.emplace_back(view.index, perceived.clouds);
  }
  if (tsdf_config_) {
    // What sizing needs of the view, and the fruitlets' TSDF from its ROI depth once the
    // region bounds the TSDF (views seen before the tag are fused when it is found).
    sizing_views_.push_back({perceived.fruitlet_mask, perceived.disparity.disparity_px,
                             frame.intrinsics, T_world_camera, perceived.fruitlet_instances});
    if (region_ && !tsdf_) {
      tsdf_ = newTsdf();
      for (std::size_t i = 0; i + 1 < sizing_views_.size(); ++i) integrateTsdf(i);
    }
    if (tsdf_) {
      views_.back().tsdf_s = integrateTsdf(sizing_views_.size() - 1);
      views_.back().tsdf_s += refuseTsdfWhereViewsMoved();
    }
  }
  if (perceived_out) *perceived_out = std::move(perceived);
  return views_.back();
}

void MappingSession::enableViewRegistration(const ViewRegistrationConfig& config) {
  // The pose graph holds a view per session view, from the first.
  if (!views_.empty())
    throw std::logic_error("MappingSession::enableViewRegistration: call before the first view");
  if (config.use_pose_graph && config.estimate_rotation)
    throw std::invalid_argument(
        "view registration: estimate_rotation needs use_pose_graph off (the graph places views "
        "by translation)");
  registration_.emplace(config);
  if (config.use_pose_graph)
    pose_graph_.emplace(config.pose_graph, perception_.config().tag.tag_size_m);
}

void MappingSession::refreshTagFromPoseGraph() {
  if (!pose_graph_) return;
  // Every view that saw the tag, in the maps' frame (the graph's estimate is the world's).
  if (const std::optional<Eigen::Isometry3d> T = pose_graph_->T_world_tag())
    T_world_tag_ = Eigen::Translation3d(-pose_graph_->mapFrameError_m()) * *T;
}

RegistrationResult MappingSession::registerView(std::size_t index, LabeledClouds& clouds) {
  if (!pose_graph_) {
    // Align the view to the model of the views before it, then fuse it where it aligned.
    RegistrationResult r = registration_->align(pointsInRegion(clouds));
    if (r.status == RegistrationStatus::kApplied) {
      moveClouds(clouds, r.correction);
      r.placement_m = r.centroid_shift_m;
    } else {
      r.correction = Eigen::Isometry3d::Identity();
    }
    registration_->addToModel(pointsInRegion(clouds));
    return r;
  }
  // Place the view where the graph expects it (its tag included), align it from there, and
  // keep the alignment's refinement only where the graph's uncertainty allows it.
  pose_graph_->solve();
  const Eigen::Vector3d predicted = pose_graph_->predictedPlacement(index);
  const Eigen::Vector3d sigma = pose_graph_->predictedPlacementSigma(index);
  moveClouds(clouds, Eigen::Isometry3d(Eigen::Translation3d(predicted)));
  RegistrationResult r = registration_->align(pointsInRegion(clouds));
  r.predicted_m = predicted;
  Eigen::Vector3d placement = predicted;
  std::vector<std::size_t> aligned_to;
  if (r.status == RegistrationStatus::kApplied) {
    const double align = pose_graph_->config().alignment_sigma_m;
    const Eigen::Vector3d gate =
        pose_graph_->config().outlier_sigmas * (sigma.array().square() + align * align).sqrt();
    if ((r.centroid_shift_m.cwiseAbs().array() <= gate.array()).all()) {
      moveClouds(clouds, Eigen::Isometry3d(Eigen::Translation3d(r.centroid_shift_m)));
      placement += r.centroid_shift_m;
      for (std::size_t j = 0; j < index; ++j)
        if (pose_graph_->view(j).placed) aligned_to.push_back(j);
    } else {
      r.status = RegistrationStatus::kDisagrees;
    }
  }
  pose_graph_->place(index, placement, std::move(aligned_to));
  pose_graph_->solve();
  r.placement_m = placement;
  r.correction = Eigen::Isometry3d(Eigen::Translation3d(placement));
  registration_->addToModel(pointsInRegion(clouds));
  return r;
}

std::vector<Eigen::Vector3f> MappingSession::pointsInRegion(const LabeledClouds& clouds) const {
  std::vector<Eigen::Vector3f> points;
  if (!region_) return points;
  for (const auto* cloud : {&clouds.roi_points_m, &clouds.other_points_m})
    for (const Eigen::Vector3f& p : *cloud)
      if (region_->contains(p.cast<double>())) points.push_back(p);
  return points;
}

void MappingSession::moveClouds(LabeledClouds& clouds, const Eigen::Isometry3d& T) {
  const Eigen::Isometry3f Tf = T.cast<float>();
  for (auto* cloud : {&clouds.roi_points_m, &clouds.other_points_m})
    for (Eigen::Vector3f& p : *cloud) p = Tf * p;
  clouds.sensor_origin_m = T * clouds.sensor_origin_m;
}

void MappingSession::enableTsdf(const tsdf::TsdfConfig& config) {
  config.validate();
  tsdf_config_ = config;
}

double MappingSession::integrateTsdf(std::size_t sizing_view) {
  const sizing::SizingView& v = sizing_views_[sizing_view];
  const cv::Mat depth = tsdf::depthFromDisparity(v.disparity_px, v.intrinsics);
  return tsdf_->integrate(depth, v.fruitlet_mask, v.intrinsics, v.T_world_camera).seconds;
}

std::unique_ptr<tsdf::TsdfVolume> MappingSession::newTsdf() const {
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(region_->radius_m());
  return std::make_unique<tsdf::TsdfVolume>(
      *tsdf_config_, Eigen::AlignedBox3d(region_->center_m() - half, region_->center_m() + half),
      backend_);
}

double MappingSession::refuseTsdfWhereViewsMoved() {
  if (!tsdf_ || !pose_graph_ || !(registration_->config().refuse_tsdf_beyond_m > 0.0)) return 0.0;
  // The graph's placements average to the fused ones over all its views (predictedPlacement
  // is e_k less the mean of e_j - C_j), so a TSDF of every view fused at them keeps the maps'
  // frame. One enabled after the first view holds only some of them: left as fused. Past
  // this check sizing view i is session view i.
  if (sizing_views_.size() != views_.size()) return 0.0;
  // How far the graph now moves each fused view from where it was fused (its placement: the
  // translation its points were moved by, T_world_camera = Trans(placement) * told).
  std::vector<Eigen::Vector3d> placements(sizing_views_.size());
  double most_m = 0.0;
  for (std::size_t i = 0; i < sizing_views_.size(); ++i) {
    if (!pose_graph_->view(i).placed) return 0.0;  // not before the region places them all
    placements[i] = pose_graph_->predictedPlacement(i);
    const Eigen::Vector3d fused_m =
        sizing_views_[i].T_world_camera.translation() - views_[i].T_world_camera_told.translation();
    most_m = std::max(most_m, (placements[i] - fused_m).norm());
  }
  if (most_m <= registration_->config().refuse_tsdf_beyond_m) return 0.0;
  const auto start = std::chrono::steady_clock::now();
  tsdf_ = newTsdf();
  for (std::size_t i = 0; i < sizing_views_.size(); ++i) {
    sizing_views_[i].T_world_camera =
        Eigen::Translation3d(placements[i]) * views_[i].T_world_camera_told;
    integrateTsdf(i);
  }
  ++tsdf_refusions_;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<Eigen::Vector3f> MappingSession::surfacePoints() const {
  return tsdf_ ? tsdf_->extractSurfacePoints() : std::vector<Eigen::Vector3f>{};
}

tsdf::TriangleMesh MappingSession::surfaceMesh() const {
  return tsdf_ ? tsdf_->extractMesh() : tsdf::TriangleMesh{};
}

sizing::SizingResult MappingSession::sizeFruitletsInMapFrame(
    const sizing::SizingConfig& config) const {
  if (!tsdf_config_)
    throw std::logic_error("MappingSession::sizeFruitlets: call enableTsdf() first");
  const map::MapEngine* map = map_.get();
  const auto in_roi_voxel = [map](const Eigen::Vector3f& p) {
    if (!map) return false;
    const map::VoxelState s = map->fineState(p.cast<double>());
    return s.roi && s.occupancy == map::VoxelClass::kOccupied;
  };
  sizing::SizingConfig own = config;
  own.surface_voxel_size_m = tsdf_config_->voxel_size_m;
  own.registered_views = pose_graph_.has_value();
  return sizing::sizeFruitlets(sizing_views_, viewSegments(), surfacePoints(), in_roi_voxel, own);
}

std::vector<std::shared_ptr<const sizing::ViewSegments>> MappingSession::viewSegments() const {
  // A view's segments do not change (its mask and instances are kept as perceived): each is
  // computed once, by the first sizing that reads it, and charged to that sizing.
  std::lock_guard<std::mutex> lock(segments_mutex_);
  while (view_segments_.size() < sizing_views_.size())
    view_segments_.push_back(std::make_shared<const sizing::ViewSegments>(
        sizing::segmentsOf(sizing_views_[view_segments_.size()])));
  return view_segments_;
}

sizing::SizingResult MappingSession::sizeFruitlets(const sizing::SizingConfig& config) const {
  sizing::SizingResult result = sizeFruitletsInMapFrame(config);
  if (correctsAnchorOffset()) sizing::translateDetections(result, appliedAnchorShift_m());
  return result;
}

AnchorOffset MappingSession::anchorOffset() const {
  if (!registration_) return {};
  if (pose_graph_) {
    AnchorOffset offset;
    offset.views = pose_graph_->placedViews();
    offset.shift_m = pose_graph_->mapFrameError_m();
    offset.hand_eye_m = pose_graph_->handEyeAtCentre_m();
    offset.valid =
        offset.views >= 2 && offset.shift_m.norm() <= registration_->config().max_translation_m;
    if (!offset.valid) offset.shift_m.setZero();
    return offset;
  }
  std::vector<RegisteredView> views;
  for (const ViewResult& v : views_)
    views.push_back(
        {v.T_world_camera_told.linear(), v.registration.value_or(RegistrationResult{})});
  return estimateAnchorOffset(views, registration_->config().hand_eye_prior_sigma_m,
                              registration_->config().max_translation_m);
}

void MappingSession::integrate(std::size_t index, const LabeledClouds& clouds) {
  ViewResult& view = views_[index];
  view.scan = map_->integrate(clouds);
  view.integrated = true;
  // The TSDF of the fine map (docs/design.md section 5) is fed here next: the same clouds, in the
  // same order, once the region is known.
}

}  // namespace fvp::host
