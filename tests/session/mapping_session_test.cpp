// MappingSession on rendered stereo pairs: the map appears with the first view whose tag is
// detected, and views seen before it are integrated, in order, once the region is known;
// with view registration, positions are corrected by the anchor's estimated offset.
#include "fvp/host/session/mapping_session.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <optional>
#include <vector>

#include "fvp/accel/backend.h"
#include "seed2_orbit_frames.h"

namespace fvp::host {
namespace {

// Seed 2's orbit over 60 degrees (seed2_orbit_frames.h): the first view does not see the
// tag, the middle one does.
class MappingSessionTest : public ::testing::Test {
 protected:
  static const StereoFrame& untagged() { return frame(0); }
  static const StereoFrame& tagged() { return frame(1); }

 private:
  static const StereoFrame& frame(std::size_t i) { return test::seed2OrbitFrame(i); }
};

std::vector<std::array<int, 3>> sorted(std::vector<std::array<int, 3>> v) {
  std::sort(v.begin(), v.end());
  return v;
}

TEST_F(MappingSessionTest, AViewWithTheTagCreatesTheMapAndIntegratesIt) {
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  MappingSession session({}, "grid", map::MapConfig{}, cpu.get());
  EXPECT_FALSE(session.region().has_value());
  EXPECT_EQ(session.map(), nullptr);

  const ViewResult view = session.addView(tagged());
  ASSERT_TRUE(view.tag_detected);
  ASSERT_TRUE(session.region().has_value());
  ASSERT_NE(session.map(), nullptr);
  EXPECT_EQ(session.map()->engineName(), "grid");
  EXPECT_EQ(session.map()->scanCount(), 1u);
  EXPECT_EQ(session.map()->region().center_m(), session.region()->center_m());
  EXPECT_TRUE(view.integrated);
  EXPECT_EQ(view.index, 0u);
  EXPECT_EQ(view.earlier_views_integrated, 0u);
  EXPECT_GT(view.roi_points, 100u);
  EXPECT_GT(view.other_points, 10000u);
  EXPECT_EQ(view.scan.points, view.roi_points + view.other_points);
  EXPECT_EQ(view.perception.roi_points, static_cast<std::int64_t>(view.roi_points));
  EXPECT_GT(view.perceive_s, 0.0);
  EXPECT_GT(view.scan.fine_voxels_updated, 1000u);
  EXPECT_FALSE(session.map()->occupiedVoxels(map::MapLevel::kFine).empty());
  EXPECT_EQ(session.views().size(), 1u);
  EXPECT_EQ(session.pendingViews(), 0u);
}

TEST_F(MappingSessionTest, ViewsBeforeTheTagAreIntegratedInOrderOnceItIsSeen) {
  MappingSession session({}, "octomap", map::MapConfig{}, nullptr);
  const ViewResult first = session.addView(untagged());
  ASSERT_FALSE(first.tag_detected) << "the test needs a first view without the tag";
  EXPECT_FALSE(first.integrated);
  EXPECT_EQ(first.scan.points, 0u);
  EXPECT_GT(first.other_points, 10000u);
  EXPECT_EQ(session.map(), nullptr);
  EXPECT_EQ(session.pendingViews(), 1u);

  const ViewResult second = session.addView(tagged());
  ASSERT_TRUE(second.tag_detected);
  ASSERT_NE(session.map(), nullptr);
  EXPECT_EQ(second.earlier_views_integrated, 1u);
  EXPECT_EQ(session.pendingViews(), 0u);
  EXPECT_EQ(session.map()->scanCount(), 2u);
  ASSERT_EQ(session.views().size(), 2u);
  const ViewResult& first_now = session.views()[0];
  EXPECT_TRUE(first_now.integrated);
  EXPECT_EQ(first_now.scan.points, first.roi_points + first.other_points);
  EXPECT_TRUE(session.views()[1].integrated);

  // The same as perceiving the views as the session did (the first without a region) and
  // integrating them in order into a map made from the second view's region.
  const PerceptionPipeline perception;
  const PerceptionResult a = perception.process(untagged());
  const PerceptionResult b = perception.process(tagged());
  ASSERT_TRUE(b.region.has_value());
  auto reference = map::createMapEngine("octomap", map::MapConfig{}, *b.region, nullptr);
  reference->integrate(a.clouds);
  reference->integrate(b.clouds);
  for (const map::MapLevel level : {map::MapLevel::kCoarse, map::MapLevel::kFine}) {
    const auto got = sorted(session.map()->occupiedVoxels(level));
    EXPECT_GT(got.size(), 100u);
    EXPECT_EQ(got, sorted(reference->occupiedVoxels(level)));
  }
}

// Without the pose graph (estimateAnchorOffset) and with it (the graph's frame error).
class MappingSessionRegistrationTest : public MappingSessionTest,
                                       public ::testing::WithParamInterface<bool> {};
INSTANTIATE_TEST_SUITE_P(PoseGraph, MappingSessionRegistrationTest, ::testing::Bool());

TEST_P(MappingSessionRegistrationTest, DetectionsAreMovedByTheAnchorsOffset) {
  const bool pose_graph = GetParam();
  // The tagged view anchors; the other is told a pose 2 mm off, so registration moves it
  // back. Two views leave no hand-eye term: the offset is their mean frame's, minus half the
  // correction. Detections move by it, sizes and the clustered points stay; the same
  // session without the correction, and sizing in the maps' frame, are the references.
  StereoFrame off = untagged();
  off.T_world_camera.translation() += Eigen::Vector3d(0.002, -0.001, 0.0);
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  sizing::SizingResult sized[2], in_map_frame;
  AnchorOffset offset[2];
  for (const bool correct : {true, false}) {
    MappingSession session({}, "grid", map::MapConfig{}, cpu.get());
    ViewRegistrationConfig config;
    config.correct_anchor_offset = correct;
    config.use_pose_graph = pose_graph;
    session.enableViewRegistration(config);
    session.enableTsdf();
    session.addView(tagged());
    const ViewResult moved = session.addView(off);
    ASSERT_TRUE(moved.registration.has_value());
    ASSERT_EQ(moved.registration->status, RegistrationStatus::kApplied);
    EXPECT_GT(moved.registration->centroid_shift_m.norm(), 0.0015);
    EXPECT_EQ(session.correctsAnchorOffset(), correct);
    // Known either way; only the correction moves the result by it.
    offset[correct] = session.anchorOffset();
    EXPECT_TRUE(offset[correct].valid);
    EXPECT_EQ(offset[correct].views, 2u);
    if (pose_graph) {
      // The graph's frame error: the anchor's and the aligned view's, as the graph sees them.
      ASSERT_NE(session.poseGraph(), nullptr);
      EXPECT_EQ(offset[correct].shift_m, session.poseGraph()->mapFrameError_m());
      EXPECT_TRUE(moved.registration->predicted_m.has_value());
      EXPECT_TRUE(moved.registration->placement_m.isApprox(
          *moved.registration->predicted_m + moved.registration->centroid_shift_m, 1e-12));
    } else {
      EXPECT_EQ(session.poseGraph(), nullptr);
      EXPECT_TRUE(
          offset[correct].shift_m.isApprox(-0.5 * moved.registration->centroid_shift_m, 1e-12));
    }
    sized[correct] = session.sizeFruitlets({});
    if (correct) in_map_frame = session.sizeFruitletsInMapFrame({});
  }
  const Eigen::Vector3d shift = offset[true].shift_m;
  EXPECT_TRUE(offset[false].shift_m.isApprox(shift, 1e-12));
  ASSERT_FALSE(sized[true].fruitlets.empty());
  ASSERT_EQ(sized[true].fruitlets.size(), sized[false].fruitlets.size());
  ASSERT_EQ(sized[true].unsupported.size(), sized[false].unsupported.size());
  for (const auto list : {&sizing::SizingResult::fruitlets, &sizing::SizingResult::unsupported})
    for (std::size_t i = 0; i < (sized[true].*list).size(); ++i) {
      const auto& a = (sized[true].*list)[i];
      const auto& b = (sized[false].*list)[i];
      EXPECT_EQ(a.size_mm, b.size_mm);
      EXPECT_TRUE(a.center_m.isApprox(b.center_m + shift, 1e-12));
      EXPECT_TRUE(a.sphere_center_m.isApprox(b.sphere_center_m + shift, 1e-12));
      EXPECT_TRUE(a.centroid_m.isApprox(b.centroid_m + shift, 1e-12));
      EXPECT_TRUE((in_map_frame.*list)[i].center_m.isApprox(b.center_m, 1e-12));
    }
  EXPECT_EQ(sized[true].points, sized[false].points);
}

TEST_F(MappingSessionTest, TheTsdfIsFusedAgainWhereThePoseGraphNowPlacesItsViews) {
  // The untagged view first (fused as told once the tagged one places the region), then the
  // tagged one, then the untagged one told 2 mm off: each solve moves the earlier views.
  StereoFrame off = untagged();
  off.T_world_camera.translation() += Eigen::Vector3d(0.002, -0.001, 0.0);
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  for (const double beyond_m : {0.0, 1e-9, 1.0}) {
    SCOPED_TRACE(beyond_m);
    MappingSession session({}, "grid", map::MapConfig{}, cpu.get());
    ViewRegistrationConfig config;
    config.refuse_tsdf_beyond_m = beyond_m;
    session.enableViewRegistration(config);
    session.enableTsdf();
    const StereoFrame* frames[] = {&untagged(), &tagged(), &off};
    for (const StereoFrame* frame : frames) session.addView(*frame);
    ASSERT_NE(session.poseGraph(), nullptr);
    const ClusterPoseGraph& graph = *session.poseGraph();
    const bool refused = beyond_m > 0.0 && beyond_m < 1e-3;
    EXPECT_EQ(session.tsdfRefusions() > 0, refused);
    // Fused again or not, the TSDF is the views fused, in order, where the sizing views say
    // they are: a TSDF built from scratch from them holds the same surface.
    const map::GridGeometry& grid = session.tsdf()->geometry();
    Eigen::Vector3d lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = double(grid.first_voxel[a]) * grid.voxel_size_m;
      hi[a] = double(grid.first_voxel[a] + grid.dims[a]) * grid.voxel_size_m;
    }
    tsdf::TsdfVolume scratch(session.tsdf()->config(), Eigen::AlignedBox3d(lo, hi), cpu.get());
    for (const auto& v : session.sizingViews())
      scratch.integrate(tsdf::depthFromDisparity(v.disparity_px, v.intrinsics), v.fruitlet_mask,
                        v.intrinsics, v.T_world_camera);
    // Bricks may be allocated in another order: the same points, sorted.
    const auto sortedPoints = [](std::vector<Eigen::Vector3f> points) {
      std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) {
        return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
      });
      return points;
    };
    const auto fused = sortedPoints(session.surfacePoints());
    const auto expected = sortedPoints(scratch.extractSurfacePoints());
    ASSERT_FALSE(fused.empty());
    ASSERT_EQ(fused.size(), expected.size());
    std::size_t apart = 0;
    for (std::size_t i = 0; i < fused.size(); ++i) apart += (fused[i] - expected[i]).norm() > 1e-6f;
    EXPECT_EQ(apart, 0u) << "of " << fused.size();
    // Fused again, every view is where the last solve places it; otherwise where it was
    // first fused.
    for (std::size_t k = 0; k < 3; ++k) {
      const Eigen::Vector3d placed = session.sizingViews()[k].T_world_camera.translation() -
                                     frames[k]->T_world_camera.translation();
      if (refused) {
        EXPECT_TRUE(placed.isApprox(graph.predictedPlacement(k), 1e-9)) << "view " << k;
      } else if (k == 2) {
        EXPECT_TRUE(placed.isApprox(graph.view(k).placement_m, 1e-12));
      }
    }
  }
  ViewRegistrationConfig bad;
  bad.refuse_tsdf_beyond_m = -1.0;
  MappingSession session({}, "grid", map::MapConfig{}, cpu.get());
  EXPECT_THROW(session.enableViewRegistration(bad), std::invalid_argument);
}

TEST_F(MappingSessionTest, RegistrationIsEnabledBeforeTheFirstViewAndWithoutRotation) {
  auto cpu = accel::createBackend(accel::BackendKind::kCpu);
  MappingSession session({}, "grid", map::MapConfig{}, cpu.get());
  ViewRegistrationConfig rotating;
  rotating.estimate_rotation = true;  // the pose graph places views by translation
  EXPECT_THROW(session.enableViewRegistration(rotating), std::invalid_argument);
  session.addView(tagged());
  EXPECT_THROW(session.enableViewRegistration(), std::logic_error);
}

TEST(MappingSession, RejectsABadEngineBeforeAnyView) {
  EXPECT_THROW(MappingSession({}, "voxblox", map::MapConfig{}, nullptr), std::invalid_argument);
  EXPECT_THROW(MappingSession({}, "grid", map::MapConfig{}, nullptr), std::invalid_argument);
  map::MapConfig bad;
  bad.fine_voxel_size_m = -1.0;
  EXPECT_THROW(MappingSession({}, "octomap", bad, nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::host
