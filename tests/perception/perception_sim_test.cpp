// Perception on the simulator's renders: segmentation against the object-id layer,
// disparity against the exact depth, AprilTag pose against the placed tag, the whole chain,
// and (heavy) the occlusion statistic over 35 seeds.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <opencv2/imgproc.hpp>

#include "fvp/host/perception/apriltag_detector.h"
#include "fvp/host/perception/cluster_region_image.h"
#include "fvp/host/perception/fruitlet_segmenter.h"
#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/perception/stereo_matcher.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/object_ids.h"
#include "fvp/robot/sim/occlusion_statistic.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"

namespace fvp::host {
namespace {

using robot::sim::isFruitletId;
using robot::sim::kBackgroundId;
using robot::sim::kFirstFruitletId;
using robot::sim::kFirstLeafId;
using robot::sim::kMaxFruitlets;
using robot::sim::OcclusionStatistic;
using robot::sim::RenderConfig;
using robot::sim::RenderedView;
using robot::sim::RenderOptions;
using robot::sim::StereoRenderer;
using robot::sim::World;
using robot::sim::WorldConfig;

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// A window of the full 1440x1080 camera (same focal length, principal point moved) so that
// the optical axis lands at pixel (axis_u, axis_v): renders only the pixels a test needs.
// Pixel (u, v) of the window is pixel (u + full.cx - cx, ...) of the full image.
StereoIntrinsics windowCamera(int width, int height, double axis_u, double axis_v) {
  StereoIntrinsics K;
  K.width_px = width;
  K.height_px = height;
  K.cx_px = axis_u;
  K.cy_px = axis_v;
  return K;
}

// Left optical frame at eye looking at target, image "up" towards world +z.
Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << x, z.cross(x), z;
  T.translation() = eye;
  return T;
}

// Segmentation vs the renderer's ids on the start views of a few seeds (window around the
// cluster): per-fruitlet IoU for fruitlets at least half visible, and stray pixels.
// The flash casts leaf shadows and there is no ambient light, so a fruitlet pixel in shadow
// is black (noise only) in the image: no camera can segment it. Truth is therefore the id
// layer restricted to lit pixels (brightest channel >= kLitMin, 5 sigma above the noise);
// "half visible" counts lit pixels against the leafless render.
TEST(OcclusionStatistic, FractionsFromIdMaps) {
  cv::Mat with(10, 10, CV_32S, cv::Scalar(kBackgroundId)), without = with.clone();
  without(cv::Rect(0, 0, 4, 5)).setTo(kFirstFruitletId);      // 20 px
  without(cv::Rect(5, 0, 5, 2)).setTo(kFirstFruitletId + 1);  // 10 px
  with(cv::Rect(0, 0, 4, 5)).setTo(kFirstFruitletId);
  with(cv::Rect(0, 0, 4, 2)).setTo(kFirstLeafId);      // 12 of 20 visible
  with(cv::Rect(5, 0, 5, 2)).setTo(kFirstLeafId + 3);  // 0 of 10 visible
  const auto s = OcclusionStatistic::compute(with, without);
  ASSERT_EQ(s.fruitlets().size(), 2u);
  EXPECT_DOUBLE_EQ(s.fruitlets()[0].visible_fraction, 0.6);
  EXPECT_DOUBLE_EQ(s.fruitlets()[1].visible_fraction, 0.0);
  EXPECT_EQ(s.fruitletsInView(), 2);
  EXPECT_DOUBLE_EQ(s.meanVisibleFraction(), 0.3);
}

TEST(PerceptionSim, SegmentationIoUOnStartViews) {
  const StereoIntrinsics K = windowCamera(640, 640, 319.5, 319.5);
  RenderConfig rc;
  rc.intrinsics = K;
  const FruitletSegmenter segmenter;
  double min_iou = 1.0, sum_iou = 0.0;
  int counted = 0;
  long stray = 0, fruit_px = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const World world = World::generate(WorldConfig{}, seed);
    const StereoRenderer renderer(world, rc);
    const RenderedView frame_view = renderer.renderWithGroundTruth(world.startCameraPose());
    const host::StereoFrame& frame = frame_view.frame;
    RenderOptions bare;
    bare.with_leaves = false;
    bare.images = false;
    const cv::Mat ids_bare =
        renderer.renderWithGroundTruth(world.startCameraPose(), bare).ground_truth.object_id;
    const auto occlusion = OcclusionStatistic::compute(frame_view.ground_truth.object_id, ids_bare);
    const cv::Mat mask = segmenter.segment(frame.left_bgr);
    constexpr int kLitMin = 10;
    cv::Mat brightest;
    cv::transform(frame.left_bgr, brightest, cv::Matx13f(1, 0, 0));
    cv::max(
        brightest,
        [&] {
          cv::Mat g;
          cv::extractChannel(frame.left_bgr, g, 1);
          return g;
        }(),
        brightest);
    cv::max(
        brightest,
        [&] {
          cv::Mat r;
          cv::extractChannel(frame.left_bgr, r, 2);
          return r;
        }(),
        brightest);
    const cv::Mat lit = brightest >= kLitMin;
    cv::Mat all_fruit = (frame_view.ground_truth.object_id >= kFirstFruitletId) &
                        (frame_view.ground_truth.object_id < kFirstFruitletId + kMaxFruitlets);
    cv::Mat near_fruit;
    cv::dilate(all_fruit, near_fruit, cv::getStructuringElement(cv::MORPH_ELLIPSE, {7, 7}));
    stray += cv::countNonZero(mask & ~near_fruit);
    fruit_px += cv::countNonZero(all_fruit);
    for (const auto& f : occlusion.fruitlets()) {
      const cv::Mat gt = (frame_view.ground_truth.object_id == f.object_id) & lit;
      const double lit_fraction =
          f.unoccluded_px ? static_cast<double>(cv::countNonZero(gt)) / f.unoccluded_px : 0.0;
      if (lit_fraction < 0.5) continue;
      cv::Mat zone;
      cv::dilate(gt, zone, cv::getStructuringElement(cv::MORPH_ELLIPSE, {7, 7}));
      const cv::Mat others = all_fruit & ~gt;
      const cv::Mat pred = mask & zone & ~others;
      const double iou = static_cast<double>(cv::countNonZero(pred & gt)) /
                         std::max(1, cv::countNonZero(pred | gt));
      std::cout << "[ measured ] seed " << seed << " fruitlet " << f.object_id - kFirstFruitletId
                << ": visible " << f.visible_fraction << ", lit and visible " << lit_fraction
                << ", IoU " << iou << "\n";
      min_iou = std::min(min_iou, iou);
      sum_iou += iou;
      ++counted;
    }
  }
  std::cout << "[ measured ] segmentation IoU over " << counted
            << " fruitlets >= half visible: min " << min_iou << ", mean " << sum_iou / counted
            << "; stray mask px (> 3 px from any fruitlet) " << stray << " vs " << fruit_px
            << " fruitlet px\n";
  ASSERT_GE(counted, 8);
  EXPECT_GE(min_iou, 0.9);
  EXPECT_LT(stray, fruit_px / 50);
}

