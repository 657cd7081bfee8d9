// Planners rank, the loop acts: planAndMove tries each round's ranked views in order, counts
// every move, tells the planner how each round went and stops at the first move that works.
// With the arm's goal check, views it turns down are skipped before a move is tried and
// counted apart from the failed moves.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "fvp/host/core/cluster_region.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/planner/view_planner.h"
#include "planner_test_maps.h"

namespace fvp::host::planner {
namespace {

/// Ranks `per_round` views a round, for `rounds` rounds; view k of round r sits at x = 10 r + k.
class ScriptedPlanner : public ViewPlanner {
 public:
  ScriptedPlanner(std::size_t rounds, std::size_t per_round)
      : rounds_(rounds), per_round_(per_round) {}
  std::string_view name() const override { return "scripted"; }
  std::string configJson() const override { return "{}"; }
  std::optional<Ranking> rank(map::MapEngine&, const Eigen::Isometry3d&, const ReachabilityFn&,
                              std::size_t round, PlanStep& step) override {
    if (round >= rounds_) return std::nullopt;
    ++step.sampling_rounds;
    Ranking ranking;
    for (std::size_t k = 0; k < per_round_; ++k) {
      Candidate c;
      c.T_world_camera.translation().x() = 10.0 * round + k;
      ranking.candidates.push_back(c);
    }
    // Best last: the order, not the index, is what the loop follows.
    for (std::size_t k = per_round_; k-- > 0;) ranking.order.push_back(k);
    return ranking;
  }
  void roundDone(bool moved) override { outcomes.push_back(moved); }
  std::vector<bool> outcomes;

