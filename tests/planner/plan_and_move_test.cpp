// Planners rank, the loop acts: planAndMove tries each round's ranked views in order, counts
// every move, tells the planner how each round went and stops at the first move that works.
#include <gtest/gtest.h>

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

TEST(PlanAndMove, GivesUpWhenThePlannerHasNoRoundLeft) {
  ScriptedPlanner planner(2, 2);
  const PlanStep step = planAndMove(planner, someMap(), Eigen::Isometry3d::Identity(), {},
                                    [](const Eigen::Isometry3d&) { return false; });
  EXPECT_FALSE(step.moved());
  EXPECT_EQ(step.move_attempts, 4u);
  EXPECT_EQ(step.failed_moves, 4u);
  EXPECT_EQ(planner.outcomes, (std::vector<bool>{false, false}));
  EXPECT_EQ(step.candidates.size(), 2u);  // the last round's
}

}  // namespace
}  // namespace fvp::host::planner
