#include "fvp/host/nbv/sizing_guidance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "fvp/host/core/one_to_one_assignment.h"

namespace fvp::host::nbv {

SizingGuidance::SizingGuidance(const std::vector<SizingSnapshot>& history,
                               const ClusterCompletionConfig& config, planner::ViewPlanner& planner,
                               double min_visible_fraction, int max_aimed_views)
    : history_(history),
      config_(config),
      planner_(planner),
      min_visible_fraction_(min_visible_fraction),
      max_aimed_views_(max_aimed_views) {
  if (!(min_visible_fraction >= 0.0 && min_visible_fraction <= 1.0))
    throw std::invalid_argument("SizingGuidance: min_visible_fraction: expected 0 to 1");
  if (max_aimed_views < 1)
    throw std::invalid_argument("SizingGuidance: max_aimed_views: expected at least 1");
}

const SizingGuidance::Aim* SizingGuidance::findAim(const Eigen::Vector3d& center_m) const {
  const double same_m = config_.same_fruitlet_m;
  for (const Aim& aim : aims_)
    if ((aim.center_m - center_m).norm() <= same_m) return &aim;
  return nullptr;
}

SizingGuidance::Aim* SizingGuidance::findAim(const Eigen::Vector3d& center_m) {
  return const_cast<Aim*>(std::as_const(*this).findAim(center_m));
}

bool SizingGuidance::leftOut(const Eigen::Vector3d& center_m) const {
  const Aim* aim = findAim(center_m);
  return aim && aim->views >= max_aimed_views_;
}

void SizingGuidance::onPlan(const PlanEvent& event) {
  if (!event.step || !event.step->moved()) return;
  const planner::Candidate& chosen = event.step->candidates[*event.step->chosen];
  int aimed_target = -1;
  if (chosen.kind == planner::CandidateKind::kSizing) {
    ++aimed_views_;
    aimed_target = chosen.sizing_target;
  }
  // The view aimed at a target counts for it; every view counts for an unconfirmed one, and
  // for every target once the sizes have settled and only the targets' evidence holds the
  // stop: a cluster waits at most max_aimed_views views on each (the planner may find none of
  // its candidates worth more than the others', and views it prefers then only spend the cap).
  // Without release_left_out a target left out still holds the stop: counting views it was
  // not aimed at would only stop the planner aiming at it.
  // By the rule the stop applies now.
  const ClusterCompletionConfig rule = completion_ ? completion_->ruleNow() : config_;
  const bool only_evidence_holds =
      config_.release_left_out &&
      sizesSettled(history_, rule, [](const FruitletSnapshot&) { return true; });
  for (std::size_t t = 0; t < targets_.size(); ++t) {
    // A remembered fruitlet is looked for by every view but the remembered ones: they come
    // first and show where the cluster was, so they cannot tell gone from not yet sized; the
    // views after them, aimed at it or at the cluster, can.
    const bool counts = target_expected_[t] ? chosen.kind != planner::CandidateKind::kRemembered
                                            : int(t) == aimed_target || target_unconfirmed_[t] ||
                                                  only_evidence_holds;
    if (!counts) continue;
    if (Aim* aim = findAim(targets_[t].center_m))
      ++aim->views;
    else
      aims_.push_back({targets_[t].center_m, static_cast<int>(targets_[t].seen_from.size()), 1,
                       target_unconfirmed_[t]});
  }
}

void SizingGuidance::expect(std::vector<RememberedFruitlet> fruitlets_tag, TagPoseFn T_world_tag,
                            double max_shift_m) {
  if (!(max_shift_m > 0.0) || !std::isfinite(max_shift_m))
    throw std::invalid_argument("SizingGuidance::expect: max_shift_m: expected > 0");
  if (!T_world_tag) throw std::invalid_argument("SizingGuidance::expect: no tag pose");
  expected_ = std::move(fruitlets_tag);
  T_world_tag_ = std::move(T_world_tag);
  max_shift_m_ = max_shift_m;
}

void SizingGuidance::seekExpected() {
  expected_found_ = expected_gone_ = 0;
  fruitlets_known_ = false;
  if (expected_.empty()) return;
  const std::optional<Eigen::Isometry3d>& T_world_tag = T_world_tag_();
  if (!T_world_tag) return;
  const SizingSnapshot& latest = history_.back();
  std::vector<const FruitletSnapshot*> sized;
  for (const FruitletSnapshot& f : latest.fruitlets) sized.push_back(&f);
  // A partly seen detection is not the remembered fruitlet found: it may be a scrap of leaf
  // near where the fruitlet was, and the final sizing does not report it.
  for (const FruitletSnapshot& f : latest.unconfirmed)
    if (!f.partly_seen) sized.push_back(&f);
  // Where each was, in the maps' frame, where the snapshot's centres and the tag seen on this
  // visit both are (remembered centres are in the tag frame of the earlier visit's maps:
  // eval::addTagFrame).
  std::vector<Eigen::Vector3d> where;
  for (const RememberedFruitlet& f : expected_) where.push_back(*T_world_tag * f.center_tag_m);
  const std::vector<int> found = assignOneToOne(where.size(), sized.size(), [&](auto e, auto s) {
    const double d = (where[e] - sized[s]->center_m).norm();
    return d <= max_shift_m_ ? d : std::numeric_limits<double>::infinity();
  });
  std::size_t found_kept = 0;  // sized[0, latest.fruitlets.size()) are the kept ones
  for (std::size_t e = 0; e < where.size(); ++e) {
    if (found[e] >= 0) {
      ++expected_found_;
      found_kept += std::size_t(found[e]) < latest.fruitlets.size();
      continue;
    }
    if (const Aim* aim = findAim(where[e]); aim && aim->views >= max_aimed_views_) {
      ++expected_gone_;
      continue;
    }
    planner::SizingTarget target;
    target.center_m = where[e];
    target.radius_m = 0.5e-3 * expected_[e].size_mm;
    target.min_angle_deg = config_.min_view_span_deg;
    target.min_visible_fraction = min_visible_fraction_;
    targets_.push_back(std::move(target));
    target_unconfirmed_.push_back(false);
    target_expected_.push_back(true);
  }
  fruitlets_known_ = found_kept == expected_.size() && found_kept == latest.fruitlets.size();
}

void SizingGuidance::onView(const ViewEvent& event) {
  targets_.clear();
  target_unconfirmed_.clear();
  target_expected_.clear();
  // No sizing for this view (no Cluster Region yet): nothing to aim at.
  if (history_.empty() || history_.back().view != event.index) {
    planner_.setSizingTargets({});
    return;
  }
  std::vector<const FruitletSnapshot*> candidates;
  for (const FruitletSnapshot& f : history_.back().fruitlets) candidates.push_back(&f);
  for (const FruitletSnapshot& f : history_.back().unconfirmed) candidates.push_back(&f);
  for (const FruitletSnapshot* candidate : candidates) {
    const FruitletSnapshot& f = *candidate;
    if (!lacksEvidence(f, config_)) continue;
    if (Aim* aim = findAim(f.center_m)) {
      // A new well-seen image, or a detection kept now that was looked at as unconfirmed or
      // partly seen (its count was of sized images, not well-seen ones): the count starts again.
      if (!f.unconfirmed && (aim->for_unconfirmed || f.well_seen_images > aim->well_seen_images)) {
        *aim = aims_.back();
        aims_.pop_back();
      } else if (aim->views >= max_aimed_views_) {
        if (aim->views == max_aimed_views_) {
          ++dropped_;
          ++aim->views;  // counted once
        }
        continue;
      }
    }
    planner::SizingTarget target;
    target.center_m = f.center_m;
    target.radius_m = 0.5e-3 * f.size_mm;
    target.seen_from = f.well_seen_directions;
    target.min_angle_deg = config_.min_view_span_deg;
    target.min_visible_fraction = min_visible_fraction_;
    targets_.push_back(std::move(target));
    target_unconfirmed_.push_back(f.unconfirmed);
    target_expected_.push_back(false);
  }
  seekExpected();
  planner_.setSizingTargets(targets_);
}

}  // namespace fvp::host::nbv