 private:
  std::size_t rounds_, per_round_;
};

/// A small octomap engine (ScriptedPlanner never reads it).
map::MapEngine& someMap() {
  static const std::unique_ptr<map::MapEngine> engine = map::createMapEngine(
      "octomap", testing::plannerTestConfig(), testing::kPlannerTestRegion, nullptr);
  return *engine;
}

TEST(PlanAndMove, TriesRankedViewsInOrderAndStopsAtTheFirstMove) {
  ScriptedPlanner planner(3, 3);
  std::vector<double> tried;
  const PlanStep step = planAndMove(planner, someMap(), Eigen::Isometry3d::Identity(), {},
                                    [&](const Eigen::Isometry3d& T) {
                                      tried.push_back(T.translation().x());
                                      return T.translation().x() == 11.0;  // round 1's middle view
                                    });
  EXPECT_EQ(tried, (std::vector<double>{2, 1, 0, 12, 11}));
  EXPECT_EQ(step.move_attempts, 5u);
  EXPECT_EQ(step.failed_moves, 4u);
  ASSERT_TRUE(step.moved());
  EXPECT_EQ(*step.chosen, 1u);
  EXPECT_DOUBLE_EQ(step.candidates[*step.chosen].T_world_camera.translation().x(), 11.0);
  EXPECT_EQ(planner.outcomes, (std::vector<bool>{false, true}));
  EXPECT_EQ(step.sampling_rounds, 2u);
}

TEST(PlanAndMove, GiveUpEndsTheIterationAfterAFailedMove) {
  ScriptedPlanner planner(3, 3);
  std::vector<double> tried;
  std::size_t asked = 0;
  const PlanStep step = planAndMove(
      planner, someMap(), Eigen::Isometry3d::Identity(), {},
      [&](const Eigen::Isometry3d& T) {
        tried.push_back(T.translation().x());
        return T.translation().x() == 10.0;  // round 1's last: never reached
      },
      {}, kDefaultGoalCheckBatch, 0.0, [&] { return ++asked == 4; });
  EXPECT_EQ(tried, (std::vector<double>{2, 1, 0, 12}));  // into round 1, then no more
  EXPECT_EQ(asked, 4u);                                  // once after each failed move
  EXPECT_TRUE(step.gave_up);
  EXPECT_FALSE(step.moved());
  EXPECT_EQ(step.move_attempts, 4u);
  EXPECT_EQ(step.failed_moves, 4u);
  // The cut round is told it moved nowhere, and no round follows it.
  EXPECT_EQ(planner.outcomes, (std::vector<bool>{false, false}));
  EXPECT_EQ(step.sampling_rounds, 2u);
}

TEST(PlanAndMove, GivesUpWhenThePlannerHasNoRoundLeft) {
  ScriptedPlanner planner(2, 2);
  const PlanStep step = planAndMove(planner, someMap(), Eigen::Isometry3d::Identity(), {},
                                    [](const Eigen::Isometry3d&) { return false; });
  EXPECT_FALSE(step.moved());
  EXPECT_EQ(step.move_attempts, 4u);
  EXPECT_EQ(step.failed_moves, 4u);
  EXPECT_EQ(planner.outcomes, (std::vector<bool>{false, false}));
  EXPECT_EQ(step.candidates.size(), 2u);  // the last round's
  EXPECT_FALSE(step.gave_up);             // no give_up given
}

/// A goal check by the view's x: 1 has no IK, 2 only IK solutions in collision, the rest pass.
/// Records the x of every pose it is asked about, batch by batch.
struct ScriptedGoalCheck {
  std::vector<std::vector<double>> batches;
  GoalCheckFn fn() {
    return [this](const std::vector<Eigen::Isometry3d>& poses) {
      batches.emplace_back();
      std::vector<GoalReach> out;
      for (const Eigen::Isometry3d& T : poses) {
        const double x = T.translation().x();
        batches.back().push_back(x);
        out.push_back({x == 1.0   ? GoalCheck::kNoIk
                       : x == 2.0 ? GoalCheck::kNoCollisionFreeIk
                                  : GoalCheck::kFeasible});
      }
      return out;
    };
  }
};

TEST(PlanAndMove, ViewsTheGoalCheckTurnsDownAreNotTriedAndAreCountedApart) {
  ScriptedPlanner planner(2, 4);  // round 0 ranks 3, 2, 1, 0
  ScriptedGoalCheck check;
  std::vector<double> tried;
  const PlanStep step = planAndMove(
      planner, someMap(), Eigen::Isometry3d::Identity(), {},
      [&](const Eigen::Isometry3d& T) {
        tried.push_back(T.translation().x());
        return T.translation().x() == 0.0;
      },
      check.fn());
  EXPECT_EQ(tried, (std::vector<double>{3, 0}));  // 2 and 1 never reach the arm's planner
  EXPECT_EQ(step.move_attempts, 2u);
  EXPECT_EQ(step.failed_moves, 1u);
  EXPECT_EQ(step.rejected_no_ik, 1u);
  EXPECT_EQ(step.rejected_no_collision_free_ik, 1u);
  EXPECT_EQ(step.goal_checks, 4u);
  EXPECT_EQ(step.goal_check_batches, 1u);
  ASSERT_TRUE(step.moved());
  EXPECT_DOUBLE_EQ(step.candidates[*step.chosen].T_world_camera.translation().x(), 0.0);
  EXPECT_EQ(planner.outcomes, (std::vector<bool>{true}));
}

TEST(PlanAndMove, ChecksABatchAheadOfTheMovesAndNoFurther) {
  ScriptedGoalCheck check;
  ScriptedPlanner first_moves(1, 5);  // ranks 4, 3, 2, 1, 0; the first move works
  const PlanStep moved = planAndMove(
      first_moves, someMap(), Eigen::Isometry3d::Identity(), {},
      [](const Eigen::Isometry3d&) { return true; }, check.fn(), 2);
  EXPECT_EQ(check.batches, (std::vector<std::vector<double>>{{4, 3}}));
  EXPECT_EQ(moved.goal_checks, 2u);

  check.batches.clear();
  ScriptedPlanner none_move(1, 5);
  const PlanStep failed = planAndMove(
      none_move, someMap(), Eigen::Isometry3d::Identity(), {},
      [](const Eigen::Isometry3d&) { return false; }, check.fn(), 2);
  EXPECT_EQ(check.batches, (std::vector<std::vector<double>>{{4, 3}, {2, 1}, {0}}));
  EXPECT_EQ(failed.goal_check_batches, 3u);
  EXPECT_EQ(failed.goal_checks, 5u);
  EXPECT_EQ(failed.move_attempts, 3u);  // 4, 3 and 0: 2 and 1 turned down
  EXPECT_EQ(failed.failed_moves, 3u);
  EXPECT_FALSE(failed.moved());
}

/// Ranks the views it is given (ig and x) in the order given, in one round.
class GivenRanking : public ViewPlanner {
 public:
  explicit GivenRanking(std::vector<double> igs) : igs_(std::move(igs)) {}
  std::string_view name() const override { return "given"; }
  std::string configJson() const override { return "{}"; }
  std::optional<Ranking> rank(map::MapEngine&, const Eigen::Isometry3d&, const ReachabilityFn&,
                              std::size_t round, PlanStep&) override {
    if (round > 0) return std::nullopt;
    Ranking ranking;
    for (std::size_t k = 0; k < igs_.size(); ++k) {
      Candidate c;
      c.ig = igs_[k];
      c.T_world_camera.translation().x() = static_cast<double>(k);
      ranking.candidates.push_back(c);
      ranking.order.push_back(k);
    }
    return ranking;
  }