// SGBM (full-resolution band) on fruitlet surfaces ~0.3 m away vs the exact depth layer.
// Leafless worlds, so that the right camera sees the fruitlets too. Note: flat surfaces
// (tag, bark) come out within 0.2 px; curved fruitlets need ONE flash lighting both
// exposures -- with a flash at each camera the shading differs between the images and
// biases SGBM by ~-0.9 px on fruitlets (1.45 mm median here; 0.61 mm with one flash).
TEST(PerceptionSim, DisparityDepthErrorOnFruitletsAtPointThreeMetres) {
  // Optical axis at u = 1000 so the cluster is right of the 320-column blind band.
  const StereoIntrinsics K = windowCamera(1280, 400, 900.0, 199.5);
  RenderConfig rc;
  rc.intrinsics = K;
  WorldConfig wc;
  wc.leaf_count = 0;
  std::vector<double> err_m, signed_px;
  double depth_sum = 0.0;
  double sgbm_s = 0.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const World world = World::generate(wc, seed);
    const StereoRenderer renderer(world, rc);
    const RenderedView frame_view = renderer.renderWithGroundTruth(world.startCameraPose());
    const StereoFrame& frame = frame_view.frame;
    const ClusterRegion region(world.clusterCenter_m(), 0.05);
    const cv::Rect band = clusterRegionImageBounds(region, K, frame.T_world_camera);
    const DisparityResult r = StereoMatcher().compute(frame.left_bgr, frame.right_bgr, band);
    sgbm_s += r.stats.sgbm_s;
    for (int v = 0; v < K.height_px; ++v)
      for (int u = 0; u < K.width_px; ++u) {
        if (!isFruitletId(frame_view.ground_truth.object_id.at<int>(v, u))) continue;
        const float d = r.disparity_px.at<float>(v, u);
        const double z = frame_view.ground_truth.depth_m.at<float>(v, u);
        if (d <= 0.0f) continue;
        err_m.push_back(std::abs(K.depthFromDisparity(d) - z));
        depth_sum += z;
        signed_px.push_back(d - K.fx_px * K.baseline_m / z);
      }
  }
  ASSERT_GT(err_m.size(), 1000u);
  const double med_mm = median(err_m) * 1e3;
  std::cout << "[ measured ] SGBM on fruitlet surfaces (mean depth " << depth_sum / err_m.size()
            << " m, " << err_m.size() << " px): median |depth error| " << med_mm
            << " mm (median disparity error " << median(signed_px) << " px); band SGBM "
            << sgbm_s / 3 * 1e3 << " ms per 1280x400 view\n";
  EXPECT_LE(med_mm, 1.0);
}

