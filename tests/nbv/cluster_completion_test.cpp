// The automatic stop's rule on constructed sizing histories: settled sizes stop; a fruitlet
// found late, one not yet well seen, one seen from a single direction, a size still moving
// and an empty cluster do not; which dropped detections are looked at again. Then the observer on
// real frames: it sizes after each view and charges the sizing to the loop clock.
#include "fvp/host/nbv/cluster_completion.h"

#include <gtest/gtest.h>

#include <cmath>

#include "fvp/accel/backend.h"
#include "seed2_orbit_frames.h"

namespace fvp::host::nbv {
namespace {

FruitletSnapshot fruitlet(double x_m, double size_mm, int well_seen = 4, double span_deg = 60.0) {
  FruitletSnapshot f;
  f.center_m = Eigen::Vector3d(x_m, 0.0, 0.3);
  f.size_mm = size_mm;
  f.well_seen_images = well_seen;
  f.view_span_deg = span_deg;
  return f;
}

/// A camera 0.3 m from the fruitlets' centroid (0.01, 0, 0.3), azimuth_deg around it.
Eigen::Vector3d cameraAt(double azimuth_deg) {
  const double a = azimuth_deg * M_PI / 180.0;
  return Eigen::Vector3d(0.01, 0.0, 0.3) + 0.3 * Eigen::Vector3d(std::sin(a), -std::cos(a), 0.0);
}

/// views snapshots of two fruitlets whose sizes move by step_mm per view, taken by a camera
/// that moves step_deg around them per view.
std::vector<SizingSnapshot> history(int views, double step_mm = 0.02, double step_deg = 20.0) {
  std::vector<SizingSnapshot> h;
  for (int v = 0; v < views; ++v) {
    SizingSnapshot s;
    s.view = v;
    s.now_s = 5.0 * v;
    s.camera_position_m = cameraAt(step_deg * v);
    s.fruitlets = {fruitlet(0.0, 8.0 + step_mm * v), fruitlet(0.02, 11.0 - step_mm * v)};
    h.push_back(s);
  }
  return h;
}

TEST(ClusterCompletion, SettledSizesStopOnceEnoughViewsAgree) {
  const ClusterCompletionConfig config;  // 3 views, 0.1 mm
  EXPECT_FALSE(sizesSettled(history(3), config)) << "3 snapshots cannot show 3 quiet views";
  EXPECT_TRUE(sizesSettled(history(4), config));
  EXPECT_TRUE(sizesSettled(history(10), config));
  // Detections wander by less than a fruitlet's radius between sizings: still the same.
  auto h = history(4);
  h.back().fruitlets[0].center_m.x() += 0.002;
  EXPECT_TRUE(sizesSettled(h, config));
}

TEST(ClusterCompletion, AgreementAmongViewsFromOneDirectionDoesNotStop) {
  const ClusterCompletionConfig config;  // 30 degrees
  // Six views within 10 degrees of each other: what they all miss stays missed.
  auto h = history(6, 0.0, 2.0);
  EXPECT_EQ(discoveryWindow(h, config), 0u);
  EXPECT_FALSE(sizesSettled(h, config));
  // The window reaches back to the first view that spans 30 degrees with a later one.
  h.front().camera_position_m = cameraAt(-40.0);
  EXPECT_EQ(discoveryWindow(h, config), 6u);
  EXPECT_TRUE(sizesSettled(h, config));
  // ...and a fruitlet found after that view means the views since found something.
  h.front().fruitlets.pop_back();
  EXPECT_FALSE(sizesSettled(h, config));
  // Off: any stable_views + 1 sizings.
  ClusterCompletionConfig off;
  off.min_stable_span_deg = 0.0;
  EXPECT_EQ(discoveryWindow(h, off), 4u);
  EXPECT_TRUE(sizesSettled(h, off));
  // Views spread enough need no more than stable_views + 1.
  EXPECT_EQ(discoveryWindow(history(6), config), 4u);
}

TEST(ClusterCompletion, ASizeStillMovingDoesNotStop) {
  const ClusterCompletionConfig config;
  // 0.04 mm per view: 0.12 mm over the last three views, past the 0.1 mm tolerance.
  EXPECT_FALSE(sizesSettled(history(6, 0.04), config));
  auto h = history(6);
  h.back().fruitlets[1].size_mm += 0.15;
  EXPECT_FALSE(sizesSettled(h, config));
}

TEST(ClusterCompletion, ANoisyMedianMayMoveByItsStandardError) {
  ClusterCompletionConfig config;
  // 0.05 mm per view: 0.15 mm over three views, past the 0.1 mm floor...
  auto h = history(6, 0.05);
  EXPECT_FALSE(sizesSettled(h, config));
  // ...but within the 0.2 mm standard error of medians of scattered images.
  for (auto& f : h.back().fruitlets) f.size_stderr_mm = 0.2;
  EXPECT_TRUE(sizesSettled(h, config));
  config.tolerate_standard_error = false;
  EXPECT_FALSE(sizesSettled(h, config));
  // A precise median (0.03 mm) keeps the 0.1 mm floor.
  config.tolerate_standard_error = true;
  for (auto& f : h.back().fruitlets) f.size_stderr_mm = 0.03;
  EXPECT_FALSE(sizesSettled(h, config));
}

TEST(ClusterCompletion, AFruitletFoundLateOrNotYetWellSeenDoesNotStop) {
  const ClusterCompletionConfig config;
  // A third fruitlet appears in the newest sizing (a view revealed it).
  auto found = history(6);
  found.back().fruitlets.push_back(fruitlet(0.04, 9.0));
  EXPECT_FALSE(sizesSettled(found, config));
  // Seen in every sizing, but never in a well-seen image (only cut or shared segments).
  auto unseen = history(6);
  for (auto& s : unseen) s.fruitlets.push_back(fruitlet(0.04, 9.0, /*well_seen=*/0, 0.0));
  EXPECT_FALSE(sizesSettled(unseen, config));
  // One that moved farther than a fruitlet's radius is another fruitlet.
  auto moved = history(6);
  moved.back().fruitlets[0].center_m.x() += 0.004;
  EXPECT_FALSE(sizesSettled(moved, config));
  // Once the newcomer is well seen and quiet for three views from around the cluster, the
  // cluster is done.
  for (int v = 0; v < 4; ++v) {
    SizingSnapshot s = found.back();
    s.view += 1;
    s.camera_position_m = cameraAt(20.0 * s.view);
    found.push_back(s);
  }
  EXPECT_TRUE(sizesSettled(found, config));
}

TEST(ClusterCompletion, ImagesFromOneDirectionDoNotStopButSphereFitsDo) {
  const ClusterCompletionConfig config;
  auto narrow = history(6);
  for (auto& s : narrow) s.fruitlets[0].view_span_deg = 12.0;
  EXPECT_FALSE(sizesSettled(narrow, config));
  // Released (release_left_out: the planner looked for it twice in vain), its stable size
  // is enough; a size still moving is not.
  const auto first = [](const FruitletSnapshot& f) { return f.center_m.x() == 0.0; };
  EXPECT_TRUE(sizesSettled(narrow, config, first));
  auto moving = narrow;  // only the released fruitlet's size moves
  for (std::size_t v = 0; v < moving.size(); ++v) moving[v].fruitlets[0].size_mm += 0.2 * double(v);
  EXPECT_FALSE(sizesSettled(moving, config, first));
  // A fruitlet merged with a neighbour in every image has no well-seen image: its sphere
  // fit is its size, and it counts once that is stable.
  auto merged = history(6);
  for (auto& s : merged) {
    s.fruitlets[0].well_seen_images = 0;
    s.fruitlets[0].view_span_deg = 0.0;
    s.fruitlets[0].size_source = sizing::SizeSource::kSphereFit;
  }
  EXPECT_TRUE(sizesSettled(merged, config));
}

// An unconfirmed detection lacks evidence until sized from directions 30 degrees apart,
// although its size is a sphere fit's; sizesSettled leaves it to the hold (holdWhile).
TEST(ClusterCompletion, AnUnconfirmedDetectionNeedsSizedImagesFromTwoDirections) {
  const ClusterCompletionConfig config;
  FruitletSnapshot u = fruitlet(0.05, 4.0, 1, 0.0);
  u.size_source = sizing::SizeSource::kSphereFit;
  EXPECT_FALSE(lacksEvidence(u, config)) << "a kept sphere fit needs no images";
  u.unconfirmed = true;
  EXPECT_TRUE(lacksEvidence(u, config));
  u.well_seen_images = 2;
  u.view_span_deg = 31.0;
  EXPECT_FALSE(lacksEvidence(u, config));
  auto h = history(6);
  u.view_span_deg = 0.0;
  for (auto& s : h) s.unconfirmed = {u};
  EXPECT_TRUE(sizesSettled(h, config)) << "not compared with the kept fruitlets";
}

// A detection the support rule dropped is worth another look when it could be a fruitlet of
// its own: sized in an image, and its fitted centre outside every kept fruitlet's sphere by the
// smallest radius the sizing keeps (1.5 mm).
TEST(ClusterCompletion, APartlySeenDetectionLiesApartFromEveryKeptFruitlet) {
  sizing::FruitletEstimate kept;
  kept.sphere_center_m = Eigen::Vector3d(0.0, 0.0, 0.3);
  kept.size_ours_mm = 10.0;  // radius 5 mm: another fruitlet's centre lies 6.5 mm away or more
  kept.center_m = kept.sphere_center_m - Eigen::Vector3d(0.0, 0.0, 0.004);  // the paper's centroid
  sizing::FruitletEstimate dropped;
  dropped.points = 100;
  dropped.support.required_points = 400.0;
  dropped.per_image.resize(1);
  const auto at = [&](const Eigen::Vector3d& offset_m) {
    dropped.sphere_center_m = dropped.center_m = kept.sphere_center_m + offset_m;
  };
  at({0.0066, 0.0, 0.0});
  EXPECT_TRUE(partlySeen(dropped, {kept}));
  EXPECT_TRUE(partlySeen(dropped, {})) << "nothing kept: anything may be a fruitlet";
  at({0.0, 0.0064, 0.0});
  EXPECT_FALSE(partlySeen(dropped, {kept})) << "a piece of the kept fruitlet's surface";
  at({0.0, 0.0, -0.0066});
  EXPECT_TRUE(partlySeen(dropped, {kept})) << "measured from the fitted centre, not the centroid";
  at({std::nan(""), 0.0, 0.0});
  EXPECT_FALSE(partlySeen(dropped, {kept})) << "a NaN centre is never apart";
  at({0.02, 0.0, 0.0});
  dropped.support.unconfirmed = true;
  EXPECT_FALSE(partlySeen(dropped, {kept})) << "the hemisphere rule's: confirm_detections'";
  dropped.support.unconfirmed = false;
  dropped.points = 400;
  EXPECT_FALSE(partlySeen(dropped, {kept})) << "enough seen: dropped by another rule";
  dropped.points = 100;
  dropped.per_image.clear();
  EXPECT_FALSE(partlySeen(dropped, {kept})) << "never sized in an image";
}

TEST(ClusterCompletion, NaNSizesAndTwoDetectionsOnOneEarlierFruitletNeverSettle) {
  const ClusterCompletionConfig config;
  auto nan = history(6);
  for (auto& s : nan) s.fruitlets[1].size_mm = std::nan("");
  EXPECT_FALSE(sizesSettled(nan, config));
  // The newest sizing lost the fruitlet at 2 cm and split the one at 0 into two: as many
  // detections as before, but both near one earlier fruitlet.
  auto split = history(6);
  split.back().fruitlets[1] = fruitlet(0.001, 8.1);
  EXPECT_FALSE(sizesSettled(split, config));
}

TEST(ClusterCompletion, ViewsThatSizedNothingDoNotSettleTheCluster) {
  const ClusterCompletionConfig config;  // 3 views, 30 degrees
  // The second fruitlet is found at view 2; views 3 to 5 size no image (leaves hide the
  // cluster), so the sizing after each is view 2's.
  auto h = history(6);
  h[0].fruitlets.pop_back();
  h[1].fruitlets.pop_back();
  for (int v = 3; v < 6; ++v) h[v].fruitlets = h[2].fruitlets;
  EXPECT_TRUE(sizesSettled(h, config)) << "counted, they pass for views that found nothing new";
  for (int v = 3; v < 6; ++v) h[v].sized_any_image = false;
  EXPECT_FALSE(sizesSettled(h, config));
  // Views that size the fruitlets again, 40 degrees and more from view 2, do settle it.
  for (int v = 6; v < 9; ++v) {
    SizingSnapshot s = h[2];
    s.view = v;
    s.camera_position_m = cameraAt(20.0 * v);
    h.push_back(s);
    EXPECT_EQ(sizesSettled(h, config), v == 8) << "after view " << v;
  }
  // A view that sized nothing at the end leaves it settled while the sizing after it holds
  // the same sizes; what it fused may still change them, and then it does not.
  h.push_back(h.back());
  h.back().sized_any_image = false;
  EXPECT_TRUE(sizesSettled(h, config));
  h.back().fruitlets[1].size_mm += 0.5;
  EXPECT_FALSE(sizesSettled(h, config));
  h.back().fruitlets.pop_back();
  EXPECT_FALSE(sizesSettled(h, config));
  // No view that sized an image: nothing to settle.
  for (auto& s : h) s.sized_any_image = false;
  EXPECT_FALSE(sizesSettled(h, config));
}

// Memory accounts for the fruitlets (a later visit): the evidence and one agreeing view stop,
// from any directions; a size still moving or a fruitlet short of the evidence does not.
TEST(ClusterCompletion, KnownFruitletsNeedTheEvidenceAndOneAgreeingView) {
  const ClusterCompletionConfig config;
  const ClusterCompletionConfig known = knownFruitletsRule(config);
  EXPECT_EQ(known.stable_views, 1);
  EXPECT_EQ(known.min_stable_span_deg, 0.0);
  const auto two = history(2, 0.02, 2.0);  // two views 2 degrees apart
  EXPECT_FALSE(sizesSettled(two, config));
  EXPECT_TRUE(sizesSettled(two, known));
  EXPECT_FALSE(sizesSettled(history(1), known)) << "one sizing agrees with nothing";
  EXPECT_FALSE(sizesSettled(history(2, 0.2), known)) << "a size moved by 0.2 mm";
  auto short_of_evidence = two;
  short_of_evidence.back().fruitlets[1].view_span_deg = 10.0;
  EXPECT_FALSE(sizesSettled(short_of_evidence, known));
  auto one_lost = two;
  one_lost.back().fruitlets.pop_back();
  EXPECT_FALSE(sizesSettled(one_lost, known));
}

TEST(ClusterCompletion, AnEmptyClusterIsNeverDone) {
  std::vector<SizingSnapshot> empty(8);
  EXPECT_FALSE(sizesSettled(empty, {}));
  EXPECT_FALSE(sizesSettled({}, {}));
}

TEST(ClusterCompletion, BadConfigIsRefusedNamingTheField) {
  const auto refused = [](ClusterCompletionConfig c, const std::string& field) {
    try {
      c.validate();
      ADD_FAILURE() << field << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  ClusterCompletionConfig c;
  c.stable_views = 0;
  refused(c, "stable_views");
  c = {};
  c.size_tolerance_mm = -1.0;
  refused(c, "size_tolerance_mm");
  c = {};
  c.same_fruitlet_m = 0.0;
  refused(c, "same_fruitlet_m");
  c = {};
  c.min_well_seen_images = 0;
  refused(c, "min_well_seen_images");
  c = {};
  c.min_view_span_deg = 200.0;
  refused(c, "min_view_span_deg");
  c = {};
  c.min_stable_span_deg = -1.0;
  refused(c, "min_stable_span_deg");
  c = {};
  c.known_stable_views = 0;
  refused(c, "known_stable_views");
}

class CountingClock : public LoopClock {
 public:
  double now_s() const override { return 0.0; }
  void chargeCompute(LoopStage stage, double wall_s) override {
    if (stage == LoopStage::kSizing) sizing_s += wall_s, ++sizing_charges;
  }
  double sizing_s = 0.0;
  int sizing_charges = 0;
};

TEST(ClusterCompletion, SizesTheSessionAfterEveryMappedViewAndChargesTheClock) {
  auto backend = accel::createBackend("cpu");
  {
    const MappingSession without_tsdf({}, "grid", {}, backend.get());
    CountingClock clock;
    EXPECT_THROW(ClusterCompletion(without_tsdf, clock, {}), std::invalid_argument);
  }
  MappingSession session({}, "grid", {}, backend.get());
  session.enableTsdf();
  CountingClock clock;
  ClusterCompletion completion(session, clock, {});
  // View 0 shows no tag; view 1 does (and is captured twice); the last is view 1 again with
  // every fruitlet hidden (an empty fruitlet mask, as if leaves covered them).
  const std::size_t frames[] = {0, 1, 1, 1};
  for (int i = 0; i < 4; ++i) {
    auto frame = test::seed2OrbitFrame(frames[i]);
    if (i == 3) frame.fruitlet_mask = cv::Mat::zeros(frame.left_bgr.size(), CV_8U);
    session.addView(frame);
    ViewEvent event;
    event.index = i;
    completion.onView(event);
  }
  // The view before the tag was seen had nothing to size; every later one was sized.
  ASSERT_EQ(completion.history().size(), 3u);
  EXPECT_FALSE(completion.history().back().sized_any_image) << "it showed no fruitlet";
  EXPECT_EQ(int(completion.history().size()), clock.sizing_charges);
  EXPECT_EQ(completion.history().back().view, 3);
  EXPECT_FALSE(completion.history().back().fruitlets.empty());
  for (std::size_t k = 0; k + 1 < completion.history().size(); ++k)
    EXPECT_TRUE(completion.history()[k].sized_any_image) << "snapshot " << k;
  EXPECT_GT(clock.sizing_s, 0.0);
  // Three views cannot show three quiet ones after the first sizing.
  EXPECT_FALSE(completion.done());
  EXPECT_EQ(completion.stopCondition().check({}), std::nullopt);
  // The rule memory's knowing the fruitlets switches to, and only while it knows them.
  EXPECT_EQ(completion.ruleNow().stable_views, 3);
  bool known = true;
  completion.knownWhen([&known] { return known; });
  EXPECT_EQ(completion.ruleNow().stable_views, 1);
  EXPECT_EQ(completion.ruleNow().min_stable_span_deg, 0.0);
  known = false;
  EXPECT_EQ(completion.ruleNow().stable_views, 3);
  ClusterCompletionConfig off;
  off.known_fruitlets = false;
  ClusterCompletion without(session, clock, {}, off);
  without.knownWhen([] { return true; });
  EXPECT_EQ(without.ruleNow().stable_views, 3);
}

}  // namespace
}  // namespace fvp::host::nbv
