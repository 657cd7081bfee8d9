#include "fvp/host/planner/view_planner.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace fvp::host::planner {

const char* toString(GoalCheck check) {
  switch (check) {
    case GoalCheck::kFeasible:
      return "feasible";
    case GoalCheck::kNoIk:
      return "no_ik";
    case GoalCheck::kNoCollisionFreeIk:
      return "no_collision_free_ik";
  }
  return "unknown";
}

namespace {

/// Checks the next batch of a round's ranked views (from order[checked.size()]) and appends
/// their statuses to checked.
void checkNextBatch(const GoalCheckFn& check_goals, std::size_t batch,
                    const std::vector<Candidate>& candidates, const std::vector<std::size_t>& order,
                    std::vector<GoalCheck>& checked, PlanStep& step) {
  const std::size_t first = checked.size();
  const std::size_t end = std::min(order.size(), first + std::max<std::size_t>(batch, 1));
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(end - first);
  for (std::size_t k = first; k < end; ++k) poses.push_back(candidates.at(order[k]).T_world_camera);
  const std::vector<GoalCheck> statuses = check_goals(poses);
  // A check that does not answer for every pose is a broken arm, not an expected outcome.
  if (statuses.size() != poses.size())
    throw std::runtime_error("planAndMove: the goal check answered " +
                             std::to_string(statuses.size()) + " of " +
                             std::to_string(poses.size()) + " poses");
  ++step.goal_check_batches;
  step.goal_checks += poses.size();
  checked.insert(checked.end(), statuses.begin(), statuses.end());
}

}  // namespace

PlanStep planAndMove(ViewPlanner& planner, map::MapEngine& map,
                     const Eigen::Isometry3d& T_world_camera_now, const ReachabilityFn& reachable,
                     const MoveToPoseFn& move, const GoalCheckFn& check_goals,
                     std::size_t goal_check_batch) {
  PlanStep step;
  for (std::size_t round = 0;; ++round) {
    std::optional<Ranking> ranking = planner.rank(map, T_world_camera_now, reachable, round, step);
    if (!ranking) break;
    step.candidates = std::move(ranking->candidates);
    // Statuses of order[0, checked.size()): checked a batch at a time, only as far as the
    // moves get, so a round whose first view is reached pays for one batch.
    std::vector<GoalCheck> checked;
    for (std::size_t k = 0; k < ranking->order.size(); ++k) {
      if (check_goals) {
        if (k == checked.size())
          checkNextBatch(check_goals, goal_check_batch, step.candidates, ranking->order, checked,
                         step);
        if (checked[k] == GoalCheck::kNoIk) ++step.rejected_no_ik;
        if (checked[k] == GoalCheck::kNoCollisionFreeIk) ++step.rejected_no_collision_free_ik;
        if (checked[k] != GoalCheck::kFeasible) continue;
      }
      const std::size_t i = ranking->order[k];
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
