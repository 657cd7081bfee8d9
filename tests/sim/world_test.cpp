#include "fvp/robot/sim/world.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "fvp/host/core/stereo_intrinsics.h"

namespace fvp::robot::sim {
namespace {

constexpr int kSeeds = 40;

// Implicit-function value of point p for the ellipsoid grown by `gap` along each semi-axis:
// < 1 inside. Growing the semi-axes by gap bounds the gap-neighbourhood from inside only
// approximately, so this is an independent check of the generator's conservative bound.
double grownEllipsoidValue(const Fruitlet& f, const Eigen::Vector3d& p, double gap) {
  const Eigen::Vector3d q = f.R_world_fruitlet.transpose() * (p - f.center_m);
  return q.cwiseQuotient(f.semiAxes_m() + Eigen::Vector3d::Constant(gap)).squaredNorm();
}

// Points on a (curled) leaf: a grid of `step` in the unit disc, mapped onto the ellipse.
std::vector<Eigen::Vector3d> leafSamples(const Leaf& leaf, double step) {
  std::vector<Eigen::Vector3d> points;
  for (double sx = -1.0; sx <= 1.0; sx += step) {
    for (double sy = -1.0; sy <= 1.0; sy += step) {
      if (sx * sx + sy * sy > 1.0) continue;
      const double x = sx * leaf.half_length_m;
      points.push_back(leaf.T_world_leaf *
                       Eigen::Vector3d(x, sy * leaf.half_width_m, leaf.curl_per_m * x * x));
    }
  }
  return points;
}

// Points on a tag's plate: a grid of `step` plate widths.
std::vector<Eigen::Vector3d> plateSamples(const AprilTagPlacement& tag, double step) {
  std::vector<Eigen::Vector3d> points;
  for (double sx = -0.5; sx <= 0.5; sx += step)
    for (double sy = -0.5; sy <= 0.5; sy += step)
      points.push_back(tag.T_world_tag *
                       Eigen::Vector3d(sx * tag.plate_size_m, sy * tag.plate_size_m, 0.0));
  return points;
}

TEST(World, FruitletCountsSizesAndSpreadInRange) {
  const WorldConfig config;
  for (std::uint64_t seed = 0; seed < kSeeds; ++seed) {
    const World world = World::generate(config, seed);
    const auto& fruitlets = world.fruitlets();
    ASSERT_GE(static_cast<int>(fruitlets.size()), config.min_fruitlets) << seed;
    ASSERT_LE(static_cast<int>(fruitlets.size()), config.max_fruitlets) << seed;
    for (std::size_t i = 0; i < fruitlets.size(); ++i) {
      const Fruitlet& f = fruitlets[i];
      EXPECT_EQ(f.index, static_cast<int>(i));
      EXPECT_GE(f.radius_m, config.min_radius_m);
      EXPECT_LE(f.radius_m, config.max_radius_m);
      EXPECT_GE(f.elongation, config.min_elongation);
      EXPECT_LE(f.elongation, config.max_elongation);
      EXPECT_DOUBLE_EQ(f.gtSizeMm(), 2000.0 * f.radius_m);
      EXPECT_LE((f.center_m - world.clusterCenter_m()).norm(), config.cluster_spread_m + 1e-12);
      EXPECT_NEAR(f.R_world_fruitlet.determinant(), 1.0, 1e-9);
      EXPECT_TRUE((f.R_world_fruitlet.transpose() * f.R_world_fruitlet)
                      .isApprox(Eigen::Matrix3d::Identity(), 1e-9));
    }
  }
}

TEST(World, FruitletsLeavesAndTagDoNotIntersect) {
  const WorldConfig config;
  for (std::uint64_t seed = 0; seed < kSeeds; ++seed) {
    const World world = World::generate(config, seed);
    const auto& fruitlets = world.fruitlets();
    for (std::size_t i = 0; i < fruitlets.size(); ++i) {
      for (std::size_t j = i + 1; j < fruitlets.size(); ++j) {
        // Surface-to-surface distance >= centre distance - both bounding radii.
        const double gap = (fruitlets[i].center_m - fruitlets[j].center_m).norm() -
                           fruitlets[i].boundingRadius_m() - fruitlets[j].boundingRadius_m();
        EXPECT_GE(gap, config.min_gap_m - 1e-12) << "seed " << seed;
      }
    }
    // Dense samples of every leaf and of the tag plate stay outside every fruitlet.
    for (const Leaf& leaf : world.leaves()) {
      for (const Eigen::Vector3d& p : leafSamples(leaf, 0.05)) {
        for (const Fruitlet& f : fruitlets) {
          ASSERT_GT(grownEllipsoidValue(f, p, config.min_gap_m), 1.0)
              << "seed " << seed << " leaf " << leaf.index << " fruitlet " << f.index;
        }
      }
    }
    const AprilTagPlacement& tag = world.tag();
    ASSERT_TRUE(world.hasTag());
    for (const Eigen::Vector3d& p : plateSamples(tag, 0.025)) {
      for (const Fruitlet& f : fruitlets) {
        ASSERT_GT(grownEllipsoidValue(f, p, config.min_gap_m), 1.0) << "seed " << seed;
      }
    }
    const double tag_distance = (tag.T_world_tag.translation() - world.clusterCenter_m()).norm();
    EXPECT_GE(tag_distance, config.min_tag_distance_m);
    EXPECT_LE(tag_distance, config.max_tag_distance_m);
    EXPECT_EQ(static_cast<int>(world.leaves().size()), config.leaf_count);
    for (const Leaf& leaf : world.leaves()) {
      EXPECT_LE((leaf.T_world_leaf.translation() - world.clusterCenter_m()).norm(),
                config.leaf_region_m + 1e-12);
    }
  }
}

TEST(World, StartViewLooksAtClusterAndSeesTagFace) {
  const WorldConfig config;
  const host::StereoIntrinsics intrinsics;
  for (std::uint64_t seed = 0; seed < kSeeds; ++seed) {
    const World world = World::generate(config, seed);
    const Eigen::Isometry3d T_camera_world = world.startCameraPose().inverse();
    const Eigen::Vector3d cluster_camera = T_camera_world * world.clusterCenter_m();
    EXPECT_NEAR(cluster_camera.norm(), config.start_view_distance_m, 1e-9);
    const auto pixel = intrinsics.project(cluster_camera);
    ASSERT_TRUE(pixel.has_value());
    EXPECT_NEAR(pixel->x(), intrinsics.cx_px, 1e-6);
    EXPECT_NEAR(pixel->y(), intrinsics.cy_px, 1e-6);
    // Image "down" is world down.
    EXPECT_LT(world.startCameraPose().linear().col(1).z(), -0.9);
    // The tag is in view, its z axis (into the plate) points away from the camera, and it is
    // upright to within the configured tilt.
    const Eigen::Isometry3d T_camera_tag = T_camera_world * world.tag().T_world_tag;
    const auto tag_pixel = intrinsics.project(T_camera_tag.translation());
    ASSERT_TRUE(tag_pixel.has_value());
    EXPECT_GT(tag_pixel->x(), 0.0);
    EXPECT_LT(tag_pixel->x(), intrinsics.width_px - 1.0);
    const Eigen::Vector3d view_dir = T_camera_tag.translation().normalized();
    EXPECT_GT(T_camera_tag.linear().col(2).dot(view_dir), std::cos(45.0 * M_PI / 180.0));
    EXPECT_GT(T_camera_tag.linear()(1, 1), 0.8);
  }
}

// A tree of several clusters: each on its own branch, apart from the others, with its own
// tag beside it and its own start view; nothing of one touches a fruitlet of another.
TEST(World, ClustersOfATreeAreApartEachWithItsOwnTagAndStartView) {
  WorldConfig config;
  config.cluster_count = 4;
  const host::StereoIntrinsics intrinsics;
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    const World world = World::generate(config, seed);
    ASSERT_EQ(world.clusters().size(), 4u) << seed;
    EXPECT_EQ(world.leaves().size(), 4u * config.leaf_count);
    std::vector<int> indices;
    for (const FruitletCluster& c : world.clusters()) {
      EXPECT_EQ(c.tag.tag_id, config.tag_id + c.index);
      ASSERT_GE(static_cast<int>(c.fruitlet_indices.size()), config.min_fruitlets);
      ASSERT_LE(static_cast<int>(c.fruitlet_indices.size()), config.max_fruitlets);
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int i : c.fruitlet_indices) {
        indices.push_back(i);
        centroid += world.fruitlets()[static_cast<std::size_t>(i)].center_m;
        EXPECT_LE((world.fruitlets()[static_cast<std::size_t>(i)].center_m - c.center_m).norm(),
                  config.cluster_spread_m + 1e-12);
      }
      EXPECT_LT((centroid / double(c.fruitlet_indices.size()) - c.center_m).norm(), 1e-9);
      const double tag_distance = (c.tag.T_world_tag.translation() - c.center_m).norm();
      EXPECT_GE(tag_distance, config.min_tag_distance_m);
      EXPECT_LE(tag_distance, config.max_tag_distance_m);
      // The start view looks at the cluster with its tag in the image.
      const Eigen::Isometry3d T_camera_world = c.T_world_start_camera.inverse();
      EXPECT_NEAR((T_camera_world * c.center_m).norm(), config.start_view_distance_m, 1e-9);
      const auto tag_pixel = intrinsics.project(T_camera_world * c.tag.T_world_tag.translation());
      ASSERT_TRUE(tag_pixel.has_value());
      EXPECT_GT(tag_pixel->x(), 0.0);
      EXPECT_LT(tag_pixel->x(), intrinsics.width_px - 1.0);
      for (const FruitletCluster& other : world.clusters()) {
        if (other.index == c.index) continue;
        EXPECT_GE((other.center_m - c.center_m).norm(), config.min_cluster_spacing_m);
        // Another cluster's tag stays out of this cluster's region (tag distance + spread).
        EXPECT_GT((other.tag.T_world_tag.translation() - c.center_m).norm(),
                  config.max_tag_distance_m + config.cluster_spread_m);
      }
    }
    std::vector<int> expected(world.fruitlets().size());
    for (std::size_t i = 0; i < expected.size(); ++i) expected[i] = static_cast<int>(i);
    EXPECT_EQ(indices, expected) << "the clusters partition the fruitlets, in order";
    // No leaf, plate or fruiting branch touches any fruitlet.
    for (const Fruitlet& f : world.fruitlets()) {
      for (const Leaf& leaf : world.leaves()) {
        for (const Eigen::Vector3d& p : leafSamples(leaf, 0.1)) {
          ASSERT_GT(grownEllipsoidValue(f, p, config.min_gap_m), 1.0) << "seed " << seed;
        }
      }
      for (const FruitletCluster& c : world.clusters()) {
        for (const Eigen::Vector3d& p : plateSamples(c.tag, 0.05)) {
          ASSERT_GT(grownEllipsoidValue(f, p, config.min_gap_m), 1.0) << "seed " << seed;
        }
      }
    }
  }
}

