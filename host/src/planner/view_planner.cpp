#include "fvp/host/planner/view_planner.h"

#include <algorithm>
#include <cmath>
#include <limits>
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
                    std::vector<GoalReach>& checked, PlanStep& step) {
  const std::size_t first = checked.size();
  const std::size_t end = std::min(order.size(), first + std::max<std::size_t>(batch, 1));
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(end - first);
  for (std::size_t k = first; k < end; ++k) poses.push_back(candidates.at(order[k]).T_world_camera);
  const std::vector<GoalReach> statuses = check_goals(poses);
  // A check that does not answer for every pose is a broken arm, not an expected outcome.
  if (statuses.size() != poses.size())
    throw std::runtime_error("planAndMove: the goal check answered " +
                             std::to_string(statuses.size()) + " of " +
                             std::to_string(poses.size()) + " poses");
  ++step.goal_check_batches;
  step.goal_checks += poses.size();
  for (const GoalReach& answer : statuses) {
    if (answer.check == GoalCheck::kNoIk) ++step.rejected_no_ik;
    if (answer.check == GoalCheck::kNoCollisionFreeIk) ++step.rejected_no_collision_free_ik;
  }
  checked.insert(checked.end(), statuses.begin(), statuses.end());
}

/// Within order[first, checked.size()) (a checked batch), the feasible views by information
/// per second of the robot's time, ig / (travel_s + view_overhead_s), best first (ties keep
/// the planner's order); the others after them. Left as ranked when a travel time is unknown.
void rankBatchByInformationRate(const std::vector<Candidate>& candidates,
                                std::vector<std::size_t>& order, std::vector<GoalReach>& checked,
                                std::size_t first, double view_overhead_s) {
  const std::size_t end = checked.size();
  for (std::size_t k = first; k < end; ++k)
    if (checked[k].feasible() && !std::isfinite(checked[k].travel_s)) return;
  // Each view with its answer and its rate, sorted together and written back in place.
  struct Entry {
    std::size_t candidate;
    GoalReach answer;
    double rate;
  };
  std::vector<Entry> batch;
  for (std::size_t k = first; k < end; ++k) {
    const GoalReach& a = checked[k];
    batch.push_back({order[k], a,
                     a.feasible() ? candidates.at(order[k]).ig / (a.travel_s + view_overhead_s)
                                  : -std::numeric_limits<double>::infinity()});
  }
  std::stable_sort(batch.begin(), batch.end(),
                   [](const Entry& a, const Entry& b) { return a.rate > b.rate; });
  for (std::size_t i = 0; i < batch.size(); ++i) {
    order[first + i] = batch[i].candidate;
    checked[first + i] = batch[i].answer;
  }
}

}  // namespace

PlanStep planAndMove(ViewPlanner& planner, map::MapEngine& map,
                     const Eigen::Isometry3d& T_world_camera_now, const ReachabilityFn& reachable,
                     const MoveToPoseFn& move, const GoalCheckFn& check_goals,
                     std::size_t goal_check_batch, double view_overhead_s,
                     const GiveUpFn& give_up) {
  PlanStep step;
  for (std::size_t round = 0;; ++round) {
    std::optional<Ranking> ranking = planner.rank(map, T_world_camera_now, reachable, round, step);
    if (!ranking) break;
    step.candidates = std::move(ranking->candidates);
    // Answers for order[0, checked.size()): checked a batch at a time, only as far as the
    // moves get, so a round whose first view is reached pays for one batch.
    std::vector<std::size_t>& order = ranking->order;
    std::vector<GoalReach> checked;
    for (std::size_t k = 0; k < order.size(); ++k) {
      if (check_goals) {
        if (k == checked.size()) {
          checkNextBatch(check_goals, goal_check_batch, step.candidates, order, checked, step);
          if (view_overhead_s > 0.0)
            rankBatchByInformationRate(step.candidates, order, checked, k, view_overhead_s);
        }
        if (!checked[k].feasible()) continue;
      }
      const std::size_t i = order[k];
      ++step.move_attempts;
      if (move(step.candidates.at(i).T_world_camera)) {
        step.chosen = i;
        planner.movedTo(step.candidates[i]);
        break;
      }
      ++step.failed_moves;
      if (give_up && give_up()) {
        step.gave_up = true;
        break;
      }
    }
    planner.roundDone(step.moved());
    if (step.moved() || step.gave_up) break;
  }
  return step;
}

}  // namespace fvp::host::planner
