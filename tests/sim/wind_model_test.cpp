// Wind: off by default; deterministic per (seed, view) and different between views; every
// leaf turned about its attachment with its tip moved within kMaxTipSigmas sigma; every
// fruitlet moved horizontally by at most the swing; no move brings a fruitlet into another
// or a leaf into a fruitlet; ground truth stays the rest pose; and the simulated camera
// renders each view's canopy.
#include <gtest/gtest.h>

#include <cmath>

#include "fvp/robot/sim/simulated_camera.h"
#include "fvp/robot/sim/wind_model.h"
#include "fvp/robot/sim/world.h"
#include "small_intrinsics.h"

namespace fvp::robot::sim {
namespace {

WorldConfig windy(double tip_m = 0.003, double swing_m = 0.002) {
  WorldConfig c;
  c.wind_leaf_tip_m = tip_m;
  c.wind_fruitlet_swing_m = swing_m;
  return c;
}

bool fruitletsOverlap(const Fruitlet& a, const Fruitlet& b, double gap_m) {
  return (a.center_m - b.center_m).norm() < a.boundingRadius_m() + b.boundingRadius_m() + gap_m;
}

TEST(WindModel, OffByDefault) {
  const World world = World::generate(WorldConfig{}, 3);
  const WindModel wind(world, 3);
  EXPECT_FALSE(wind.enabled());
  const World same = wind.worldAt(5);
  for (std::size_t i = 0; i < world.leaves().size(); ++i)
    EXPECT_TRUE(same.leaves()[i].T_world_leaf.isApprox(world.leaves()[i].T_world_leaf, 0.0));
}

TEST(WindModel, DeterministicPerViewAndDifferentBetweenViews) {
  const World world = World::generate(windy(), 4);
  const WindModel a(world, 4), b(world, 4);
  const World a2 = a.worldAt(2), b2 = b.worldAt(2), a3 = a.worldAt(3);
  for (std::size_t i = 0; i < world.fruitlets().size(); ++i) {
    EXPECT_EQ(a2.fruitlets()[i].center_m, b2.fruitlets()[i].center_m);
    EXPECT_NE(a2.fruitlets()[i].center_m, a3.fruitlets()[i].center_m);
  }
  for (std::size_t i = 0; i < world.leaves().size(); ++i)
    EXPECT_TRUE(a2.leaves()[i].T_world_leaf.isApprox(b2.leaves()[i].T_world_leaf, 0.0));
  // The wind keys do not change the world drawn from the seed.
  const World still = World::generate(WorldConfig{}, 4);
  for (std::size_t i = 0; i < world.fruitlets().size(); ++i)
    EXPECT_EQ(world.fruitlets()[i].center_m, still.fruitlets()[i].center_m);
}

TEST(WindModel, MovesStayWithinTheirBoundsAndNothingMovesIntoAnything) {
  const WorldConfig c = windy();
  double tip_sum_sq = 0.0;
  int tips = 0, fruitlet_moves = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const World rest = World::generate(c, seed);
    const WindModel wind(rest, seed);
    ASSERT_TRUE(wind.enabled());
    const std::string ground_truth = rest.groundTruthJson();
    for (int view = 0; view < 8; ++view) {
      const World moved = wind.worldAt(view);
      ASSERT_EQ(moved.fruitlets().size(), rest.fruitlets().size());
      // Ground truth (what trials score against): the rest pose, untouched by the wind.
      EXPECT_EQ(rest.groundTruthJson(), ground_truth);
      for (std::size_t i = 0; i < rest.fruitlets().size(); ++i) {
        const Eigen::Vector3d d = moved.fruitlets()[i].center_m - rest.fruitlets()[i].center_m;
        EXPECT_LE(d.norm(), c.wind_fruitlet_swing_m + 1e-12);
        EXPECT_EQ(d.z(), 0.0) << "a fruitlet swings horizontally";
        fruitlet_moves += d.norm() > 0.0;
        for (std::size_t j = 0; j < i; ++j) {
          if (fruitletsOverlap(rest.fruitlets()[i], rest.fruitlets()[j], c.min_gap_m)) continue;
          EXPECT_FALSE(fruitletsOverlap(moved.fruitlets()[i], moved.fruitlets()[j], c.min_gap_m))
              << "seed " << seed << " view " << view << " fruitlets " << i << ", " << j;
        }
      }
      for (std::size_t k = 0; k < rest.leaves().size(); ++k) {
        const Leaf& a = rest.leaves()[k];
        const Leaf& b = moved.leaves()[k];
        // Turned about the attachment: it stays put, the tip moves within the cut.
        EXPECT_LT((a.attachment_m() - b.attachment_m()).norm(), 1e-12);
        const double tip_m = (a.tip_m() - b.tip_m()).norm();
        EXPECT_LE(tip_m, WindModel::kMaxTipSigmas * c.wind_leaf_tip_m * (1.0 + 1e-9));
        tip_sum_sq += tip_m * tip_m;
        ++tips;
        for (std::size_t i = 0; i < rest.fruitlets().size(); ++i) {
          const Fruitlet& f = moved.fruitlets()[i];
          if (a.distanceLowerBound_m(rest.fruitlets()[i].center_m) <
              rest.fruitlets()[i].boundingRadius_m())
            continue;
          EXPECT_GE(b.distanceLowerBound_m(f.center_m), f.boundingRadius_m())
              << "seed " << seed << " view " << view << " leaf " << k << " fruitlet " << i;
        }
      }
    }
  }
  // The tips move by the configured RMS (a normal cut at 2 sigma keeps 77 % of its
  // variance; shortened moves take a little more), the fruitlets almost always move.
  const double rms_m = std::sqrt(tip_sum_sq / tips);
  EXPECT_GT(rms_m, 0.7 * c.wind_leaf_tip_m);
  EXPECT_LT(rms_m, 1.0 * c.wind_leaf_tip_m);
  EXPECT_GT(fruitlet_moves, 0);
}

TEST(WindModel, TheCameraRendersEachViewsCanopy) {
  const World world = World::generate(windy(0.01, 0.004), 2);
  RenderConfig rc;
  rc.intrinsics = test::smallIntrinsics(288, 216, 220.0);
  const StereoRenderer still(world, rc);
  const WindModel wind(world, 2);
  SimClock clock(SimClock::Mode::kFixed);
  SimulatedCamera camera(still, clock, SimulatedErrors{nullptr, &wind, nullptr});
  const Eigen::Isometry3d pose = world.startCameraPose();
  const host::StereoFrame first = camera.capture(pose).frame;
  const host::StereoFrame second = camera.capture(pose).frame;
  // View 0 is the canopy of worldAt(0), pixel for pixel; view 1 another.
  const StereoRenderer at0(wind.worldAt(0), rc);
  EXPECT_EQ(cv::norm(first.left_bgr, at0.render(pose).left_bgr, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(first.left_bgr, second.left_bgr, cv::NORM_L1), 0.0);
  EXPECT_GT(cv::norm(first.left_bgr, still.render(pose).left_bgr, cv::NORM_L1), 0.0);
}

}  // namespace
}  // namespace fvp::robot::sim