TEST(World, OneClusterByDefaultHoldingEveryFruitlet) {
  const World world = World::generate(WorldConfig{}, 3);
  ASSERT_EQ(world.clusters().size(), 1u);
  EXPECT_EQ(world.clusters()[0].fruitlet_indices.size(), world.fruitlets().size());
  EXPECT_LT((world.clusters()[0].center_m - world.clusterCenter_m()).norm(), 1e-9);
  EXPECT_TRUE(world.startCameraPose().isApprox(world.clusters()[0].T_world_start_camera));
}

TEST(World, TooManyClustersForTheTagFamilyOrTheObjectIdsAreRejected) {
  WorldConfig config;
  config.cluster_count = 8;
  config.max_fruitlets = 9;
  EXPECT_THROW(config.validate(), std::invalid_argument);
  config.max_fruitlets = 6;
  config.tag_id = 580;
  EXPECT_THROW(config.validate(), std::invalid_argument);
  config.tag_id = 579;
  EXPECT_NO_THROW(config.validate());
}

TEST(World, SameSeedSameWorldDifferentSeedDifferentWorld) {
  const WorldConfig config;
  const World a = World::generate(config, 1234);
  const World b = World::generate(config, 1234);
  const World c = World::generate(config, 1235);
  EXPECT_EQ(a.groundTruthJson(), b.groundTruthJson());
  EXPECT_NE(a.groundTruthJson(), c.groundTruthJson());
  EXPECT_EQ(a.seed(), 1234u);
}

