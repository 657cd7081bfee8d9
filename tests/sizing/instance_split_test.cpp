// The instance split: two touching fruitlets whose fused surface is too blurred for the
// sphere split, told apart by the views' instance ids; a single fruitlet, a split seen in
// one view only and views without instances stay whole.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "fvp/host/sizing/fruitlet_sizer.h"
#include "fvp/host/sizing/instance_split.h"
#include "fvp/host/sizing/point_filters.h"
#include "sphere_views.h"

namespace fvp::host {
namespace {

constexpr double kRadius = 0.0045;
const Eigen::Vector3d kLeft(-0.0045, 0.0, 0.3), kRight(0.0045, 0.0, 0.3);

Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << x, z.cross(x), z;
  T.translation() = eye;
  return T;
}

sizing::SizingView view(const std::vector<Eigen::Vector4d>& spheres, const Eigen::Vector3d& eye,
                        bool with_instances = true) {
  const testing::SphereView v = testing::renderSpheres(spheres, lookAt(eye, {0.0, 0.0, 0.3}));
  cv::Mat disparity(v.depth.size(), CV_32F, cv::Scalar(0));
  for (int y = 0; y < v.depth.rows; ++y)
    for (int x = 0; x < v.depth.cols; ++x)
      if (const float z = v.depth.at<float>(y, x); z > 0.0f)
        disparity.at<float>(y, x) = float(v.in.fx_px * v.in.baseline_m / z);
  return {v.mask, disparity, v.in, v.T_world_camera, with_instances ? v.instances : cv::Mat()};
}

/// The camera-facing cap of a sphere (within 80 degrees of -z), blurred radially by up to
/// blur_m as a surface fused from views that disagree is.
std::vector<Eigen::Vector3f> blurredCap(const Eigen::Vector3d& c, int n, double blur_m,
                                        std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> off(-blur_m, blur_m);
  std::vector<Eigen::Vector3f> out;
  while (int(out.size()) < n) {
    const Eigen::Vector3d d = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    if (-d.z() < std::cos(80.0 * M_PI / 180.0)) continue;
    out.push_back((c + (kRadius + off(rng)) * d).cast<float>());
  }
  return out;
}

struct Pair {
  std::vector<Eigen::Vector3f> points;
  std::vector<int> truth;  ///< 0 left, 1 right
};

Pair touchingPair(double blur_m) {
  Pair p;
  for (int side = 0; side < 2; ++side)
    for (const auto& q : blurredCap(side ? kRight : kLeft, 3000, blur_m, 7 + side)) {
      p.points.push_back(q);
      p.truth.push_back(side);
    }
  return p;
}

const std::vector<Eigen::Vector4d> kPair = {{kLeft.x(), kLeft.y(), kLeft.z(), kRadius},
                                            {kRight.x(), kRight.y(), kRight.z(), kRadius}};
const std::vector<Eigen::Vector3d> kEyes = {
    {0.0, 0.0, 0.0}, {0.06, 0.02, 0.02}, {-0.05, -0.03, 0.01}};

TEST(InstanceSplit, TouchingPairSplitsAlongTheContact) {
  const Pair pair = touchingPair(0.001);
  std::vector<sizing::SizingView> views;
  for (const auto& eye : kEyes) views.push_back(view(kPair, eye));
  std::vector<int> labels(pair.points.size(), 0);
  EXPECT_EQ(sizing::splitByInstances(pair.points, labels, views), 1u);
  // Each side's points carry one label, the two sides different ones.
  std::map<int, int> side_label[2];
  for (std::size_t i = 0; i < labels.size(); ++i) ++side_label[pair.truth[i]][labels[i]];
  int majority[2];
  for (int side = 0; side < 2; ++side) {
    int best = 0;
    for (const auto& [label, n] : side_label[side])
      if (n > best) best = n, majority[side] = label;
    EXPECT_GT(best, 0.95 * 3000) << "side " << side;
    EXPECT_NE(majority[side], sizing::kDbscanNoise);
  }
  EXPECT_NE(majority[0], majority[1]);
}

TEST(InstanceSplit, OneFruitletOneViewOrNoInstancesStayWhole) {
  // One fruitlet: one instance in every view.
  const std::vector<Eigen::Vector3f> single = blurredCap(kLeft, 3000, 0.001, 3);
  std::vector<sizing::SizingView> views;
  for (const auto& eye : kEyes) views.push_back(view({kPair[0]}, eye));
  std::vector<int> labels(single.size(), 0);
  EXPECT_EQ(sizing::splitByInstances(single, labels, views), 0u);
  EXPECT_EQ(labels, std::vector<int>(single.size(), 0));

  // The pair seen split in one view only (a fruitlet that swung onto its neighbour's
  // outline once): whole, unless one view is declared enough.
  const Pair pair = touchingPair(0.001);
  const std::vector<sizing::SizingView> one{view(kPair, kEyes[0])};
  labels.assign(pair.points.size(), 0);
  EXPECT_EQ(sizing::splitByInstances(pair.points, labels, one), 0u);
  sizing::InstanceSplitConfig lenient;
  lenient.min_splitting_views = 1;
  EXPECT_EQ(sizing::splitByInstances(pair.points, labels, one, lenient), 1u);

  // Binary masks only: nothing to split by.
  std::vector<sizing::SizingView> binary;
  for (const auto& eye : kEyes) binary.push_back(view(kPair, eye, false));
  labels.assign(pair.points.size(), 0);
  EXPECT_EQ(sizing::splitByInstances(pair.points, labels, binary), 0u);

  // Wrong image types are a misuse, not an event.
  std::vector<sizing::SizingView> bad{views[0]};
  bad[0].fruitlet_instances.convertTo(bad[0].fruitlet_instances, CV_8U);
  EXPECT_THROW(sizing::splitByInstances(pair.points, labels, bad), std::invalid_argument);
}

TEST(InstanceSplit, DetectionsOnOneInstanceAreOneFruitlet) {
  std::vector<sizing::SizingView> views;
  for (const auto& eye : kEyes) views.push_back(view(kPair, eye));
  const auto left = sizing::dominantInstances(blurredCap(kLeft, 2000, 0.001, 1), views);
  const auto left_again = sizing::dominantInstances(blurredCap(kLeft, 500, 0.001, 2), views);
  const auto right = sizing::dominantInstances(blurredCap(kRight, 2000, 0.001, 3), views);
  ASSERT_EQ(left.size(), kEyes.size());
  for (std::size_t v = 0; v < kEyes.size(); ++v) {
    EXPECT_EQ(left[v], 1) << v;  // sphere 0's instance id
    EXPECT_EQ(right[v], 2) << v;
  }
  EXPECT_TRUE(sizing::sameInstance(left, left_again));
  EXPECT_FALSE(sizing::sameInstance(left, right));
  // One view is not enough; a view that does not decide (0) does not count.
  EXPECT_FALSE(sizing::sameInstance({1, 0, 0}, {1, 0, 0}));
  EXPECT_TRUE(sizing::sameInstance({1, 0, 5}, {1, 3, 5}));
  EXPECT_FALSE(sizing::sameInstance({1, 2, 5, 7}, {1, 3, 5, 8}));
  // Points the view sees behind another surface do not vote: the right sphere's far side.
  std::vector<Eigen::Vector3f> hidden;
  for (const auto& p : blurredCap(kRight, 500, 0.0, 4))
    hidden.push_back(p + Eigen::Vector3f(0, 0, 0.02f));
  EXPECT_EQ(sizing::dominantInstances(hidden, {views[0]})[0], 0);
}

TEST(InstanceSplit, SizingFindsBothFruitletsOnlyWithInstances) {
  const Pair pair = touchingPair(0.0015);
  sizing::SizingConfig config;
  config.split_merged_clusters = false;  // the instance split alone
  std::vector<sizing::SizingView> views, binary;
  for (const auto& eye : kEyes) {
    views.push_back(view(kPair, eye));
    binary.push_back(view(kPair, eye, false));
  }
  const auto fused = sizing::sizeFruitlets(binary, pair.points, nullptr, config);
  ASSERT_EQ(fused.fruitlets.size(), 1u);

  const auto apart = sizing::sizeFruitlets(views, pair.points, nullptr, config);
  EXPECT_EQ(apart.events.instance_parts_split_off, 1u);
  ASSERT_EQ(apart.fruitlets.size(), 2u);
  for (const Eigen::Vector3d& truth : {kLeft, kRight}) {
    double nearest = INFINITY;
    const sizing::FruitletEstimate* found = nullptr;
    for (const auto& f : apart.fruitlets)
      if ((f.center_m - truth).norm() < nearest) nearest = (f.center_m - truth).norm(), found = &f;
    EXPECT_LT(nearest, 0.002);  // a cap blurred by 1.5 mm fits a sphere within ~1.4 mm
    // Its own instance in every view: well seen, sized within a few percent.
    EXPECT_GE(found->support.well_seen_images, 2);
    EXPECT_NEAR(found->size_mm, 2000.0 * kRadius, 0.4);
  }
}

}  // namespace
}  // namespace fvp::host
