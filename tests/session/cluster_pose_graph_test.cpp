// The cluster's pose graph on constructed views: known hand-eye and arm errors, a tag seen
// by some views, alignments that place each view against the earlier ones.
#include "fvp/host/session/cluster_pose_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace fvp::host {
namespace {

Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  // OpenCV camera: z forward, y down (world z up).
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << x, y, z;
  T.translation() = eye;
  return T;
}

// A constructed cluster: told poses around it, the truth behind them and what views measure.
struct Scene {
  Eigen::Vector3d centre{0.5, 0.2, 1.0};
  Eigen::Isometry3d H = Eigen::Isometry3d::Identity();  // the hand-eye error
  std::vector<Eigen::Isometry3d> told, truth;
  Eigen::Isometry3d T_world_tag = Eigen::Isometry3d::Identity();
  double tag_size_m = 0.03;
  StereoIntrinsics intrinsics;

  Scene(int views, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> arm(0.0, 0.001);
    H.linear() =
        Eigen::AngleAxisd(0.6 * std::numbers::pi / 180.0, Eigen::Vector3d(1, -2, 0.5).normalized())
            .toRotationMatrix();
    H.translation() = Eigen::Vector3d(0.0015, -0.001, 0.0005);
    // The tag 4 cm below the centre, facing the views' side (its z into the printed face).
    T_world_tag.linear() = lookAt(centre + Eigen::Vector3d(-0.3, 0, 0), centre).linear();
    T_world_tag.translation() = centre + Eigen::Vector3d(-0.005, 0.0, -0.04);
    for (int k = 0; k < views; ++k) {
      const double azimuth = -1.0 + 2.0 * k / std::max(1, views - 1);  // +-57 degrees
      const double elevation = 0.3 * std::sin(1.7 * k);
      const Eigen::Vector3d eye =
          centre + 0.3 * Eigen::Vector3d(-std::cos(azimuth) * std::cos(elevation),
                                         std::sin(azimuth) * std::cos(elevation),
                                         std::sin(elevation));
      told.push_back(lookAt(eye, centre));
      const Eigen::Translation3d a(arm(rng), arm(rng), arm(rng));
      truth.push_back(Eigen::Isometry3d(a) * told.back() * H);
    }
  }
  // What moves a point view k's told pose put at the centre to the truth.
  Eigen::Vector3d errorAtCentre(int k) const {
    return truth[k] * told[k].inverse() * centre - centre;
  }
  // The tag as view k sees it (corners through the true pose, with pixel noise).
  TagDetection tag(int k, std::mt19937& rng, double noise_px) const {
    std::normal_distribution<double> noise(0.0, noise_px);
    TagDetection d;
    d.tag_id = 1;
    static constexpr double kSigns[4][2] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
    const Eigen::Isometry3d T_camera_tag = truth[k].inverse() * T_world_tag;
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d corner(0.5 * tag_size_m * kSigns[c][0], 0.5 * tag_size_m * kSigns[c][1],
                                   0.0);
      d.corners_px[c] =
          *intrinsics.project(T_camera_tag * corner) + Eigen::Vector2d(noise(rng), noise(rng));
    }
    d.T_camera_tag = T_camera_tag;  // an initial guess only
    return d;
  }
};

struct SceneRun {
  Eigen::Vector3d true_frame_error = Eigen::Vector3d::Zero();
  Eigen::Vector3d estimated_frame_error = Eigen::Vector3d::Zero();
  std::vector<bool> disagrees;
};

// Views placed one by one as a session does: view 0 anchors (placed as told); each later view
// is placed by an alignment that measures it against the views before it (with noise), one
// view's alignment wrong by `bad_shift_m` if bad_view >= 0.
SceneRun runScene(const Scene& scene, int tag_every, int bad_view = -1,
                  const Eigen::Vector3d& bad_shift_m = Eigen::Vector3d::Zero()) {
  ClusterPoseGraph graph(PoseGraphConfig{}, scene.tag_size_m);
  graph.setClusterCentre(scene.centre);
  std::mt19937 rng(7);
  std::normal_distribution<double> align_noise(0.0, 0.0002);
  Eigen::Vector3d frame_sum = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> placements;
  for (int k = 0; k < int(scene.told.size()); ++k) {
    std::optional<TagDetection> tag;
    if (tag_every > 0 && k % tag_every == 0) tag = scene.tag(k, rng, 0.2);
    graph.addView(scene.told[k], tag, scene.intrinsics);
    Eigen::Vector3d placement = Eigen::Vector3d::Zero();
    std::vector<std::size_t> aligned_to;
    if (k > 0) {
      // The maps' frame error so far; an exact alignment puts view k in it.
      const Eigen::Vector3d frame = frame_sum / double(k);
      placement = scene.errorAtCentre(k) - frame +
                  Eigen::Vector3d(align_noise(rng), align_noise(rng), align_noise(rng));
      if (k == bad_view) placement += bad_shift_m;
      for (int j = 0; j < k; ++j) aligned_to.push_back(j);
    }
    graph.place(k, placement, aligned_to);
    graph.solve();
    frame_sum += scene.errorAtCentre(k) - placement;
    placements.push_back(placement);
  }
  SceneRun run;
  run.true_frame_error = frame_sum / double(scene.told.size());
  run.estimated_frame_error = graph.mapFrameError_m();
  for (std::size_t k = 0; k < graph.size(); ++k)
    run.disagrees.push_back(graph.estimate(k).disagrees);
  return run;
}