TEST(World, BadConfigThrowsNamingKey) {
  WorldConfig config;
  config.max_fruitlets = 99;
  try {
    World::generate(config, 1);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_fruitlets"), std::string::npos) << e.what();
  }
  config = WorldConfig{};
  config.min_elongation = 1.2;  // above max_elongation
  try {
    World::generate(config, 1);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_elongation"), std::string::npos) << e.what();
  }
}

TEST(World, ImpossiblePackingIsARuntimeError) {
  WorldConfig config;
  config.min_fruitlets = config.max_fruitlets = 20;
  config.cluster_spread_m = 0.01;
  EXPECT_THROW(World::generate(config, 3), std::runtime_error);
}

TEST(World, GroundTruthJsonHasFruitletSizesAndTag) {
  const World world = World::generate(WorldConfig{}, 5);
  const std::string json = world.groundTruthJson();
  EXPECT_NE(json.find("\"gt_size_mm\""), std::string::npos);
  EXPECT_NE(json.find("\"T_world_tag\""), std::string::npos);
  EXPECT_NE(json.find("\"tag36h11\""), std::string::npos);
}

TEST(World, FromPartsChecksIndicesAndLooksAlongPlusY) {
  Fruitlet f;
  f.index = 0;
  f.center_m = {0.1, 0.2, 0.3};
  f.radius_m = 0.005;
  const World world = World::fromParts({f}, {}, {}, std::nullopt);
  EXPECT_FALSE(world.hasTag());
  EXPECT_TRUE(world.startCameraPose().translation().isApprox(Eigen::Vector3d(0.1, -0.1, 0.3)));
  EXPECT_TRUE(world.startCameraPose().linear().col(2).isApprox(Eigen::Vector3d::UnitY()));
  f.index = 3;
  EXPECT_THROW(World::fromParts({f}, {}, {}, std::nullopt), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::robot::sim
