#include "fvp/host/planner/view_planner.h"

namespace fvp::host::planner {

PlanStep planAndMove(ViewPlanner& planner, map::MapEngine& map,
                     const Eigen::Isometry3d& T_world_camera_now, const ReachabilityFn& reachable,
                     const MoveToPoseFn& move) {
  PlanStep step;
  for (std::size_t round = 0;; ++round) {
    std::optional<Ranking> ranking = planner.rank(map, T_world_camera_now, reachable, round, step);
    if (!ranking) break;
    step.candidates = std::move(ranking->candidates);
    for (const std::size_t i : ranking->order) {
      ++step.move_attempts;
      if (move(step.candidates.at(i).T_world_camera)) {
        step.chosen = i;
        break;
      }
      ++step.failed_moves;
    }
    planner.roundDone(step.moved());
    if (step.moved()) break;
  }
  return step;
}

}  // namespace fvp::host::planner
