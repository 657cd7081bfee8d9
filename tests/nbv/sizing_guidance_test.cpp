// The sizing guidance on constructed sizing histories: only fruitlets short of the stop's
// evidence become targets, with their well-seen directions; a fruitlet aimed at twice without
// a new well-seen image is dropped, and one that gains an image is aimed at again; detections
// not kept (unconfirmed, partly seen) are looked at for a bounded number of views.
#include "fvp/host/nbv/sizing_guidance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>

namespace fvp::host::nbv {
namespace {

// Records what the guidance hands over.
class RecordingPlanner : public planner::ViewPlanner {
 public:
  std::string_view name() const override { return "recording"; }
  std::optional<planner::Ranking> rank(map::MapEngine&, const Eigen::Isometry3d&,
                                       const planner::ReachabilityFn&, std::size_t,
                                       planner::PlanStep&) override {
    return std::nullopt;
  }
  std::string configJson() const override { return "{}"; }
  void setSizingTargets(std::vector<planner::SizingTarget> targets) override {
    targets_ = std::move(targets);
    ++calls_;
  }
  std::vector<planner::SizingTarget> targets_;
  int calls_ = 0;
};

FruitletSnapshot fruitlet(double x_m, int well_seen, double span_deg) {
  FruitletSnapshot f;
  f.center_m = Eigen::Vector3d(x_m, 0.0, 0.3);
  f.size_mm = 10.0;
  f.well_seen_images = well_seen;
  f.view_span_deg = span_deg;
  for (int i = 0; i < well_seen; ++i) f.well_seen_directions.push_back(Eigen::Vector3d::UnitY());
  return f;
}

SizingSnapshot snapshot(int view, std::vector<FruitletSnapshot> fruitlets) {
  SizingSnapshot s;
  s.view = view;
  s.fruitlets = std::move(fruitlets);
  return s;
}

// The tag's pose as the guidance asks for it: T must outlive the function.
TagPoseFn tagPoseOf(const std::optional<Eigen::Isometry3d>& T) {
  return [&T]() -> const std::optional<Eigen::Isometry3d>& { return T; };
}

// A plan step that moved to a sizing candidate aimed at target t.
planner::PlanStep aimedAt(int t) {
  planner::PlanStep step;
  planner::Candidate c;
  c.kind = planner::CandidateKind::kSizing;
  c.sizing_target = t;
  step.candidates = {c};
  step.chosen = 0;
  return step;
}

TEST(SizingGuidance, TargetsOnlyFruitletsShortOfTheEvidence) {
  const ClusterCompletionConfig config;  // 2 well-seen images, 30 degrees
  std::vector<SizingSnapshot> history;
  RecordingPlanner planner;
  SizingGuidance guidance(history, config, planner, 0.6);
  FruitletSnapshot merged = fruitlet(0.06, 0, 0.0);
  merged.size_source = sizing::SizeSource::kSphereFit;  // sized by its sphere: needs no images
  history.push_back(snapshot(
      0, {fruitlet(0.0, 4, 60.0), fruitlet(0.02, 1, 0.0), fruitlet(0.04, 3, 10.0), merged}));
  guidance.onView({.index = 0});
  ASSERT_EQ(planner.targets_.size(), 2u);
  EXPECT_DOUBLE_EQ(planner.targets_[0].center_m.x(), 0.02);
  EXPECT_DOUBLE_EQ(planner.targets_[1].center_m.x(), 0.04);
  EXPECT_DOUBLE_EQ(planner.targets_[0].radius_m, 0.005);
  EXPECT_EQ(planner.targets_[1].seen_from.size(), 3u);
  EXPECT_DOUBLE_EQ(planner.targets_[1].min_angle_deg, 30.0);
  EXPECT_DOUBLE_EQ(planner.targets_[1].min_visible_fraction, 0.6);
  // A view the completion did not size (no Cluster Region yet): nothing to aim at.
  guidance.onView({.index = 1});
  EXPECT_TRUE(planner.targets_.empty());
  EXPECT_EQ(planner.calls_, 2);
}

TEST(SizingGuidance, DropsAFruitletAimedAtTwiceInVainAndReturnsToItWhenItGainsAnImage) {
  const ClusterCompletionConfig config;
  std::vector<SizingSnapshot> history;
  RecordingPlanner planner;
  SizingGuidance guidance(history, config, planner, 0.6);
  int view = 0;
  const auto sized = [&](int well_seen) {
    history.push_back(snapshot(view, {fruitlet(0.0, well_seen, 0.0)}));
    guidance.onView({.index = view++});
  };
  const planner::PlanStep step = aimedAt(0);
  sized(1);
  ASSERT_EQ(planner.targets_.size(), 1u);
  guidance.onPlan({.step = &step});
  sized(1);  // the aimed view showed nothing new
  ASSERT_EQ(planner.targets_.size(), 1u) << "one miss: the map now holds that line of sight";
  guidance.onPlan({.step = &step});
  sized(1);
  EXPECT_TRUE(planner.targets_.empty()) << "two misses: no reachable view shows it";
  EXPECT_EQ(guidance.droppedTargets(), 1u);
  EXPECT_TRUE(guidance.leftOut(Eigen::Vector3d(0.001, 0.0, 0.3)));
  EXPECT_FALSE(guidance.leftOut(Eigen::Vector3d(0.02, 0.0, 0.3)));
  sized(1);
  EXPECT_TRUE(planner.targets_.empty());
  EXPECT_EQ(guidance.droppedTargets(), 1u) << "counted once";
  // An ordinary view gave it a well-seen image, still not from 30 degrees away: a target again.
  history.push_back(snapshot(view, {fruitlet(0.0, 2, 10.0)}));
  guidance.onView({.index = view++});
  ASSERT_EQ(planner.targets_.size(), 1u);
  EXPECT_FALSE(guidance.leftOut(Eigen::Vector3d(0.0, 0.0, 0.3)));
  EXPECT_EQ(guidance.aimedViews(), 2u);
  // Moves to other kinds of candidate are not aims.
  planner::PlanStep roi = aimedAt(0);
  roi.candidates[0].kind = planner::CandidateKind::kRoi;
  guidance.onPlan({.step = &roi});
  EXPECT_EQ(guidance.aimedViews(), 2u);
}

// Once every size has settled and only a target's evidence holds the stop, each view counts
// for it, aimed at it or not: the planner preferring other views must not keep the cluster
// to its cap. While sizes still move, only aimed views count.
TEST(SizingGuidance, OnceOnlyTheEvidenceHoldsTheStopEveryViewCountsForTheTargets) {
  const ClusterCompletionConfig config;
  std::vector<SizingSnapshot> history;
  RecordingPlanner planner;
  SizingGuidance guidance(history, config, planner, 0.6);
  int view = 0;
  double size_mm = 10.0;
  const auto sized = [&] {
    FruitletSnapshot lacking = fruitlet(0.02, 1, 0.0);
    lacking.size_mm = size_mm;
    SizingSnapshot s = snapshot(view, {fruitlet(0.0, 4, 60.0), lacking});
    // Around the cluster, 20 degrees a view: the sizings span directions.
    const double a = 20.0 * view * M_PI / 180.0;
    s.camera_position_m =
        Eigen::Vector3d(0.01, 0.0, 0.3) + 0.3 * Eigen::Vector3d(std::sin(a), -std::cos(a), 0.0);
    history.push_back(s);
    guidance.onView({.index = view++});
  };
  planner::PlanStep elsewhere = aimedAt(0);
  elsewhere.candidates[0].kind = planner::CandidateKind::kRoi;
  // Sizes still moving: views elsewhere do not count.
  for (int v = 0; v < 5; ++v, size_mm += 0.5) {
    sized();
    ASSERT_EQ(planner.targets_.size(), 1u);
    guidance.onPlan({.step = &elsewhere});
  }
  EXPECT_FALSE(guidance.leftOut(Eigen::Vector3d(0.02, 0.0, 0.3)));
  // Settled over the last 3 + 1 sizings: the next two views count, then it is left out.
  for (int v = 0; v < 4; ++v) sized();
  ASSERT_TRUE(sizesSettled(history, config, [](const FruitletSnapshot&) { return true; }));
  ASSERT_FALSE(sizesSettled(history, config));  // the target's evidence holds the stop
  guidance.onPlan({.step = &elsewhere});
  sized();
  ASSERT_EQ(planner.targets_.size(), 1u);
  guidance.onPlan({.step = &elsewhere});
  sized();
  EXPECT_TRUE(planner.targets_.empty());
  EXPECT_TRUE(guidance.leftOut(Eigen::Vector3d(0.02, 0.0, 0.3)));
  EXPECT_EQ(guidance.aimedViews(), 0u);  // none of those views was aimed at it
  // Without release_left_out a left-out target holds the stop anyway: views elsewhere keep
  // their old meaning, and the planner keeps aiming at it.
  ClusterCompletionConfig kept = config;
  kept.release_left_out = false;
  std::vector<SizingSnapshot> same = history;
  SizingGuidance patient(same, kept, planner, 0.6);
  for (int v = 0; v < 3; ++v) {
    patient.onView({.index = same.back().view});
    ASSERT_EQ(planner.targets_.size(), 1u);
    patient.onPlan({.step = &elsewhere});
  }
  EXPECT_FALSE(patient.leftOut(Eigen::Vector3d(0.02, 0.0, 0.3)));
}

// An unconfirmed detection (dropped by the hemisphere rule alone) is a target until it has
// been sized from directions 30 degrees apart; the cluster waits on it (waitingOnUnconfirmed)
// for at most max_aimed_views views, aimed at it or not, and its new sized images do not
// start the count again: a phantom on a fruitlet's segment is sized in every view of it.
TEST(SizingGuidance, AnUnconfirmedDetectionHoldsTheClusterForAtMostTwoViews) {
  ClusterCompletionConfig config;
  config.confirm_detections = true;
  std::vector<SizingSnapshot> history;
  RecordingPlanner planner;
  SizingGuidance guidance(history, config, planner, 0.6);
  int view = 0;
  const auto sized = [&](int sized_images, double span_deg) {
    SizingSnapshot s = snapshot(view, {fruitlet(0.0, 4, 60.0)});
    FruitletSnapshot u = fruitlet(0.02, sized_images, span_deg);
    u.unconfirmed = true;
    u.size_source = sizing::SizeSource::kSphereFit;
    s.unconfirmed = {u};
    history.push_back(s);
    guidance.onView({.index = view++});
  };
  sized(1, 0.0);
  ASSERT_EQ(planner.targets_.size(), 1u) << "a sphere fit, yet unconfirmed: it needs images";
  EXPECT_DOUBLE_EQ(planner.targets_[0].center_m.x(), 0.02);
  EXPECT_TRUE(guidance.waitingOnUnconfirmed());
  planner::PlanStep elsewhere = aimedAt(0);
  elsewhere.candidates[0].kind = planner::CandidateKind::kRoi;
  guidance.onPlan({.step = &elsewhere});
  sized(2, 10.0);  // a new sized image from near the first: the count goes on
  EXPECT_TRUE(guidance.waitingOnUnconfirmed());
  guidance.onPlan({.step = &elsewhere});
  sized(3, 12.0);
  EXPECT_FALSE(guidance.waitingOnUnconfirmed()) << "two views: the cluster no longer waits";
  EXPECT_TRUE(planner.targets_.empty());
  EXPECT_EQ(guidance.droppedTargets(), 1u);

  // Sized from directions 30 degrees apart, it has what the rule asks: no longer a target.
  std::vector<SizingSnapshot> seen;
  SizingGuidance other(seen, config, planner, 0.6);
  SizingSnapshot s = snapshot(0, {fruitlet(0.0, 4, 60.0)});
  FruitletSnapshot u = fruitlet(0.02, 2, 35.0);
  u.unconfirmed = true;
  s.unconfirmed = {u};
  seen.push_back(s);
  other.onView({.index = 0});
  EXPECT_TRUE(planner.targets_.empty());
  EXPECT_FALSE(other.waitingOnUnconfirmed());
}

// A detection looked at while unconfirmed or partly seen, then kept, is a fruitlet the
// planner has not yet aimed at as one: its count (of sized images, every view) starts again.
TEST(SizingGuidance, ADetectionKeptAfterItsLooksAsUnconfirmedIsAimedAtAgain) {
  const ClusterCompletionConfig config;
  std::vector<SizingSnapshot> history;
  RecordingPlanner planner;
  SizingGuidance guidance(history, config, planner, 0.6);
  planner::PlanStep elsewhere = aimedAt(0);
  elsewhere.candidates[0].kind = planner::CandidateKind::kRoi;
  for (int view = 0; view < 3; ++view) {
    SizingSnapshot s = snapshot(view, {fruitlet(0.0, 4, 60.0)});
    FruitletSnapshot u = fruitlet(0.02, 1, 0.0);
    u.unconfirmed = u.partly_seen = true;
    s.unconfirmed = {u};
    history.push_back(s);
    guidance.onView({.index = view});
    if (view < 2) guidance.onPlan({.step = &elsewhere});
  }
  EXPECT_FALSE(guidance.waitingOnUnconfirmed()) << "looked at twice: no longer waited on";
  history.push_back(snapshot(3, {fruitlet(0.0, 4, 60.0), fruitlet(0.02, 1, 0.0)}));
  guidance.onView({.index = 3});
  ASSERT_EQ(planner.targets_.size(), 1u) << "kept now: a target of its own";
  EXPECT_FALSE(guidance.leftOut(Eigen::Vector3d(0.02, 0.0, 0.3)));
}

// A partly seen detection near where a remembered fruitlet was is not that fruitlet found:
// the remembered one is still sought.
TEST(SizingGuidance, APartlySeenDetectionDoesNotFindARememberedFruitlet) {
  const ClusterCompletionConfig config;
  std::vector<SizingSnapshot> history;
  RecordingPlanner planner;
  SizingGuidance guidance(history, config, planner, 0.6);
  const std::optional<Eigen::Isometry3d> T_world_tag = Eigen::Isometry3d::Identity();
  guidance.expect({{Eigen::Vector3d(0.02, 0.0, 0.3), 8.0}}, tagPoseOf(T_world_tag), 0.008);
  SizingSnapshot s = snapshot(0, {fruitlet(0.0, 4, 60.0)});
  FruitletSnapshot u = fruitlet(0.021, 1, 0.0);
  u.unconfirmed = u.partly_seen = true;
  s.unconfirmed = {u};
  history.push_back(s);
  guidance.onView({.index = 0});
  EXPECT_EQ(guidance.expectedFound(), 0u);
  EXPECT_TRUE(guidance.waitingOnExpected());
  u.partly_seen = false;  // the hemisphere rule's unconfirmed detection: it may be the fruitlet
  history.push_back(s);
  history.back().view = 1;
  history.back().unconfirmed = {u};
  guidance.onView({.index = 1});
  EXPECT_EQ(guidance.expectedFound(), 1u);
  EXPECT_FALSE(guidance.fruitletsKnown())
      << "found only as an unconfirmed detection, and a kept fruitlet no one remembers";
}

TEST(SizingGuidance, ARememberedFruitletNotFoundIsSoughtThenGone) {
  const ClusterCompletionConfig config;
  std::vector<SizingSnapshot> history;
  RecordingPlanner planner;
  SizingGuidance guidance(history, config, planner, 0.6);
  std::optional<Eigen::Isometry3d> T_world_tag;
  // The earlier visit's two fruitlets; the tag stands 1 m along x in this visit's world.
  guidance.expect({{Eigen::Vector3d(-1.0, 0.0, 0.3), 8.0}, {Eigen::Vector3d(-0.98, 0.0, 0.3), 6.0}},
                  tagPoseOf(T_world_tag), 0.008);
  int view = 0;
  const auto sized = [&](std::vector<FruitletSnapshot> fruitlets) {
    history.push_back(snapshot(view, std::move(fruitlets)));
    guidance.onView({.index = view++});
  };
  sized({fruitlet(0.0, 4, 60.0)});
  EXPECT_TRUE(planner.targets_.empty()) << "no tag seen yet: nothing to expect";
  EXPECT_FALSE(guidance.waitingOnExpected());
  T_world_tag = Eigen::Isometry3d(Eigen::Translation3d(1.0, 0.0, 0.0));
  sized({fruitlet(0.0, 4, 60.0)});
  ASSERT_EQ(planner.targets_.size(), 1u);
  EXPECT_NEAR(planner.targets_[0].center_m.x(), 0.02, 1e-12);
  EXPECT_DOUBLE_EQ(planner.targets_[0].radius_m, 0.003);
  EXPECT_TRUE(planner.targets_[0].seen_from.empty()) << "any direction may show it";
  EXPECT_TRUE(guidance.waitingOnExpected());
  EXPECT_EQ(guidance.expectedFound(), 1u);
  EXPECT_FALSE(guidance.fruitletsKnown()) << "one still sought";
  // Remembered views do not count: they showed the cluster as it was.
  planner::PlanStep remembered = aimedAt(-1);
  remembered.candidates[0].kind = planner::CandidateKind::kRemembered;
  for (int k = 0; k < 3; ++k) {
    guidance.onPlan({.step = &remembered});
    sized({fruitlet(0.0, 4, 60.0)});
  }
  EXPECT_TRUE(guidance.waitingOnExpected());
  // Two views of the planner's own, and it is still not there: gone.
  planner::PlanStep elsewhere = aimedAt(-1);
  elsewhere.candidates[0].kind = planner::CandidateKind::kRoi;
  guidance.onPlan({.step = &elsewhere});
  sized({fruitlet(0.0, 4, 60.0)});
  EXPECT_TRUE(guidance.waitingOnExpected());
  guidance.onPlan({.step = &elsewhere});
  sized({fruitlet(0.0, 4, 60.0)});
  EXPECT_FALSE(guidance.waitingOnExpected());
  EXPECT_TRUE(planner.targets_.empty());
  EXPECT_EQ(guidance.expectedGone(), 1u);
  EXPECT_EQ(guidance.expectedFound(), 1u);
  EXPECT_FALSE(guidance.fruitletsKnown()) << "gone may be hidden: the first visit's rule";
  // Found after all, 5 mm from where it was (a drooping stem): no longer gone.
  sized({fruitlet(0.0, 4, 60.0), fruitlet(0.025, 4, 60.0)});
  EXPECT_EQ(guidance.expectedFound(), 2u);
  EXPECT_EQ(guidance.expectedGone(), 0u);
  EXPECT_TRUE(guidance.fruitletsKnown());
  // A fruitlet the earlier visit did not size: memory no longer accounts for the cluster.
  sized({fruitlet(0.0, 4, 60.0), fruitlet(0.025, 4, 60.0), fruitlet(0.06, 4, 60.0)});
  EXPECT_FALSE(guidance.fruitletsKnown());
}

TEST(SizingGuidance, OneFruitletIsNotTwoRememberedOnes) {
  const ClusterCompletionConfig config;
  std::vector<SizingSnapshot> history;
  RecordingPlanner planner;
  SizingGuidance guidance(history, config, planner, 0.6);
  const std::optional<Eigen::Isometry3d> T_world_tag = Eigen::Isometry3d::Identity();
  guidance.expect({{Eigen::Vector3d(0.0, 0.0, 0.3), 8.0}, {Eigen::Vector3d(0.006, 0.0, 0.3), 8.0}},
                  tagPoseOf(T_world_tag), 0.008);
  // One fruitlet within the gate of both: it is the nearer one's; the other is sought.
  history.push_back(snapshot(0, {fruitlet(0.005, 4, 60.0)}));
  guidance.onView({.index = 0});
  EXPECT_EQ(guidance.expectedFound(), 1u);
  ASSERT_EQ(planner.targets_.size(), 1u);
  EXPECT_NEAR(planner.targets_[0].center_m.x(), 0.0, 1e-12);
  EXPECT_THROW(guidance.expect({}, {}, 0.008), std::invalid_argument);
  EXPECT_THROW(guidance.expect({}, tagPoseOf(T_world_tag), 0.0), std::invalid_argument);
}

TEST(SizingGuidance, RejectsBadSettings) {
  const ClusterCompletionConfig config;
  std::vector<SizingSnapshot> history;
  RecordingPlanner planner;
  EXPECT_THROW(SizingGuidance(history, config, planner, 1.5), std::invalid_argument);
  EXPECT_THROW(SizingGuidance(history, config, planner, 0.6, 0), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::host::nbv
