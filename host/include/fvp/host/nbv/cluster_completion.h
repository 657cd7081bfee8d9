// When a cluster is done (docs/nbv-loop.md, "Automatic stop"): the loop sizes the cluster after
// every view and stops once another view no longer changes what it would report: the same
// fruitlets, each measured in enough well-seen images, none of whose sizes moved by more
// than a tolerance over the last few views. The paper's budget stays the cap.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "fvp/host/nbv/loop_clock.h"
#include "fvp/host/nbv/nbv_loop.h"
#include "fvp/host/nbv/stop_condition.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/host/sizing/fruitlet_sizer.h"

namespace fvp::host::nbv {

struct ClusterCompletionConfig {
  /// Views over which nothing may change: a new view adds a few well-seen images to each
  /// fruitlet's median, so one quiet view says little; three say the median has settled.
  int stable_views = 3;
  /// The most a fruitlet's size may differ, in any of those views, from its latest size. One pixel
  /// at the planner's farthest view (0.40 m, fx 1100 px) spans 0.36 mm; 0.1 mm is a quarter of that
  /// and a third of the 0.3 mm error the sizing reaches with the paper's whole budget, so views
  /// that move estimates less than this cannot buy a better size.
  double size_tolerance_mm = 0.1;
  /// A fruitlet whose size is a median of noisy images may move by its standard error
  /// (FruitletSupport::size_stderr_mm) instead, when that is larger: the median cannot be
  /// known better than its standard error, so views that move it by less re-sample noise
  /// rather than improve it. Off: size_tolerance_mm for every fruitlet.
  bool tolerate_standard_error = true;
  /// Detections of two sizings closer than this are one fruitlet: the smallest fruitlet's
  /// radius (3 mm; sizing keeps spheres of 1.5-12 mm radius).
  double same_fruitlet_m = 0.003;
  /// Each fruitlet's size must come from at least this many well-seen images (one image is
  /// one sample of the per-image error; two agree or reveal it). Fruitlets sized by their
  /// sphere fit (merged with a neighbour in every image) count once their size is stable.
  int min_well_seen_images = 2;
  /// ...and from directions at least this far apart (the largest angle between two of its
  /// well-seen views, seen from the fruitlet). Images from one direction share their errors:
  /// the same leaf in Eq. 4's disparity window, the same cut of the silhouette. A leaf d in
  /// front of a fruitlet moves across its line of sight by d tan(angle); at 30 degrees and
  /// d >= 2 cm that is 12 mm, more than a fruitlet's diameter, so no one occluder spoils
  /// both ends of the span.
  double min_view_span_deg = 30.0;
  /// The views over which no fruitlet was found or lost must come from directions at least
  /// this far apart, seen from the cluster (the centroid of the latest fruitlets): views close
  /// together see the same sides, so a fruitlet hidden from one is hidden from all, and their
  /// agreement says nothing about what is still unseen. The window of stable_views + 1
  /// sizings grows back until its cameras span this angle. 30 degrees for min_view_span_deg's
  /// reason: a leaf 2 cm in front of a hidden fruitlet moves 12 mm across the line of sight,
  /// more than a fruitlet's diameter. Sizes must agree over the last stable_views + 1 only.
  /// 0: off (the rule before; any stable_views + 1 sizings).
  double min_stable_span_deg = 30.0;
  /// A cluster is also done when the planner finds no view to move to for this many
  /// iterations in a row ("no_reachable_view"): its threshold decays by threshold_decay
  /// (0.8) in each of max_sampling_rounds (8) rounds, so after 3 iterations it is 0.8^24 =
  /// 0.5 % of where it started and no longer filters anything. Every one of the 4800
  /// candidates those iterations sampled with a gain above its travel cost was then tried
  /// and none could be reached: more planning here only spends the clock.
  int max_iterations_without_view = 3;
  /// Look again at unconfirmed detections (DetectionSupport::unconfirmed: dropped by the
  /// hemisphere rule alone) before the cluster is done. Such a detection is a real fruitlet
  /// seen from one side with its outline merged with a neighbour's, or a phantom; its evidence
  /// is its sized images from directions min_view_span_deg apart, and SizingGuidance aims at
  /// it like a fruitlet short of well-seen images (holdWhile: the stop waits while it does).
  /// Off (the rule before 8c37611): the stop rule and the planner see the kept detections only.
  bool confirm_detections = true;
  /// Look again, the same way, at partly seen detections (partlySeen: dropped by the support
  /// rule, less than the quarter of their sphere seen, and apart from every kept fruitlet).
  /// Such a detection is a fruitlet seen through a gap or round a leaf's edge, or a phantom;
  /// a view aimed at it shows more of it or nothing there. Without it, views that happen to
  /// see no more of a half-hidden fruitlet count as "nothing found" and the stop leaves it
  /// unsized. Each holds the stop for max_aimed_views views at most. Off (before this rule):
  /// only unconfirmed detections are looked at again.
  bool seek_partly_seen = true;
  /// A kept fruitlet that lacks the evidence (lacksEvidence) no longer holds the stop once
  /// the planner has looked for it max_aimed_views times in vain (SizingGuidance::leftOut,
  /// handed over by releaseWhen): no reachable view shows it as the rule asks, so waiting on
  /// it only spends the cap. Its size must still be stable. Off (before 8c37611): it holds the stop
  /// to the cap.
  bool release_left_out = true;
  /// With the cluster's pose graph (view registration): not done while any of the last
  /// stable_views + 1 views disagrees with the rest (its alignment or tag residual beyond
  /// the graph's outlier_sigmas): the maps' frame is still moving, so sizes that look
  /// settled may be sized in a frame the next view corrects. The cap still ends the cluster.
  bool hold_while_views_disagree = true;
  /// On a visit after the first, once memory accounts for the cluster's fruitlets (every one
  /// an earlier visit sized is found again, and nothing else was found: knownWhen), the
  /// question the window of stable_views + 1 views spanning min_stable_span_deg answers (is a
  /// fruitlet still unseen?) has been answered by the earlier visit, whose own stop asked it
  /// over the whole cluster. The cluster is then done once each fruitlet has the evidence and
  /// the sizes agree over known_stable_views + 1 views: the evidence makes each size a median
  /// of images from two directions, and one more agreeing view shows the latest images no
  /// longer move it. Measured on the ten development seasons (docs/results.md, 2026-12-02):
  /// at the moment every fruitlet had the evidence, later visits' MAE was the stop's own
  /// (0.28 against 0.30 mm on day 4, 0.37 against 0.37 on day 7), with 51-59 % of the cluster's
  /// time still to come. Off: a later visit stops by the first visit's rule.
  bool known_fruitlets = true;
  int known_stable_views = 1;
  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
};

/// One fruitlet of one sizing, as the stop rule compares them.
struct FruitletSnapshot {
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  double size_mm = 0.0;
  int well_seen_images = 0;
  double view_span_deg = 0.0;  ///< largest angle between two well-seen views' directions
  sizing::SizeSource size_source = sizing::SizeSource::kWellSeenImages;
  /// The size's standard error (FruitletSupport::size_stderr_mm); -1 under 2 well-seen images.
  double size_stderr_mm = -1.0;
  /// Unit vectors from the fruitlet towards the cameras of its well-seen images.
  std::vector<Eigen::Vector3d> well_seen_directions;
  /// An unconfirmed or partly seen detection (ClusterCompletionConfig::confirm_detections,
  /// seek_partly_seen): well_seen_images, view_span_deg and well_seen_directions then count
  /// every image that sized it.
  bool unconfirmed = false;
  /// Of those, a partly seen one (partlySeen), not the hemisphere rule's.
  bool partly_seen = false;
};

/// The cluster sized after one view.
struct SizingSnapshot {
  int view = 0;        ///< 0-based index of the view it followed
  double now_s = 0.0;  ///< the loop clock when the view was mapped
  double sizing_s = 0.0;
  /// Where the arm put the camera for the view (ViewEvent::T_world_camera; registration may
  /// move the session's copy by millimetres, nothing at the scale of directions).
  Eigen::Vector3d camera_position_m = Eigen::Vector3d::Zero();
  /// Centres are in the registered maps' frame; this added puts them in the world as the
  /// final sizing reports them (MappingSession::anchorOffset; zero without the correction).
  Eigen::Vector3d world_shift_m = Eigen::Vector3d::Zero();
  std::vector<FruitletSnapshot> fruitlets;
  /// The unconfirmed detections, with confirm_detections, and the partly seen ones, with
  /// seek_partly_seen (not compared by sizesSettled).
  std::vector<FruitletSnapshot> unconfirmed;
  /// The view sized at least one image of some detection, kept or not. One that sized none
  /// (no fruitlet in its images, or every one hidden or cut off) shows nothing of the
  /// cluster: sizesSettled leaves it out rather than read it as a look that found nothing.
  bool sized_any_image = true;
};

/// A loop observer that sizes the session's cluster after every view and a stop condition
/// that holds once the sizes have settled. The sizing's wall time is charged to the loop
/// clock as LoopStage::kSizing: a robot would spend it too.
class ClusterCompletion : public LoopObserver {
 public:
  /// session and clock must outlive this. Throws std::invalid_argument for a bad config or
  /// a session without enableTsdf() (nothing could be sized).
  ClusterCompletion(const MappingSession& session, LoopClock& clock,
                    sizing::SizingConfig sizing_config, ClusterCompletionConfig config = {});
  // stopCondition() refers to this object.
  ClusterCompletion(const ClusterCompletion&) = delete;
  ClusterCompletion& operator=(const ClusterCompletion&) = delete;