// The start view of world `seed` (the default config, with leaves) rendered with its exact
// depth, its Cluster Region and that region's image band.
struct StartView {
  RenderedView view;
  ClusterRegion region;
  cv::Rect band;
};
StartView startView(std::uint64_t seed) {
  const World world = World::generate(WorldConfig{}, seed);
  StartView out{StereoRenderer(world).renderWithGroundTruth(world.startCameraPose()),
                ClusterRegion(world.clusterCenter_m(), kDefaultClusterRadiusM),
                {}};
  out.band = clusterRegionImageBounds(out.region, out.view.frame.intrinsics,
                                      out.view.frame.T_world_camera);
  return out;
}

// The fine pass searched only over disparities of the Cluster Region and nearer (the
// pipeline's disparity_window) against the whole range, on full start views of worlds with leaves:
// fruitlet depth as good, the band's other pixels as well placed, and what lies behind the
// region kept from the coarse pass rather than matched wrongly into the window.
TEST(PerceptionSim, DisparityWindowKeepsFruitletDepthAndWhatLiesOutside) {
  struct Tally {
    std::vector<double> fruit_err_m;
    long outside_valid = 0, outside_close = 0, outside_in_window = 0;
    long other_close = 0;  ///< the band's other pixels within 2 px of the truth
    double sgbm_s = 0.0;
  };
  Tally full, windowed;
  long outside_truth = 0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const StartView start = startView(seed);
    const RenderedView& view = start.view;
    const StereoFrame& frame = view.frame;
    const StereoIntrinsics& K = frame.intrinsics;
    const ClusterRegion& region = start.region;
    const cv::Rect band = start.band;
    const auto window =
        clusterRegionDisparityWindow(region, K, frame.T_world_camera, kDefaultWindowDepthMarginM,
                                     SgbmConfig{}.saturation_margin_px + 1);
    ASSERT_TRUE(window.has_value());
    const double fb = K.fx_px * K.baseline_m;
    for (Tally* t : {&full, &windowed}) {
      const DisparityResult r = StereoMatcher().compute(frame.left_bgr, frame.right_bgr, band,
                                                        t == &windowed ? window : std::nullopt);
      t->sgbm_s += r.stats.sgbm_s;
      for (int v = band.y; v < band.br().y; ++v)
        for (int u = band.x; u < band.br().x; ++u) {
          const double z = view.ground_truth.depth_m.at<float>(v, u);
          const float d = r.disparity_px.at<float>(v, u);
          if (!(z > 0.0)) continue;
          const double d_true = fb / z;
          if (isFruitletId(view.ground_truth.object_id.at<int>(v, u))) {
            if (d > 0.0f) t->fruit_err_m.push_back(std::abs(K.depthFromDisparity(d) - z));
            continue;
          }
          t->other_close += d > 0.0f && std::abs(d - d_true) <= 2.0;
          if (d_true < window->min_px || d_true > window->max_px) {
            outside_truth += t == &full;
            if (!(d > 0.0f)) continue;
            ++t->outside_valid;
            t->outside_close += std::abs(d - d_true) <= 2.0;
            t->outside_in_window += d >= window->min_px && d <= window->max_px;
          }
        }
    }
  }
  for (const auto& [name, t] : {std::pair{"whole range", &full}, {"window", &windowed}})
    std::cout << "[ measured ] " << name << ": fruitlet median |depth error| "
              << median(t->fruit_err_m) * 1e3 << " mm over " << t->fruit_err_m.size()
              << " px; outside the window (" << outside_truth << " px) " << t->outside_valid
              << " valid, " << t->outside_close << " within 2 px, " << t->outside_in_window
              << " in the window; other band pixels within 2 px " << t->other_close << "; SGBM "
              << t->sgbm_s / 3 * 1e3 << " ms a view\n";
  // Fruitlets: as many pixels and as accurate (a tenth of a millimetre of slack).
  EXPECT_GE(windowed.fruit_err_m.size(), full.fruit_err_m.size() * 0.98);
  EXPECT_LE(median(windowed.fruit_err_m), median(full.fruit_err_m) + 1e-4);
  // The band's other pixels: as many within 2 px of the truth (measured 99.5 % of the whole
  // range's). Behind the region (a few % of the band on these views) the coarse pass's value
  // is kept where it sees one: measured 69 % as many valid, 3.2 % of the pixels wrongly in
  // the window (2.5 % with the whole range).
  EXPECT_GE(windowed.other_close, full.other_close * 0.99);
  EXPECT_GE(windowed.outside_valid, full.outside_valid * 0.6);
  EXPECT_LE(windowed.outside_in_window, outside_truth / 20);
}

