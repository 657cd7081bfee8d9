// The segmentation model standing in for a trained network: off by default; without errors
// it hands over the exact fruitlet mask; its boundary noise keeps each fruitlet's IoU with the
// true mask in the range its RMS implies; misses drop whole fruitlets at the configured rate;
// false blobs land on leaves only, as many as configured on average; deterministic per
// (seed, view). And green fruitlets: HSV segmentation no longer finds them, the model does.
#include <gtest/gtest.h>

#include <map>
#include <opencv2/imgproc.hpp>

#include "fvp/host/perception/fruitlet_segmenter.h"
#include "fvp/robot/sim/object_ids.h"
#include "fvp/robot/sim/segmentation_model.h"
#include "fvp/robot/sim/simulated_camera.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"

namespace fvp::robot::sim {
namespace {

// The start view of a world at the default camera: ids of the left image.
cv::Mat objectIds(const World& world) {
  const StereoRenderer renderer(world);
  RenderOptions ids_only;
  ids_only.images = false;
  return renderer.renderWithGroundTruth(world.startCameraPose(), ids_only).ground_truth.object_id;
}

const cv::Mat& world1Ids() {
  static const cv::Mat ids = objectIds(World::generate(WorldConfig{}, 1));
  return ids;
}

WorldConfig withModel() {
  WorldConfig c;
  c.segmentation_model = 1;
  return c;
}

double iou(const cv::Mat& a, const cv::Mat& b) {
  const int both = cv::countNonZero(a & b), either = cv::countNonZero(a | b);
  return either ? double(both) / either : 1.0;
}

TEST(SegmentationModel, OffByDefaultAndExactWithoutErrors) {
  EXPECT_FALSE(SegmentationModel(WorldConfig{}, 1).enabled());
  const SegmentationModel model(withModel(), 1);
  ASSERT_TRUE(model.enabled());
  const cv::Mat truth = SegmentationModel::trueMask(world1Ids());
  ASSERT_GT(cv::countNonZero(truth), 1000);
  EXPECT_EQ(cv::countNonZero(model.maskFor(world1Ids(), 0) != truth), 0);
}

TEST(SegmentationModel, InstancesKeepTouchingFruitletsApart) {
  WorldConfig c = withModel();
  c.segmentation_boundary_px = 1.0;
  const cv::Mat& ids = world1Ids();
  const SegmentationModel model(c, 9);
  for (int view = 0; view < 3; ++view) {
    const cv::Mat instances = model.instancesFor(ids, view);
    ASSERT_EQ(instances.type(), CV_16U);
    EXPECT_EQ(cv::countNonZero((instances != 0) != model.maskFor(ids, view)), 0);
    EXPECT_EQ(cv::countNonZero(instances != model.instancesFor(ids, view)), 0);
    // Well inside its outline (beyond the boundary noise), every fruitlet is one instance of
    // its own.
    std::map<int, int> instance_of;  // fruitlet id -> instance id
    int fruitlets = 0;
    for (int f = kFirstFruitletId; f < kFirstFruitletId + kMaxFruitlets; ++f) {
      cv::Mat inside = ids == f;
      if (cv::countNonZero(inside) == 0) continue;
      cv::erode(inside, inside, cv::Mat(), cv::Point(-1, -1), 4);
      if (cv::countNonZero(inside) < 20) continue;
      ++fruitlets;
      double lo = 0, hi = 0;
      cv::minMaxLoc(instances, &lo, &hi, nullptr, nullptr, inside);
      EXPECT_EQ(lo, hi) << "fruitlet " << f << " view " << view;
      EXPECT_GT(lo, 0.0);
      for (const auto& [other, instance] : instance_of) EXPECT_NE(instance, int(lo)) << other;
      instance_of[f] = int(lo);
    }
    EXPECT_GE(fruitlets, 3);
  }
}

TEST(SegmentationModel, BoundaryNoiseKeepsEachFruitletsIouInItsRange) {
  WorldConfig c = withModel();
  c.segmentation_boundary_px = 1.0;
  const cv::Mat& ids = world1Ids();
  const cv::Mat truth = SegmentationModel::trueMask(ids);
  for (int view = 0; view < 4; ++view) {
    const cv::Mat mask = SegmentationModel(c, 9).maskFor(ids, view);
    EXPECT_EQ(cv::countNonZero(mask != SegmentationModel(c, 9).maskFor(ids, view)), 0);
    // Per fruitlet, in a window around it: the boundary moves by ~1 px RMS (mean |d| ~0.8
    // px), so a fruitlet of radius R px keeps an IoU near 1 - 2 * 0.8 / R on average;
    // between 1 - 4 / R and 1 - 0.3 / R bounds it for these sizes.
    int checked = 0;
    for (int id = kFirstFruitletId; id < kFirstFruitletId + kMaxFruitlets; ++id) {
      const cv::Mat own = ids == id;
      const int area = cv::countNonZero(own);
      if (area < 400) continue;  // hidden or a sliver: not a boundary test
      const cv::Rect box = cv::boundingRect(own) + cv::Size(8, 8) - cv::Point(4, 4);
      const cv::Rect window = box & cv::Rect(0, 0, ids.cols, ids.rows);
      const double radius_px = std::sqrt(area / CV_PI);
      const double v = iou(mask(window), truth(window));
      EXPECT_GT(v, 1.0 - 4.0 / radius_px) << "fruitlet id " << id << " view " << view;
      EXPECT_LT(v, 1.0 - 0.3 / radius_px) << "fruitlet id " << id << " view " << view;
      ++checked;
    }
    EXPECT_GT(checked, 0);
  }
  // More noise, lower IoU.
  c.segmentation_boundary_px = 3.0;
  EXPECT_LT(iou(SegmentationModel(c, 9).maskFor(ids, 0), truth),
            iou(SegmentationModel(withModel(), 9).maskFor(ids, 0), truth));
}

TEST(SegmentationModel, MissesDropWholeFruitletsAtTheConfiguredRate) {
  WorldConfig c = withModel();
  c.segmentation_miss_rate = 0.25;
  const cv::Mat& ids = world1Ids();
  std::map<int, int> area;
  for (int id = kFirstFruitletId; id < kFirstFruitletId + kMaxFruitlets; ++id)
    if (const int n = cv::countNonZero(ids == id); n > 0) area[id] = n;
  ASSERT_GE(area.size(), 2u);
  int seen = 0, missed = 0;
  for (int view = 0; view < 100; ++view) {
    const cv::Mat mask = SegmentationModel(c, 3).maskFor(ids, view);
    for (const auto& [id, n] : area) {
      const int kept = cv::countNonZero(mask & (ids == id));
      EXPECT_TRUE(kept == 0 || kept == n) << "a fruitlet is kept or missed whole";
      ++seen;
      missed += kept == 0;
    }
  }
  // Binomial: 0.25 of seen, within 4 standard deviations.
  const double expected = 0.25 * seen, sd = std::sqrt(seen * 0.25 * 0.75);
  EXPECT_NEAR(missed, expected, 4.0 * sd);
}

TEST(SegmentationModel, FalseBlobsLandOnLeavesAsOftenAsConfigured) {
  WorldConfig c = withModel();
  c.segmentation_false_blobs = 3.0;
  const cv::Mat& ids = world1Ids();
  const cv::Mat truth = SegmentationModel::trueMask(ids);
  const cv::Mat leaves = (ids >= kFirstLeafId) & (ids < kTreeId);
  int blobs = 0;
  const int views = 60;
  for (int view = 0; view < views; ++view) {
    const cv::Mat extra = SegmentationModel(c, 5).maskFor(ids, view) & ~truth;
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(extra, labels, stats, centroids);
    for (int k = 1; k < n; ++k) {
      const cv::Point centre(int(std::lround(centroids.at<double>(k, 0))),
                             int(std::lround(centroids.at<double>(k, 1))));
      // Each blob is an ellipse centred on a leaf pixel; where blobs overlap the merged
      // component's centroid may not be, so check the component touches a leaf.
      EXPECT_GT(cv::countNonZero(leaves & (labels == k)), 0) << "view " << view;
      (void)centre;
      EXPECT_LE(stats.at<int>(k, cv::CC_STAT_WIDTH), 4 * SegmentationModel::kMaxBlobRadiusPx + 2);
    }
    blobs += n - 1;
  }
  // Poisson(3) per view; merged or fruitlet-covered blobs count less: between 2 and 3.6.
  EXPECT_GT(double(blobs) / views, 2.0);
  EXPECT_LT(double(blobs) / views, 3.6);
}

TEST(SegmentationModel, GreenFruitletsEscapeHsvButNotTheModel) {
  WorldConfig green;
  green.fruitlet_green_fraction = 1.0;
  const World world = World::generate(green, 1);
  // The rest of the world is the one drawn without green fruitlets.
  const World painted = World::generate(WorldConfig{}, 1);
  ASSERT_EQ(world.fruitlets().size(), painted.fruitlets().size());
  for (std::size_t i = 0; i < world.fruitlets().size(); ++i) {
    EXPECT_EQ(world.fruitlets()[i].center_m, painted.fruitlets()[i].center_m);
    EXPECT_NE(world.fruitlets()[i].rgb, painted.fruitlets()[i].rgb);
  }
  const StereoRenderer renderer(world);
  const RenderedView view = renderer.renderWithGroundTruth(world.startCameraPose());
  const cv::Mat truth = SegmentationModel::trueMask(view.ground_truth.object_id);
  const cv::Mat hsv = host::FruitletSegmenter().segment(view.frame.left_bgr);
  ASSERT_GT(cv::countNonZero(truth), 1000);
  EXPECT_LT(cv::countNonZero(hsv & truth), cv::countNonZero(truth) / 20)
      << "HSV should not separate green fruitlets from leaves";
  // The model's mask reaches the camera's frame.
  SimClock clock(SimClock::Mode::kFixed);
  green.segmentation_model = 1;
  const SegmentationModel model(green, 1);
  SimulatedCamera camera(renderer, clock, SimulatedErrors{nullptr, nullptr, &model});
  const host::StereoFrame frame = camera.capture(world.startCameraPose()).frame;
  ASSERT_EQ(frame.fruitlet_mask.type(), CV_16U);  // instance ids
  EXPECT_EQ(cv::countNonZero((frame.fruitlet_mask != 0) != truth), 0);
  // segmentation_instances: 0 hands over the same mask, binary.
  green.segmentation_instances = 0;
  const SegmentationModel binary(green, 1);
  SimulatedCamera binary_camera(renderer, clock, SimulatedErrors{nullptr, nullptr, &binary});
  const host::StereoFrame binary_frame = binary_camera.capture(world.startCameraPose()).frame;
  ASSERT_EQ(binary_frame.fruitlet_mask.type(), CV_8U);
  EXPECT_EQ(cv::countNonZero(binary_frame.fruitlet_mask != truth), 0);
}

}  // namespace
}  // namespace fvp::robot::sim
