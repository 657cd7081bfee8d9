#include "fvp/host/nbv/remembered_views.h"

#include <stdexcept>
#include <utility>

namespace fvp::host::nbv {

RememberedViews::RememberedViews(std::unique_ptr<planner::ViewPlanner> planner,
                                 TagPoseFn T_world_tag, std::vector<Eigen::Isometry3d> T_tag_camera)
    : planner_(std::move(planner)),
      T_world_tag_(std::move(T_world_tag)),
      T_tag_camera_(std::move(T_tag_camera)),
      done_(T_tag_camera_.size(), false) {
  if (!planner_) throw std::invalid_argument("RememberedViews: no planner to wrap");
  if (!T_world_tag_) throw std::invalid_argument("RememberedViews: no tag pose");
}

std::optional<planner::Ranking> RememberedViews::rank(map::MapEngine& map,
                                                      const Eigen::Isometry3d& T_world_camera_now,
                                                      const planner::ReachabilityFn& reachable,
                                                      std::size_t round, planner::PlanStep& step) {
  if (round == 0) offered_ = false;
  round_remembered_ = false;
  const std::optional<Eigen::Isometry3d>& T_world_tag = T_world_tag_();
  if (round == 0 && pending() && T_world_tag) {
    planner::Ranking ranking;
    const Eigen::Vector3d tag_m = T_world_tag->translation();
    for (std::size_t k = 0; k < T_tag_camera_.size(); ++k) {
      if (done_[k]) continue;
      planner::Candidate c;
      c.kind = planner::CandidateKind::kRemembered;
      c.T_world_camera = *T_world_tag * T_tag_camera_[k];
      c.target_m = tag_m;
      c.reachable = !reachable || reachable(c.T_world_camera);
      if (!c.reachable) {  // the robot stands elsewhere today: this view is out of reach
        done_[k] = true;
        continue;
      }
      c.ig = c.utility = 1.0;                 // alike: the robot's time orders them
      c.sizing_target = static_cast<int>(k);  // which remembered view (movedTo reads it)
      ranking.order.push_back(ranking.candidates.size());
      ranking.candidates.push_back(c);
    }
    if (!ranking.candidates.empty()) {
      offered_ = round_remembered_ = true;
      return ranking;
    }
  }
  // Round 0 went to the remembered views: the wrapped planner's rounds start at 1.
  return planner_->rank(map, T_world_camera_now, reachable, offered_ ? round - 1 : round, step);
}

void RememberedViews::roundDone(bool moved) {
  if (!round_remembered_) return planner_->roundDone(moved);
  // The arm reached none of them (no IK, no path): plan from here on.
  if (!moved) given_up_ = true;
}

void RememberedViews::movedTo(const planner::Candidate& chosen) {
  if (chosen.kind != planner::CandidateKind::kRemembered) return planner_->movedTo(chosen);
  const auto k = static_cast<std::size_t>(chosen.sizing_target);
  if (chosen.sizing_target < 0 || k >= done_.size() || done_[k])
    throw std::logic_error("RememberedViews::movedTo: not a view it offered");
  done_[k] = true;
  ++taken_;
}

}  // namespace fvp::host::nbv
