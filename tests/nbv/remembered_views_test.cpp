// A later visit's remembered views (host/nbv/remembered_views.h) through the loop's
// planAndMove: none before the tag is seen; then the earlier views, carried into this visit's
// world by the tag, before any planning, each taken once; one the arm cannot reach is
// skipped; an iteration that reaches none ends the memory and the wrapped planner plans on
// from its own round 0.
#include "fvp/host/nbv/remembered_views.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "../planner/planner_test_maps.h"
#include "fvp/host/map/map_engine.h"

namespace fvp::host::nbv {
namespace {

using planner::Candidate;
using planner::CandidateKind;

/// Ranks one exploration view a round at x = 100 + round; records what it hears.
class InnerPlanner : public planner::ViewPlanner {
 public:
  std::string_view name() const override { return "inner"; }
  std::string configJson() const override { return "{\"inner\":true}"; }
  std::optional<planner::Ranking> rank(map::MapEngine&, const Eigen::Isometry3d&,
                                       const planner::ReachabilityFn&, std::size_t round,
                                       planner::PlanStep&) override {
    rounds.push_back(round);
    if (round >= 2) return std::nullopt;
    planner::Ranking ranking;
    Candidate c;
    c.kind = CandidateKind::kExploration;
    c.T_world_camera.translation().x() = 100.0 + double(round);
    ranking.candidates = {c};
    ranking.order = {0};
    return ranking;
  }
  void roundDone(bool moved) override { outcomes.push_back(moved); }
  void movedTo(const Candidate& chosen) override { moved_to.push_back(chosen.kind); }
  std::vector<std::size_t> rounds;
  std::vector<bool> outcomes;
  std::vector<CandidateKind> moved_to;
};

map::MapEngine& someMap() {
  static const std::unique_ptr<map::MapEngine> engine =
      map::createMapEngine("octomap", planner::testing::plannerTestConfig(),
                           planner::testing::kPlannerTestRegion, nullptr);
  return *engine;
}

Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

struct Fixture {
  std::optional<Eigen::Isometry3d> T_world_tag;
  InnerPlanner* inner = nullptr;
  std::unique_ptr<RememberedViews> planner;
  explicit Fixture(std::vector<Eigen::Isometry3d> T_tag_camera) {
    auto owned = std::make_unique<InnerPlanner>();
    inner = owned.get();
    planner = std::make_unique<RememberedViews>(
        std::move(owned),
        [this]() -> const std::optional<Eigen::Isometry3d>& { return T_world_tag; },
        std::move(T_tag_camera));
  }
  planner::PlanStep plan(const planner::MoveToPoseFn& move,
                         const planner::ReachabilityFn& reachable = {}) {
    return planner::planAndMove(*planner, someMap(), Eigen::Isometry3d::Identity(), reachable, move,
                                {}, 8, 0.0);
  }
};

TEST(RememberedViews, PlansAsTheWrappedPlannerUntilTheTagIsSeen) {
  Fixture f({at(0.1, 0, 0)});
  const planner::PlanStep step = f.plan([](const Eigen::Isometry3d&) { return true; });
  ASSERT_TRUE(step.moved());
  EXPECT_EQ(step.candidates[*step.chosen].kind, CandidateKind::kExploration);
  EXPECT_EQ(f.inner->rounds, std::vector<std::size_t>{0});
  EXPECT_EQ(f.inner->outcomes, std::vector<bool>{true});
  EXPECT_TRUE(f.planner->pending());
  EXPECT_EQ(f.planner->name(), "inner");
  EXPECT_EQ(f.planner->configJson(), "{\"inner\":true}");
}

TEST(RememberedViews, TakesEachEarlierViewOnceInThisVisitsWorldThenPlans) {
  Fixture f({at(0.1, 0, 0), at(0.2, 0, 0), at(0.3, 0, 0)});
  f.T_world_tag = at(1.0, 2.0, 3.0);  // the tree seen from where the robot stands today
  std::vector<double> moved_x;
  const auto move = [&](const Eigen::Isometry3d& T) {
    moved_x.push_back(T.translation().x());
    return true;
  };
  // The view at 1.2 is out of the arm's reach today: skipped, never offered again.
  const auto reachable = [](const Eigen::Isometry3d& T) {
    return std::abs(T.translation().x() - 1.2) > 1e-9;
  };
  for (int iteration = 0; iteration < 2; ++iteration) {
    const planner::PlanStep step = f.plan(move, reachable);
    ASSERT_TRUE(step.moved());
    const Candidate& c = step.candidates[*step.chosen];
    EXPECT_EQ(c.kind, CandidateKind::kRemembered);
    EXPECT_DOUBLE_EQ(c.T_world_camera.translation().y(), 2.0);
    EXPECT_DOUBLE_EQ(c.T_world_camera.translation().z(), 3.0);
  }
  EXPECT_EQ(moved_x.size(), 2u);
  EXPECT_NE(moved_x[0], moved_x[1]);
  for (const double x : moved_x) EXPECT_TRUE(std::abs(x - 1.1) < 1e-9 || std::abs(x - 1.3) < 1e-9);
  EXPECT_TRUE(f.inner->rounds.empty()) << "no planning while remembered views remain";
  EXPECT_EQ(f.planner->taken(), 2u);
  EXPECT_FALSE(f.planner->pending());
  // Memory spent: the wrapped planner plans, from its round 0.
  const planner::PlanStep step = f.plan(move, reachable);
  EXPECT_EQ(step.candidates[*step.chosen].kind, CandidateKind::kExploration);
  EXPECT_EQ(f.inner->rounds, std::vector<std::size_t>{0});
  EXPECT_EQ(f.inner->moved_to, std::vector<CandidateKind>{CandidateKind::kExploration});
}

TEST(RememberedViews, AnIterationThatReachesNoneEndsTheMemory) {
  Fixture f({at(0.1, 0, 0), at(0.2, 0, 0)});
  f.T_world_tag = Eigen::Isometry3d::Identity();
  // Every remembered move fails (leaves grew into the way); the planner's own view works.
  const planner::PlanStep step =
      f.plan([](const Eigen::Isometry3d& T) { return T.translation().x() >= 100.0; });
  ASSERT_TRUE(step.moved());
  EXPECT_EQ(step.failed_moves, 2u);
  EXPECT_EQ(step.candidates[*step.chosen].kind, CandidateKind::kExploration);
  // Round 0 went to the memory: the wrapped planner's first round is its round 0.
  EXPECT_EQ(f.inner->rounds, std::vector<std::size_t>{0});
  EXPECT_EQ(f.inner->outcomes, std::vector<bool>{true});
  EXPECT_FALSE(f.planner->pending());
  EXPECT_EQ(f.planner->taken(), 0u);
}

TEST(RememberedViews, RejectsAMissingPlannerOrTagPose) {
  EXPECT_THROW(RememberedViews(nullptr,
                               []() -> const std::optional<Eigen::Isometry3d>& {
                                 static const std::optional<Eigen::Isometry3d> none;
                                 return none;
                               },
                               {}),
               std::invalid_argument);
  EXPECT_THROW(RememberedViews(std::make_unique<InnerPlanner>(), {}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::host::nbv
