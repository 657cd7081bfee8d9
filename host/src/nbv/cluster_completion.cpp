#include "fvp/host/nbv/cluster_completion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "fvp/host/sizing/sphere_ransac.h"

namespace fvp::host::nbv {

void ClusterCompletionConfig::validate() const {
  if (stable_views < 1)
    throw std::invalid_argument("cluster completion 'stable_views': expected at least 1");
  if (!(size_tolerance_mm > 0.0) || !std::isfinite(size_tolerance_mm))
    throw std::invalid_argument("cluster completion 'size_tolerance_mm': expected > 0");
  if (!(same_fruitlet_m > 0.0) || !std::isfinite(same_fruitlet_m))
    throw std::invalid_argument("cluster completion 'same_fruitlet_m': expected > 0");
  if (min_well_seen_images < 1)
    throw std::invalid_argument("cluster completion 'min_well_seen_images': expected at least 1");
  if (!(min_view_span_deg >= 0.0) || !(min_view_span_deg <= 180.0))
    throw std::invalid_argument("cluster completion 'min_view_span_deg': expected 0 to 180");
  if (!(min_stable_span_deg >= 0.0) || !(min_stable_span_deg <= 180.0))
    throw std::invalid_argument("cluster completion 'min_stable_span_deg': expected 0 to 180");
  if (max_iterations_without_view < 1)
    throw std::invalid_argument(
        "cluster completion 'max_iterations_without_view': expected at least 1");
  if (known_stable_views < 1)
    throw std::invalid_argument("cluster completion 'known_stable_views': expected at least 1");
}

ClusterCompletion::ClusterCompletion(const MappingSession& session, LoopClock& clock,
                                     sizing::SizingConfig sizing_config,
                                     ClusterCompletionConfig config)
    : session_(session), clock_(clock), sizing_config_(sizing_config), config_(config) {
  config_.validate();
  sizing_config_.validate();
  if (!session_.tsdfEnabled())
    throw std::invalid_argument(
        "ClusterCompletion: the session sizes nothing without enableTsdf()");
}

void ClusterCompletion::onView(const ViewEvent& event) {
  if (!session_.tsdf()) return;  // no Cluster Region yet: nothing to size
  const auto start = std::chrono::steady_clock::now();
  // Compared over time in the maps' own frame: the anchor offset's estimate moves as views
  // arrive, the maps' frame does not (a TSDF fused again keeps it).
  const sizing::SizingResult sized = session_.sizeFruitletsInMapFrame(sizing_config_);
  const double sizing_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  clock_.chargeCompute(LoopStage::kSizing, sizing_s);
  SizingSnapshot snapshot;
  snapshot.view = event.index;
  snapshot.now_s = clock_.now_s();
  snapshot.sizing_s = sizing_s;
  snapshot.camera_position_m = event.T_world_camera.translation();
  snapshot.world_shift_m = session_.appliedAnchorShift_m();
  const auto& views = session_.sizingViews();
  // Its images' directions (the well-seen ones, or every sized one of an unconfirmed
  // detection) and the widest angle between two.
  const auto snapshotOf = [&](const sizing::FruitletEstimate& f, bool unconfirmed) {
    std::vector<Eigen::Vector3d> directions;
    for (const auto& image : f.per_image)
      if (image.well_seen || unconfirmed)
        directions.push_back(
            (views[std::size_t(image.view)].T_world_camera.translation() - f.center_m)
                .normalized());
    double span_rad = 0.0;
    for (std::size_t i = 0; i < directions.size(); ++i)
      for (std::size_t j = i + 1; j < directions.size(); ++j)
        span_rad =
            std::max(span_rad, std::acos(std::clamp(directions[i].dot(directions[j]), -1.0, 1.0)));
    FruitletSnapshot out;
    out.center_m = f.center_m;
    out.size_mm = f.size_mm;
    out.well_seen_images = unconfirmed ? int(directions.size()) : f.support.well_seen_images;
    out.view_span_deg = span_rad * 180.0 / M_PI;
    out.size_source = f.size_source;
    out.size_stderr_mm = f.support.size_stderr_mm;
    out.well_seen_directions = std::move(directions);
    out.unconfirmed = unconfirmed;
    return out;
  };
  // Whether this view sized an image of any detection: its sizing view is the latest.
  const int latest_view = int(views.size()) - 1;
  const auto sizedByLatest = [&](const sizing::FruitletEstimate& f) {
    return std::any_of(f.per_image.begin(), f.per_image.end(),
                       [&](const sizing::ImageSize& image) { return image.view == latest_view; });
  };
  snapshot.sized_any_image =
      std::any_of(sized.fruitlets.begin(), sized.fruitlets.end(), sizedByLatest) ||
      std::any_of(sized.unsupported.begin(), sized.unsupported.end(), sizedByLatest);
  for (const auto& f : sized.fruitlets) snapshot.fruitlets.push_back(snapshotOf(f, false));
  for (const auto& f : sized.unsupported) {
    const bool partly_seen = config_.seek_partly_seen && partlySeen(f, sized.fruitlets);
    if (!partly_seen && !(config_.confirm_detections && f.support.unconfirmed)) continue;
    snapshot.unconfirmed.push_back(snapshotOf(f, true));
    snapshot.unconfirmed.back().partly_seen = partly_seen;
  }
  history_.push_back(std::move(snapshot));
}

ClusterCompletionConfig ClusterCompletion::ruleNow() const {
  return config_.known_fruitlets && known_ && known_() ? knownFruitletsRule(config_) : config_;
}

bool ClusterCompletion::done() const {
  return sizesSettled(history_, ruleNow(), released_) && !(hold_ && hold_()) &&
         !(config_.hold_while_views_disagree && recentViewsDisagree());
}

bool ClusterCompletion::recentViewsDisagree() const {
  const ClusterPoseGraph* graph = session_.poseGraph();
  if (!graph) return false;
  // The first visit's window under either rule: the maps' frame is not memory's to settle.
  const std::size_t window = std::min(graph->size(), std::size_t(config_.stable_views) + 1);
  for (std::size_t k = graph->size() - window; k < graph->size(); ++k)
    if (graph->estimate(k).disagrees) return true;
  return false;
}

StopCondition ClusterCompletion::stopCondition() const {
  return StopCondition([this](const LoopState&) { return done(); }, "cluster_done") ||
         StopCondition::stalled(static_cast<std::size_t>(config_.max_iterations_without_view));
}

ClusterCompletionConfig knownFruitletsRule(const ClusterCompletionConfig& config) {
  ClusterCompletionConfig rule = config;
  rule.stable_views = config.known_stable_views;
  rule.min_stable_span_deg = 0.0;
  return rule;
}

bool lacksEvidence(const FruitletSnapshot& fruitlet, const ClusterCompletionConfig& config) {
  return (fruitlet.unconfirmed || fruitlet.size_source != sizing::SizeSource::kSphereFit) &&
         (fruitlet.well_seen_images < config.min_well_seen_images ||
          fruitlet.view_span_deg < config.min_view_span_deg);
}

bool partlySeen(const sizing::FruitletEstimate& detection,
                const std::vector<sizing::FruitletEstimate>& kept) {
  if (detection.support.unconfirmed || detection.per_image.empty() ||
      !(double(detection.points) < detection.support.required_points))
    return false;
  // Fitted centres and our sizes, whichever estimator reports: the paper's centroid lies
  // nearer the camera than the centre. A NaN never counts as apart.
  for (const auto& k : kept)
    if (!((detection.sphere_center_m - k.sphere_center_m).norm() >=
          0.5e-3 * k.size_ours_mm + sizing::kDefaultMinFruitletRadius_m))
      return false;
  return true;
}

namespace {

/// discoveryWindow over the snapshots history points to.
std::size_t discoveryWindowOf(const std::vector<const SizingSnapshot*>& history,
                              const ClusterCompletionConfig& config) {
  const std::size_t least = std::size_t(config.stable_views) + 1;
  if (history.size() < least || history.back()->fruitlets.empty()) return 0;
  if (config.min_stable_span_deg <= 0.0) return least;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  for (const auto& f : history.back()->fruitlets) centroid_m += f.center_m;
  centroid_m /= double(history.back()->fruitlets.size());
  const double min_cos = std::cos(config.min_stable_span_deg * M_PI / 180.0);
  // Every pair is compared once, when its later (older) snapshot joins the window.
  std::vector<Eigen::Vector3d> directions;
  bool spans = false;
  for (std::size_t n = 1; n <= history.size(); ++n) {
    const Eigen::Vector3d direction =
        (history[history.size() - n]->camera_position_m - centroid_m).normalized();
    for (const auto& d : directions) spans = spans || d.dot(direction) <= min_cos;
    if (spans && n >= least) return n;
    directions.push_back(direction);
  }
  return 0;
}

std::vector<const SizingSnapshot*> pointersTo(const std::vector<SizingSnapshot>& history) {
  std::vector<const SizingSnapshot*> out;
  for (const auto& s : history) out.push_back(&s);
  return out;
}

/// Whether `earlier` holds the fruitlets of `latest`, one to one, with sizes within
/// tolerance of the latest.
bool sameSizes(const SizingSnapshot& latest, const SizingSnapshot& earlier,
               const ClusterCompletionConfig& config) {
  if (earlier.fruitlets.size() != latest.fruitlets.size()) return false;
  std::vector<bool> taken(earlier.fruitlets.size(), false);
  for (const auto& f : latest.fruitlets) {
    std::optional<std::size_t> nearest;
    double nearest_m = config.same_fruitlet_m;
    for (std::size_t g = 0; g < earlier.fruitlets.size(); ++g)
      if (const double d = (earlier.fruitlets[g].center_m - f.center_m).norm();
          !taken[g] && d <= nearest_m)
        nearest = g, nearest_m = d;
    const double tolerance_mm = config.tolerate_standard_error
                                    ? std::max(config.size_tolerance_mm, f.size_stderr_mm)
                                    : config.size_tolerance_mm;
    // A NaN size never agrees.
    if (!nearest || !(std::abs(earlier.fruitlets[*nearest].size_mm - f.size_mm) <= tolerance_mm))
      return false;
    taken[*nearest] = true;
  }
  return true;
}

bool settledOver(const std::vector<const SizingSnapshot*>& history,
                 const ClusterCompletionConfig& config,
                 const std::function<bool(const FruitletSnapshot&)>& released) {
  // A cluster with nothing sized is not done: its fruitlets are still to be found (the
  // budget ends a cluster that has none). discoveryWindow is 0 then.
  const std::size_t window = discoveryWindowOf(history, config);
  if (window == 0) return false;
  const SizingSnapshot& latest = *history.back();
  for (const auto& f : latest.fruitlets)
    if (lacksEvidence(f, config) && !(released && released(f))) return false;
  for (std::size_t k = 1; k < window; ++k) {
    const SizingSnapshot& earlier = *history[history.size() - 1 - k];
    // A fruitlet found or lost: the cluster is still changing. Past the last stable_views + 1
    // only the count: early centres may sit a few mm off.
    if (k > std::size_t(config.stable_views) ? earlier.fruitlets.size() != latest.fruitlets.size()
                                             : !sameSizes(latest, earlier, config))
      return false;
  }
  return true;
}

}  // namespace

std::size_t discoveryWindow(const std::vector<SizingSnapshot>& history,
                            const ClusterCompletionConfig& config) {
  return discoveryWindowOf(pointersTo(history), config);
}

bool sizesSettled(const std::vector<SizingSnapshot>& history, const ClusterCompletionConfig& config,
                  const std::function<bool(const FruitletSnapshot&)>& released) {
  // A view that sized no image (its fruitlets all hidden behind leaves, or out of frame) did
  // not look at the cluster: counted, it would let views that saw nothing stand for views
  // that found nothing new. What it fused may still change the sizing (pixels too few to
  // size, occupancy), so views after the last that sized an image must leave its sizes.
  std::vector<const SizingSnapshot*> looked;
  for (const auto& s : history)
    if (s.sized_any_image) looked.push_back(&s);
  if (looked.empty()) return false;
  for (auto s = history.rbegin(); s != history.rend() && &*s != looked.back(); ++s)
    if (!sameSizes(*s, *looked.back(), config)) return false;
  return settledOver(looked, config, released);
}

}  // namespace fvp::host::nbv
