// A planner that first takes an earlier visit's views (visit_memory.h), then plans as the one it
// wraps (docs/season.md, "Visits remembered"). The views are in the cluster tag's frame and
// enter this visit's world once the session has seen the tag; each planning iteration offers
// those not yet taken, each with the same gain, so the loop's ranking by the robot's time
// (planAndMove) takes the nearest one the arm can reach. An iteration in which none can be
// reached ends the memory: the wrapped planner takes over.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "fvp/host/planner/view_planner.h"

namespace fvp::host::nbv {

/// The tag's pose on this visit, empty until a view saw it (MappingSession::T_world_tag).
using TagPoseFn = std::function<const std::optional<Eigen::Isometry3d>&()>;

class RememberedViews : public planner::ViewPlanner {
 public:
  RememberedViews(std::unique_ptr<planner::ViewPlanner> planner, TagPoseFn T_world_tag,
                  std::vector<Eigen::Isometry3d> T_tag_camera);

  std::string_view name() const override { return planner_->name(); }
  std::optional<planner::Ranking> rank(map::MapEngine& map,
                                       const Eigen::Isometry3d& T_world_camera_now,
                                       const planner::ReachabilityFn& reachable, std::size_t round,
                                       planner::PlanStep& step) override;
  void roundDone(bool moved) override;
  void movedTo(const planner::Candidate& chosen) override;
  std::string configJson() const override { return planner_->configJson(); }
  void setSizingTargets(std::vector<planner::SizingTarget> targets) override {
    planner_->setSizingTargets(std::move(targets));
  }

  /// Remembered views, and those the arm moved to.
  std::size_t remembered() const { return T_tag_camera_.size(); }
  std::size_t taken() const { return taken_; }
  /// Whether views remain to offer (none before the tag is seen counts as remaining).
  bool pending() const {
    return !given_up_ && std::find(done_.begin(), done_.end(), false) != done_.end();
  }

 private:
  std::unique_ptr<planner::ViewPlanner> planner_;
  TagPoseFn T_world_tag_;
  std::vector<Eigen::Isometry3d> T_tag_camera_;
  std::vector<bool> done_;  ///< per remembered view: taken or found unreachable
  std::size_t taken_ = 0;
  bool given_up_ = false;
  bool offered_ = false;           ///< this iteration's round 0 offered remembered views
  bool round_remembered_ = false;  ///< the round now running offers them
};

}  // namespace fvp::host::nbv