// The guided kernels' fine pass (StereoMatcherConfig::guided_fine) against SGBM's over the
// whole range, on full start views of worlds with leaves: fruitlet depth against the exact
// depth layer, and the band's other pixels within 2 px of the truth.
TEST(PerceptionSim, GuidedFinePassAgainstSgbmOnFruitlets) {
  struct Tally {
    std::vector<double> fruit_err_m, fruit_signed_px;
    long other_close = 0, other_wrong = 0;
    double stereo_s = 0.0;
  };
  Tally sgbm, guided;
  StereoMatcherConfig guided_config;
  guided_config.guided_fine = true;
  const StereoMatcher sgbm_matcher, guided_matcher(guided_config);
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const StartView start = startView(seed);
    const RenderedView& view = start.view;
    const StereoFrame& frame = view.frame;
    const StereoIntrinsics& K = frame.intrinsics;
    const cv::Rect band = start.band;
    const double fb = K.fx_px * K.baseline_m;
    for (Tally* t : {&sgbm, &guided}) {
      const StereoMatcher& matcher = t == &guided ? guided_matcher : sgbm_matcher;
      const DisparityResult r = matcher.compute(frame.left_bgr, frame.right_bgr, band);
      t->stereo_s += r.stats.sgbm_s;
      for (int v = band.y; v < band.br().y; ++v)
        for (int u = band.x; u < band.br().x; ++u) {
          const double z = view.ground_truth.depth_m.at<float>(v, u);
          const float d = r.disparity_px.at<float>(v, u);
          if (!(z > 0.0) || !(d > 0.0f)) continue;
          if (isFruitletId(view.ground_truth.object_id.at<int>(v, u))) {
            t->fruit_err_m.push_back(std::abs(K.depthFromDisparity(d) - z));
            t->fruit_signed_px.push_back(d - fb / z);
            continue;
          }
          t->other_close += std::abs(d - fb / z) <= 2.0;
          t->other_wrong += std::abs(d - fb / z) > 2.0;
        }
    }
  }
  for (const auto& [name, t] : {std::pair{"SGBM", &sgbm}, {"guided", &guided}})
    std::cout << "[ measured ] " << name << ": fruitlet median |depth error| "
              << median(t->fruit_err_m) * 1e3 << " mm over " << t->fruit_err_m.size()
              << " px (median disparity error " << median(t->fruit_signed_px)
              << " px); other band pixels within 2 px " << t->other_close << ", beyond "
              << t->other_wrong << "; stereo " << t->stereo_s / 3 * 1e3 << " ms a view\n";
  // Fruitlets: at least as accurate (measured 0.617 mm against 0.641), nearly as many pixels
  // (measured 95.4 %: the uniqueness rule rejects more of the smooth surfaces' pixels).
  EXPECT_LE(median(guided.fruit_err_m), median(sgbm.fruit_err_m));
  EXPECT_GE(guided.fruit_err_m.size(), sgbm.fruit_err_m.size() * 0.93);
  // The band's other pixels: nearly as many within 2 px (measured 96.8 %), and no more
  // beyond (measured 99.7 % as many).
  EXPECT_GE(guided.other_close, sgbm.other_close * 0.95);
  EXPECT_LE(guided.other_wrong, sgbm.other_wrong * 1.02);
}