  void onView(const ViewEvent& event) override;

  /// Whether the sizes have settled (see ClusterCompletionConfig) and no hold holds.
  bool done() const;
  /// The rule done() applies now: the config's, or with known_fruitlets and knownWhen holding,
  /// the known fruitlets' (known_stable_views, no discovery span).
  ClusterCompletionConfig ruleNow() const;
  /// Whether one of the last stable_views + 1 views disagrees in the session's pose graph
  /// (false without one). The config's stable_views under the known fruitlets' rule too:
  /// memory says which fruitlets there are, not that the maps' frame has settled (a later
  /// visit's clusters stopped after 3 views were the ones whose world positions were off).
  bool recentViewsDisagree() const;
  /// The cluster is not done while `pending` returns true (SizingGuidance::
  /// waitingOnUnconfirmed): `pending` must outlive this.
  void holdWhile(std::function<bool()> pending) { hold_ = std::move(pending); }
  /// The cluster's fruitlets are known from memory while `known` returns true
  /// (SizingGuidance::fruitletsKnown, with known_fruitlets): `known` must outlive this.
  void knownWhen(std::function<bool()> known) { known_ = std::move(known); }
  /// A fruitlet for which `released` returns true does not need the evidence
  /// (SizingGuidance::leftOut, with release_left_out): `released` must outlive this.
  void releaseWhen(std::function<bool(const FruitletSnapshot&)> released) {
    released_ = std::move(released);
  }
  /// Holds when done(); its reason is "cluster_done".
  /// "cluster_done" once the sizes have settled, "no_reachable_view" once the planner is
  /// stuck (max_iterations_without_view).
  StopCondition stopCondition() const;