 private:
  std::vector<double> igs_;
};

TEST(PlanAndMove, ACheckedBatchIsTriedByInformationPerSecond) {
  // Views 0-3 (igs 4, 3, 2, 1) reached in 7, 1, 0.1 and 1 s; view 4 in the next batch.
  // With 1 s of overhead a view: rates 0.5, 1.5, 1.82, 0.5, so 2, 1, then 0 and 3 as ranked.
  GivenRanking planner({4.0, 3.0, 2.0, 1.0, 10.0});
  const std::vector<double> travel_s{7.0, 1.0, 0.1, 1.0, 0.0};
  const GoalCheckFn check = [&](const std::vector<Eigen::Isometry3d>& poses) {
    std::vector<GoalReach> out;
    for (const Eigen::Isometry3d& T : poses)
      out.push_back(
          {GoalCheck::kFeasible, travel_s.at(static_cast<std::size_t>(T.translation().x()))});
    return out;
  };
  std::vector<double> tried;
  const auto fail = [&](const Eigen::Isometry3d& T) {
    tried.push_back(T.translation().x());
    return false;
  };
  planAndMove(planner, someMap(), Eigen::Isometry3d::Identity(), {}, fail, check, 4, 1.0);
  // The batch by rate; the next batch after it, never mixed in.
  EXPECT_EQ(tried, (std::vector<double>{2, 1, 0, 3, 4}));
  // Without the overhead (0: off) or without travel times, the planner's order.
  tried.clear();
  GivenRanking again({4.0, 3.0, 2.0, 1.0, 10.0});
  planAndMove(again, someMap(), Eigen::Isometry3d::Identity(), {}, fail, check, 4, 0.0);
  EXPECT_EQ(tried, (std::vector<double>{0, 1, 2, 3, 4}));
  tried.clear();
  GivenRanking unknown({4.0, 3.0, 2.0, 1.0, 10.0});
  ScriptedGoalCheck no_times;
  planAndMove(unknown, someMap(), Eigen::Isometry3d::Identity(), {}, fail, no_times.fn(), 4, 1.0);
  EXPECT_EQ(tried, (std::vector<double>{0, 3, 4}));  // 1 and 2 turned down, as scripted
}

TEST(PlanAndMove, WithoutAGoalCheckEveryRankedViewIsTried) {
  ScriptedPlanner planner(1, 3);
  const PlanStep step = planAndMove(planner, someMap(), Eigen::Isometry3d::Identity(), {},
                                    [](const Eigen::Isometry3d&) { return false; });
  EXPECT_EQ(step.move_attempts, 3u);
  EXPECT_EQ(step.goal_checks, 0u);
  EXPECT_EQ(step.rejected_no_ik + step.rejected_no_collision_free_ik, 0u);
}

TEST(PlanAndMove, AGoalCheckThatDoesNotAnswerForEveryPoseThrows) {
  ScriptedPlanner planner(1, 3);
  const GoalCheckFn mute = [](const std::vector<Eigen::Isometry3d>&) {
    return std::vector<GoalReach>{};
  };
  EXPECT_THROW(planAndMove(
                   planner, someMap(), Eigen::Isometry3d::Identity(), {},
                   [](const Eigen::Isometry3d&) { return false; }, mute),
               std::runtime_error);
  EXPECT_STREQ(toString(GoalCheck::kNoCollisionFreeIk), "no_collision_free_ik");
}

}  // namespace
}  // namespace fvp::host::planner