// libapriltag on the rendered tag, from the start camera's position looking at the tag
// (~0.3 m): pose against the placed T_world_tag.
TEST(PerceptionSim, AprilTagPoseAtPointThreeMetres) {
  const StereoIntrinsics K = windowCamera(480, 480, 239.5, 239.5);
  RenderConfig rc;
  rc.intrinsics = K;
  double max_mm = 0.0, max_deg = 0.0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const World world = World::generate(WorldConfig{}, seed);
    const Eigen::Isometry3d& T_world_tag = world.tag().T_world_tag;
    const Eigen::Vector3d eye = world.startCameraPose().translation();
    const Eigen::Isometry3d T_world_camera = lookAt(eye, T_world_tag.translation());
    const StereoRenderer renderer(world, rc);
    RenderOptions opts;
    const StereoFrame frame = renderer.render(T_world_camera, opts);
    AprilTagDetectorConfig config;
    config.tag_size_m = world.tag().tag_size_m;
    const auto det = AprilTagDetector(config).detect(frame.left_bgr, K, T_world_camera);
    ASSERT_TRUE(det.has_value()) << "seed " << seed;
    const double mm = (det->T_world_tag.translation() - T_world_tag.translation()).norm() * 1e3;
    const double deg =
        Eigen::AngleAxisd(det->T_world_tag.linear().transpose() * T_world_tag.linear()).angle() *
        180.0 / M_PI;
    std::cout << "[ measured ] seed " << seed << ": tag at "
              << (T_world_tag.translation() - eye).norm() << " m, pose error " << mm << " mm, "
              << deg << " deg\n";
    max_mm = std::max(max_mm, mm);
    max_deg = std::max(max_deg, deg);
  }
  std::cout << "[ measured ] tag pose error at ~0.3 m: max " << max_mm << " mm, " << max_deg
            << " deg\n";
  EXPECT_LE(max_mm, 2.0);
  EXPECT_LE(max_deg, 2.0);
}

// detectNear on full 1440x1080 views: in the window up to where the tag should appear it
// finds what the whole image's search finds, bit for bit, with the expected pose exact or 2
// degrees and 5 mm off; a tag far to the left of where it was expected (its window, anchored
// at the top-left corner, ends before it) is not searched for.
TEST(PerceptionSim, TagSearchedWhereItShouldAppearIsTheWholeImagesDetection) {
  int windowed = 0;
  double window_fraction = 0.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const World world = World::generate(WorldConfig{}, seed);
    const StereoRenderer renderer(world);
    AprilTagDetectorConfig config;
    config.tag_size_m = world.tag().tag_size_m;
    const AprilTagDetector detector(config);
    const Eigen::Isometry3d& T_world_tag = world.tag().T_world_tag;
    Eigen::Isometry3d off = T_world_tag;
    off.translation() += Eigen::Vector3d(0.005, -0.003, 0.002);
    off.linear() = Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d(1, 1, 0).normalized()) *
                   T_world_tag.linear();
    for (const Eigen::Isometry3d& pose : robot::sim::orbitViews(world, 2, 60.0)) {
      Eigen::Isometry3d far_off = T_world_tag;  // ~25 degrees to the camera's left at 0.3 m
      far_off.translation() -= 0.15 * pose.linear().col(0);
      const StereoFrame frame = renderer.render(pose);
      const StereoIntrinsics& K = frame.intrinsics;
      const auto whole = detector.detect(frame.left_bgr, K, pose);
      if (!whole) continue;
      const Eigen::Isometry3d expectations[] = {T_world_tag, off, far_off};
      for (const Eigen::Isometry3d& expected : expectations) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const cv::Rect window = detector.searchWindow(K, pose, expected);
        const auto near = detector.detectNear(frame.left_bgr, K, pose, expected);
        if (&expected == &expectations[2]) {
          EXPECT_FALSE(near.has_value());
          EXPECT_FALSE(
              window.contains(cv::Point(int(whole->center_px.x()), int(whole->center_px.y()))));
          continue;
        }
        ASSERT_TRUE(near.has_value());
        for (int k = 0; k < 4; ++k) EXPECT_EQ(near->corners_px[k], whole->corners_px[k]);
        EXPECT_EQ(near->T_world_tag.matrix(), whole->T_world_tag.matrix());
        ASSERT_FALSE(window.empty());
        EXPECT_LT(window.area(), K.width_px * K.height_px);
        window_fraction += double(window.area()) / (K.width_px * K.height_px);
        for (int k = 0; k < 4; ++k)
          EXPECT_TRUE(window.contains(
              cv::Point(int(whole->corners_px[k].x()), int(whole->corners_px[k].y()))))
              << "window " << window << ", corner " << whole->corners_px[k].transpose();
        ++windowed;
      }
    }
  }
  EXPECT_GE(windowed, 6);  // the tag is in view from one of each world's two poses
  std::cout << "[ measured ] the window holds " << 100.0 * window_fraction / windowed
            << " % of the image on average\n";
}