  /// One snapshot per view mapped after the Cluster Region was known.
  const std::vector<SizingSnapshot>& history() const { return history_; }
  const ClusterCompletionConfig& config() const { return config_; }

 private:
  const MappingSession& session_;
  LoopClock& clock_;
  sizing::SizingConfig sizing_config_;
  ClusterCompletionConfig config_;
  std::vector<SizingSnapshot> history_;
  std::function<bool()> hold_;
  std::function<bool()> known_;
  std::function<bool(const FruitletSnapshot&)> released_;
};

/// The rule once memory accounts for the cluster's fruitlets (known_fruitlets): config with
/// stable_views = known_stable_views and no discovery span.
ClusterCompletionConfig knownFruitletsRule(const ClusterCompletionConfig& config);

/// Whether a fruitlet still lacks the images the rule asks for: min_well_seen_images
/// well-seen images from directions min_view_span_deg apart (sphere-fit sizes need none; an
/// unconfirmed detection needs as many sized images, as far apart).
bool lacksEvidence(const FruitletSnapshot& fruitlet, const ClusterCompletionConfig& config);

/// Whether a detection the sizing dropped may be a fruitlet not yet seen enough
/// (ClusterCompletionConfig::seek_partly_seen): dropped by the support rule (fewer points than
/// required, not the hemisphere rule's unconfirmed ones), sized in at least one image, and
/// its centre outside every kept fruitlet's sphere by at least the smallest fruitlet's radius
/// (sphere_ransac.h): fruitlets do not overlap, so a centre closer than that is a piece of the
/// kept fruitlet's own surface. Fitted centres and our sizes (sphere_center_m, size_ours_mm)
/// whichever estimator reports.
bool partlySeen(const sizing::FruitletEstimate& detection,
                const std::vector<sizing::FruitletEstimate>& kept);

/// How many of history's latest snapshots the found-or-lost check spans: at least
/// config.stable_views + 1, and back until their cameras span config.min_stable_span_deg seen
/// from the latest fruitlets' centroid; 0 when the whole history does not span it (or is
/// shorter than stable_views + 1, or has no fruitlet).
std::size_t discoveryWindow(const std::vector<SizingSnapshot>& history,
                            const ClusterCompletionConfig& config);

/// Whether the latest snapshots of history agree (the rule of done()): the same fruitlets
/// over discoveryWindow, sizes within tolerance over the last config.stable_views + 1.
/// Snapshots of views that sized no image (SizingSnapshot::sized_any_image) are left out.
/// `released` (optional): fruitlets that need not show the evidence.
bool sizesSettled(const std::vector<SizingSnapshot>& history, const ClusterCompletionConfig& config,
                  const std::function<bool(const FruitletSnapshot&)>& released = {});

}  // namespace fvp::host::nbv