TEST(ClusterPoseGraph, RecoversTheMapsFrameErrorFromAlignmentsAndTheTag) {
  const Scene scene(16, 3);
  // The frame's error is the anchor view's: millimetres, mostly the hand-eye error.
  const SceneRun run = runScene(scene, 3);
  std::cout << "true frame error " << 1e3 * run.true_frame_error.transpose() << " mm, estimated "
            << 1e3 * run.estimated_frame_error.transpose() << " mm\n";
  EXPECT_GT(run.true_frame_error.norm(), 0.002);
  // What stays is the arm's error the views share: a_k's mean, 1 mm / sqrt(16) per axis.
  EXPECT_LT((run.estimated_frame_error - run.true_frame_error).norm(), 0.001);
  for (std::size_t k = 0; k < run.disagrees.size(); ++k) EXPECT_FALSE(run.disagrees[k]) << k;
}

TEST(ClusterPoseGraph, AWrongAlignmentIsOutvotedAndFlagged) {
  const Scene scene(16, 3);
  const SceneRun clean = runScene(scene, 3);
  const SceneRun bad = runScene(scene, 3, 9, Eigen::Vector3d(0.0, 0.005, 0.0));
  EXPECT_TRUE(bad.disagrees[9]);
  // The frame moves by the wrong view's share of the maps at most (5 mm / 16), not by 5 mm.
  EXPECT_LT((bad.estimated_frame_error - bad.true_frame_error).norm(), 0.0012);
  EXPECT_LT((bad.estimated_frame_error - clean.estimated_frame_error).norm() -
                (bad.true_frame_error - clean.true_frame_error).norm(),
            0.0005);
}

TEST(ClusterPoseGraph, PredictsWhereTheNextViewBelongsWithinItsSigma) {
  const Scene scene(14, 5);
  ClusterPoseGraph graph(PoseGraphConfig{}, scene.tag_size_m);
  graph.setClusterCentre(scene.centre);
  std::mt19937 rng(11);
  Eigen::Vector3d frame_sum = Eigen::Vector3d::Zero();
  int inside = 0, predicted = 0;
  double first_sigma = 0.0, last_sigma = 0.0;
  for (int k = 0; k < 14; ++k) {
    graph.addView(scene.told[k], scene.tag(k, rng, 0.2), scene.intrinsics);
    Eigen::Vector3d placement = Eigen::Vector3d::Zero();
    std::vector<std::size_t> aligned_to;
    if (k > 0) {
      graph.solve();
      placement = scene.errorAtCentre(k) - frame_sum / double(k);  // the ideal placement
      const Eigen::Vector3d miss = graph.predictedPlacement(k) - placement;
      const Eigen::Vector3d sigma = graph.predictedPlacementSigma(k);
      for (int a = 0; a < 3; ++a) inside += std::abs(miss[a]) <= 3.0 * sigma[a];
      predicted += 3;
      (k == 1 ? first_sigma : last_sigma) = sigma.norm();
      for (int j = 0; j < k; ++j) aligned_to.push_back(j);
    }
    graph.place(k, placement, aligned_to);
    frame_sum += scene.errorAtCentre(k) - placement;
  }
  EXPECT_GE(inside, predicted - 2);  // 3 sigmas: nearly every axis of every view
  // Every view sees the tag: the hand-eye error is learnt and the prediction tightens.
  EXPECT_LT(last_sigma, 0.7 * first_sigma);
  ASSERT_TRUE(graph.T_world_tag().has_value());
}

TEST(ClusterPoseGraph, RefusesBadConfigAndPlacements) {
  PoseGraphConfig config;
  config.tag_corner_sigma_px = 0.0;
  try {
    ClusterPoseGraph graph(config, 0.03);
    FAIL() << "accepted a zero sigma";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("tag_corner_sigma_px"), std::string::npos);
  }
  EXPECT_THROW(ClusterPoseGraph(PoseGraphConfig{}, 0.0), std::invalid_argument);
  ClusterPoseGraph graph(PoseGraphConfig{}, 0.03);
  graph.addView(Eigen::Isometry3d::Identity(), std::nullopt, StereoIntrinsics{});
  graph.addView(Eigen::Isometry3d::Identity(), std::nullopt, StereoIntrinsics{});
  // Aligned to a view not yet placed, or to itself.
  EXPECT_THROW(graph.place(1, Eigen::Vector3d::Zero(), {0}), std::invalid_argument);
  graph.place(0, Eigen::Vector3d::Zero(), {});
  EXPECT_THROW(graph.place(1, Eigen::Vector3d::Zero(), {1}), std::invalid_argument);
  // No centre: nothing solved, nothing moved.
  graph.solve();
  EXPECT_EQ(graph.mapFrameError_m(), Eigen::Vector3d::Zero());
  EXPECT_THROW(graph.predictedPlacement(5), std::out_of_range);
  EXPECT_THROW(graph.predictedPlacementSigma(5), std::out_of_range);
}

TEST(ClusterPoseGraph, FollowsTheFirstTagItSaw) {
  const Scene scene(3, 5);
  std::mt19937 rng(3);
  ClusterPoseGraph graph(PoseGraphConfig{}, scene.tag_size_m);
  TagDetection own = scene.tag(0, rng, 0.2), other = scene.tag(1, rng, 0.2);
  other.tag_id = own.tag_id + 1;  // another cluster's tag in view
  graph.addView(scene.told[0], own, scene.intrinsics);
  graph.addView(scene.told[1], other, scene.intrinsics);
  graph.addView(scene.told[2], scene.tag(2, rng, 0.2), scene.intrinsics);
  EXPECT_TRUE(graph.view(0).tag.has_value());
  EXPECT_FALSE(graph.view(1).tag.has_value());
  EXPECT_TRUE(graph.view(2).tag.has_value());
}

}  // namespace
}  // namespace fvp::host