// The whole chain on a full 1440x1080 start view: the tag places a Cluster Region that holds
// the cluster, ROI points lie on fruitlets, and the SGBM band is cheaper than a full pass.
TEST(PerceptionSim, PipelineOnFullStartView) {
  const World world = World::generate(WorldConfig{}, 2);
  const StereoRenderer renderer(world);
  const StereoFrame frame = renderer.render(world.startCameraPose());
  const double render_s = renderer.lastRenderSeconds();
  PerceptionConfig config;
  config.tag.tag_size_m = world.tag().tag_size_m;
  const PerceptionResult r = PerceptionPipeline(config).process(frame);
  ASSERT_TRUE(r.tag.has_value());
  ASSERT_TRUE(r.region.has_value());
  for (const auto& f : world.fruitlets())
    EXPECT_TRUE(r.region->contains(f.center_m)) << "fruitlet " << f.index;
  const PerceptionStats& st = r.clouds.stats;
  EXPECT_GT(st.roi_points, 200);
  EXPECT_GT(st.other_points, 100000);
  EXPECT_GT(st.blind_band, 0);
  // ROI points near a fruitlet surface (distance to the centre within r*e + 3 mm).
  long near = 0;
  for (const auto& p : r.clouds.roi_points_m) {
    for (const auto& f : world.fruitlets())
      if ((p.cast<double>() - f.center_m).norm() <
          f.radius_m * std::max(1.0, f.elongation) + 0.003) {
        ++near;
        break;
      }
  }
  const double near_fraction = static_cast<double>(near) / r.clouds.roi_points_m.size();
  // A single-threaded SGBM pass over the whole pair, for comparison.
  const auto t0 = std::chrono::steady_clock::now();
  StereoMatcher::runSgbm(frame.left_bgr, frame.right_bgr, SgbmConfig{});
  const double full_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "[ measured ] full start view: render " << render_s << " s; SGBM full pair "
            << "(1 thread) " << full_s << " s vs band " << r.disparity.fine_rect.width << "x"
            << r.disparity.fine_rect.height << " + half-res coarse (2 threads) " << st.sgbm_s
            << " s; " << st.roi_points << " ROI points (" << near_fraction * 100
            << " % on fruitlets), " << st.other_points << " other\n"
            << st;
  EXPECT_GT(near_fraction, 0.9);
  EXPECT_LT(st.sgbm_s, full_s);

  // The same view with the fine pass's disparity window and without: the same band, ROI
  // points within 2 % of each other, the window's counts only with it.
  PerceptionConfig with_window = config, without_window = config;
  with_window.disparity_window = true;
  without_window.disparity_window = false;
  const PerceptionStats a = PerceptionPipeline(with_window).process(frame).clouds.stats;
  const PerceptionStats b = PerceptionPipeline(without_window).process(frame).clouds.stats;
  std::cout << "[ measured ] SGBM with the window " << a.sgbm_s << " s, without " << b.sgbm_s
            << " s; ROI points " << a.roi_points << " vs " << b.roi_points << "; from coarse "
            << a.window_from_coarse << ", rejected at the window's edge " << a.outside_window
            << "\n";
  EXPECT_EQ(a.fine_samples, b.fine_samples);
  EXPECT_NEAR(a.roi_points, b.roi_points, 0.02 * b.roi_points);
  EXPECT_GT(a.window_from_coarse + a.outside_window, 0);
  EXPECT_EQ(b.window_from_coarse + b.outside_window, 0);
}

}  // namespace
}  // namespace fvp::host
