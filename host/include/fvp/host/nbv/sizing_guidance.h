// Aims the planner at what the automatic stop still waits for (docs/nbv-loop.md, "Views the
// stop rule needs"). After each sizing, every fruitlet short of the rule's evidence (two
// well-seen images from directions 30 degrees apart, lacksEvidence) becomes one of the
// planner's sizing targets. A fruitlet the planner has moved to look at max_aimed_views times
// without gaining a well-seen image is left out until it gains one: after the first such view
// the occluders on that line of sight are in the map, so the next prediction is better
// informed; a second miss says no reachable view shows it (a neighbour merged with it in 2-D,
// a leaf the arm cannot see past), and the cluster must not wait on it.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include "fvp/host/nbv/cluster_completion.h"
#include "fvp/host/nbv/nbv_loop.h"
#include "fvp/host/nbv/remembered_views.h"
#include "fvp/host/nbv/visit_memory.h"
#include "fvp/host/planner/view_planner.h"

namespace fvp::host::nbv {

class SizingGuidance : public LoopObserver {
 public:
  /// completion and planner must outlive this; add this observer after completion, whose
  /// sizing it reads. min_visible_fraction: sizing's well_seen_fraction.
  SizingGuidance(const ClusterCompletion& completion, planner::ViewPlanner& planner,
                 double min_visible_fraction, int max_aimed_views = 2)
      : SizingGuidance(completion.history(), completion.config(), planner, min_visible_fraction,
                       max_aimed_views) {
    completion_ = &completion;
  }
  /// Over any sizing history (tests): history and config must outlive this.
  SizingGuidance(const std::vector<SizingSnapshot>& history, const ClusterCompletionConfig& config,
                 planner::ViewPlanner& planner, double min_visible_fraction,
                 int max_aimed_views = 2);

  void onView(const ViewEvent& event) override;
  void onPlan(const PlanEvent& event) override;

  /// The targets handed to the planner after the last view.
  const std::vector<planner::SizingTarget>& targets() const { return targets_; }
  /// Moves to a sizing candidate so far.
  std::size_t aimedViews() const { return aimed_views_; }
  /// Fruitlets left out after max_aimed_views aimed views without a new well-seen image.
  std::size_t droppedTargets() const { return dropped_; }
  /// Whether an unconfirmed detection (SizingSnapshot::unconfirmed) is still a target: not
  /// yet sized from directions the rule asks, and the loop has not yet taken max_aimed_views
  /// views since it became one. ClusterCompletion::holdWhile takes it: a cluster is not done
  /// while the planner may still confirm one.
  bool waitingOnUnconfirmed() const {
    return std::find(target_unconfirmed_.begin(), target_unconfirmed_.end(), true) !=
           target_unconfirmed_.end();
  }
  /// The fruitlets an earlier visit sized, in the tag's frame (visit_memory.h); T_world_tag
  /// gives the tag's pose on this visit (empty until a view saw it) and must outlive this.
  /// After each sizing, a remembered fruitlet that no fruitlet of the sizing (kept or
  /// unconfirmed; a partly seen detection is not one) stands within max_shift_m of, one to one, is
  /// a target the stop waits on (waitingOnExpected); one still not found after max_aimed_views
  /// views other than remembered ones is gone (expectedGone): looked for where it was, and not
  /// there.
  void expect(std::vector<RememberedFruitlet> fruitlets_tag, TagPoseFn T_world_tag,
              double max_shift_m);
  bool waitingOnExpected() const {
    return std::find(target_expected_.begin(), target_expected_.end(), true) !=
           target_expected_.end();
  }
  /// After the last sizing: remembered fruitlets found, and those given up as gone.
  std::size_t expectedFound() const { return expected_found_; }
  std::size_t expectedGone() const { return expected_gone_; }
  /// After the last sizing: memory accounts for the cluster's fruitlets. Every remembered
  /// fruitlet stands where a kept fruitlet of the sizing does, and every kept fruitlet is a
  /// remembered one (ClusterCompletion::knownWhen takes it). One gone, one found only as an
  /// unconfirmed detection, or a fruitlet the earlier visit did not size leaves the cluster
  /// to the first visit's rule: two views without a remembered fruitlet cannot tell fallen
  /// from hidden (on development season 1, 4 of a cluster's 6 fruitlets were given up as gone
  /// while hanging behind leaves), and that rule's search finds a hidden one again. False
  /// without remembered fruitlets or before a view saw the tag.
  bool fruitletsKnown() const { return fruitlets_known_; }
  /// Whether the fruitlet at center_m was left out: looked at max_aimed_views times without a
  /// new well-seen image (ClusterCompletion::releaseWhen takes it, with release_left_out).
  bool leftOut(const Eigen::Vector3d& center_m) const;

 private:
  struct Aim {
    Eigen::Vector3d center_m;
    int well_seen_images = 0;  ///< when first aimed at
    int views = 0;
    bool for_unconfirmed = false;  ///< first aimed at as an unconfirmed detection
  };
  Aim* findAim(const Eigen::Vector3d& center_m);
  const Aim* findAim(const Eigen::Vector3d& center_m) const;
  /// Adds the remembered fruitlets the latest sizing lacks to the targets (expect()).
  void seekExpected();

  const std::vector<SizingSnapshot>& history_;
  /// The stop whose rule onPlan follows (ClusterCompletion::ruleNow); none over a bare
  /// history: the config's rule.
  const ClusterCompletion* completion_ = nullptr;
  const ClusterCompletionConfig& config_;
  planner::ViewPlanner& planner_;
  double min_visible_fraction_;
  int max_aimed_views_;
  std::vector<planner::SizingTarget> targets_;
  std::vector<bool> target_unconfirmed_;  ///< per target: an unconfirmed detection
  std::vector<bool> target_expected_;     ///< per target: a remembered fruitlet not found
  std::vector<RememberedFruitlet> expected_;
  TagPoseFn T_world_tag_;
  double max_shift_m_ = 0.0;
  std::size_t expected_found_ = 0, expected_gone_ = 0;
  bool fruitlets_known_ = false;
  std::vector<Aim> aims_;
  std::size_t aimed_views_ = 0, dropped_ = 0;
};

}  // namespace fvp::host::nbv
