// The sizing chain's parts: outlier removal and DBSCAN against brute force, matching and
// metrics by hand, the TSDF surface of an ideal sphere, and Eq. 4 on a synthetic view.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>
#include <utility>

#include "backend_test_support.h"
#include "fvp/host/core/look_at.h"
#include "fvp/host/eval/fruitlet_matching.h"
#include "fvp/host/eval/sizing_score.h"
#include "fvp/host/sizing/fruitlet_sizer.h"
#include "fvp/host/sizing/point_filters.h"
#include "fvp/host/tsdf/tsdf_volume.h"
#include "sphere_views.h"

namespace fvp::host {
namespace {

std::vector<Eigen::Vector3f> blobs(std::uint64_t seed, int per_blob, int noise) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> n(0.0f, 0.0015f);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  std::vector<Eigen::Vector3f> pts;
  const Eigen::Vector3f centres[3] = {{0, 0, 0}, {0.02f, 0, 0}, {0, 0.03f, 0.01f}};
  for (const auto& c : centres)
    for (int i = 0; i < per_blob; ++i) pts.push_back(c + Eigen::Vector3f(n(rng), n(rng), n(rng)));
  for (int i = 0; i < noise; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  return pts;
}

TEST(PointFilters, OutlierRemovalEqualsBruteForce) {
  const std::uint64_t seed = testing::freshSeed();
  const auto pts = blobs(seed, 300, 60);
  const int k = 10;
  const double ratio = 1.5;
  std::vector<double> mean(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    std::vector<double> d;
    for (const auto& q : pts) d.push_back((pts[i] - q).norm());
    std::sort(d.begin(), d.end());
    double s = 0;
    for (int j = 0; j < k; ++j) s += d[j];
    mean[i] = s / k;
  }
  double m = 0, v = 0;
  for (double x : mean) m += x;
  m /= mean.size();
  for (double x : mean) v += (x - m) * (x - m);
  const double limit = m + ratio * std::sqrt(v / (mean.size() - 1));
  std::vector<std::size_t> want;
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (mean[i] <= limit) want.push_back(i);
  const auto got = sizing::statisticalOutlierInliers(pts, k, ratio);
  // Float distances: a point exactly at the limit could flip; allow none on random data.
  EXPECT_EQ(got, want) << testing::replayHint(seed);
  EXPECT_LT(got.size(), pts.size());
}

TEST(PointFilters, DbscanEqualsBruteForce) {
  const std::uint64_t seed = testing::freshSeed();
  const auto pts = blobs(seed, 200, 40);
  const double eps = 0.003;
  const int min_samples = 8;
  const auto got = sizing::dbscan(pts, eps, min_samples);
  // Brute force: core points by counting, clusters as connected components of cores.
  const std::size_t n = pts.size();
  std::vector<std::vector<std::size_t>> nb(n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      if ((pts[i] - pts[j]).squaredNorm() <= float(eps * eps)) nb[i].push_back(j);
  std::vector<char> core(n);
  for (std::size_t i = 0; i < n; ++i) core[i] = int(nb[i].size()) >= min_samples;
  for (std::size_t i = 0; i < n; ++i) {
    if (core[i]) {
      ASSERT_NE(got[i], sizing::kDbscanNoise) << i << " " << testing::replayHint(seed);
      for (std::size_t j : nb[i]) {  // cores within eps share a cluster
        if (core[j]) {
          ASSERT_EQ(got[i], got[j]) << testing::replayHint(seed);
        }
      }
    } else {
      bool near_core = false;
      for (std::size_t j : nb[i]) near_core |= bool(core[j]);
      EXPECT_EQ(got[i] != sizing::kDbscanNoise, near_core) << i << " " << testing::replayHint(seed);
    }
  }
}

TEST(PointFilters, ClusterMembersGroupsIndicesByLabelAndLeavesNoiseOut) {
  const std::vector<int> labels = {2, sizing::kDbscanNoise, 0, 2, 0, sizing::kDbscanNoise, 5};
  const auto members = sizing::clusterMembers(labels);
  ASSERT_EQ(members.size(), 3u);
  EXPECT_EQ(members.at(0), (std::vector<std::size_t>{2, 4}));
  EXPECT_EQ(members.at(2), (std::vector<std::size_t>{0, 3}));
  EXPECT_EQ(members.at(5), (std::vector<std::size_t>{6}));
  EXPECT_TRUE(sizing::clusterMembers({}).empty());
}

TEST(Matching, OneToOneWithinTheGateByHand) {
  const std::vector<Eigen::Vector3d> gt = {{0, 0, 0}, {0.004, 0, 0}, {0.1, 0, 0}};
  // d0 is 1 mm from gt0 and 3 mm from gt1; d1 is 1 mm from gt1 and 5 mm from gt0: the
  // optimal pairing takes both; a spurious d2 is 6 mm from everything.
  const std::vector<Eigen::Vector3d> det = {{0.001, 0, 0}, {0.005, 0, 0}, {0.1, 0.006, 0}};
  const auto m = eval::matchFruitlets(det, gt);
  EXPECT_EQ(m, (std::vector<int>{0, 1, -1}));
  // Two detections near one fruitlet: only one matches.
  const auto m2 = eval::matchFruitlets({{0.001, 0, 0}, {-0.001, 0, 0}}, {{0, 0, 0}});
  EXPECT_EQ(m2.size(), 1u);
  EXPECT_GE(m2[0], 0);
  // Maximising matches beats the closest pair: d0 is closest to gt0 but only it reaches gt1.
  const auto m3 = eval::matchFruitlets({{0.002, 0, 0}, {-0.001, 0, 0}}, {{0, 0, 0}, {0.006, 0, 0}});
  EXPECT_EQ(m3, (std::vector<int>{1, 0}));
}

TEST(Matching, MetricsByHand) {
  const auto m = eval::sizeMetrics({10.0, 8.0, 6.0}, {11.0, 7.0}, {0, 1, -1}, 2);
  EXPECT_EQ(m.matched, 2u);
  EXPECT_NEAR(m.match_percent, 200.0 / 3.0, 1e-12);
  EXPECT_NEAR(*m.mae_mm, 1.0, 1e-12);
  EXPECT_NEAR(*m.mape_percent, (10.0 + 12.5) / 2.0, 1e-12);
  EXPECT_NEAR(*m.precision_percent, 100.0, 1e-12);
  const auto none = eval::sizeMetrics({10.0}, {}, {-1}, 0);
  EXPECT_FALSE(none.mae_mm.has_value());
  EXPECT_FALSE(none.precision_percent.has_value());
}

// Detections in the tag's frame: a tag turned 90 degrees about z, 1 m along x.
TEST(Matching, TagFrameCentresByHand) {
  nlohmann::json details = {{"sized_fruitlets", {{{"center_m", {1.0, 0.02, 0.5}}}}}};
  const nlohmann::json untouched = details;
  eval::addTagFrame(details, std::nullopt);
  EXPECT_EQ(details, untouched);
  Eigen::Isometry3d T_world_tag = Eigen::Isometry3d::Identity();
  T_world_tag.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_world_tag.translation() = Eigen::Vector3d(1.0, 0.0, 0.0);
  eval::addTagFrame(details, T_world_tag);
  // World +y is the tag's +x: the fruitlet 2 cm along world y is 2 cm along the tag's x.
  const auto& c = details["sized_fruitlets"][0]["center_tag_m"];
  EXPECT_NEAR(c[0].get<double>(), 0.02, 1e-12);
  EXPECT_NEAR(c[1].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(c[2].get<double>(), 0.5, 1e-12);
  const auto& q = details["T_world_tag"]["quaternion_wxyz"];
  EXPECT_NEAR(q[0].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(q[3].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_EQ(details["T_world_tag"]["translation_m"], nlohmann::json({1.0, 0.0, 0.0}));
  // Centres the sizing moved by an anchor shift go back into the maps' frame, where the tag is.
  nlohmann::json shifted = {{"sized_fruitlets", {{{"center_m", {1.003, 0.02, 0.5}}}}}};
  eval::addTagFrame(shifted, T_world_tag, Eigen::Vector3d(0.003, 0.0, 0.0));
  EXPECT_NEAR(shifted["sized_fruitlets"][0]["center_tag_m"][0].get<double>(), 0.02, 1e-12);
  EXPECT_NEAR(shifted["sized_fruitlets"][0]["center_tag_m"][1].get<double>(), 0.0, 1e-12);
}

TEST(SphereFit, RecoversCentreAndRadiusFromAHemisphere) {
  std::mt19937_64 rng(3);
  std::normal_distribution<float> n(0.0f, 1.0f);
  const Eigen::Vector3f c(0.1f, -0.05f, 1.0f);
  std::vector<Eigen::Vector3f> pts;
  while (pts.size() < 2000) {
    Eigen::Vector3f d(n(rng), n(rng), n(rng));
    d.normalize();
    if (d.y() < 0) pts.push_back(c + 0.005f * d);  // the side a camera sees
  }
  Eigen::Vector3d centre;
  double r = 0;
  ASSERT_TRUE(sizing::fitSphere(pts, centre, r));
  EXPECT_LT((centre - c.cast<double>()).norm(), 1e-6);
  EXPECT_NEAR(r, 0.005, 1e-6);
}

// An ideal view of a sphere from a pinhole camera at the origin: exact depth, mask and the
// disparity a perfect stereo pair would give.
struct SphereView : testing::SphereView {
  cv::Mat disparity;
};
SphereView renderSphere(const Eigen::Vector3d& c, double r) {
  SphereView v;
  static_cast<testing::SphereView&>(v) = testing::renderSpheres(
      {Eigen::Vector4d(c.x(), c.y(), c.z(), r)}, Eigen::Isometry3d::Identity());
  v.disparity = cv::Mat(v.depth.size(), CV_32F, cv::Scalar(0));
  for (int y = 0; y < v.depth.rows; ++y)
    for (int x = 0; x < v.depth.cols; ++x)
      if (const float z = v.depth.at<float>(y, x); z > 0.0f)
        v.disparity.at<float>(y, x) = float(v.in.fx_px * v.in.baseline_m / z);
  return v;
}

TEST(Tsdf, SurfaceOfAnIdealSphereLiesOnIt) {
  const Eigen::Vector3d c(0.01, -0.005, 0.3);
  const double r = 0.006;
  const SphereView v = renderSphere(c, r);
  tsdf::TsdfVolume volume({}, Eigen::AlignedBox3d(c.array() - 0.02, c.array() + 0.02));
  const auto stats = volume.integrate(v.depth, v.mask, v.in, Eigen::Isometry3d::Identity());
  EXPECT_GT(stats.roi_pixels, 1000u);
  EXPECT_GT(volume.blockCount(), 0u);
  const auto surface = volume.extractSurfacePoints();
  ASSERT_GT(surface.size(), 1000u);
  double worst = 0, sum = 0;
  for (const auto& p : surface) {
    const double e = std::abs((p.cast<double>() - c).norm() - r);
    worst = std::max(worst, e);
    sum += e;
  }
  // Projective distances along the ray are within a fraction of a 0.5 mm voxel at the front;
  // at grazing angles more.
  EXPECT_LT(sum / surface.size(), 0.0001);
  EXPECT_LT(worst, 0.0008);
}

TEST(Sizing, Eq4OnAnIdealSphereViewPaperShortOursClose) {
  const Eigen::Vector3d c(0.0, 0.0, 0.3);
  const double r = 0.005;
  const SphereView v = renderSphere(c, r);
  // The visible cap as the cluster's surface points.
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 4000; ++i) {
    const double a = 2.0 * M_PI * i / 4000.0 * 37.0, z = -1.0 + 0.9 * (i % 1000) / 1000.0;
    const Eigen::Vector3d d(std::sqrt(1 - z * z) * std::cos(a), std::sqrt(1 - z * z) * std::sin(a),
                            z);
    pts.push_back((c + r * d).cast<float>());
  }
  sizing::SizingView view{v.mask, v.disparity, v.in, Eigen::Isometry3d::Identity(), {}};
  sizing::SizingConfig config;
  const auto result = sizing::sizeFruitlets({view, view}, pts, nullptr, config);
  ASSERT_EQ(result.fruitlets.size(), 1u);
  const auto& f = result.fruitlets[0];
  // docs/design.md section 10: the paper's Eq. 4 sizes ideal spheres a few percent small.
  EXPECT_LT(f.size_paper_mm, 10.0);
  EXPECT_GT(f.size_paper_mm, 9.0);
  EXPECT_NEAR(f.size_ours_mm, 10.0, 0.15);
  EXPECT_LT((f.sphere_center_m - c).norm(), 1e-4);
  EXPECT_EQ(f.per_image.size(), 2u);
}

// A 10 mm sphere 0.3 m in front of the camera, its one view fused into a TSDF, and the
// volume's surface points: what a session would size after one view.
struct FusedSphere {
  Eigen::Vector3d center_m{0.0, 0.0, 0.3};
  double radius_m = 0.005;
  SphereView view;
  std::vector<Eigen::Vector3f> surface;
};

FusedSphere fuseOneSphereView() {
  FusedSphere s;
  s.view = renderSphere(s.center_m, s.radius_m);
  tsdf::TsdfVolume volume(
      {}, Eigen::AlignedBox3d(s.center_m.array() - 0.03, s.center_m.array() + 0.03));
  volume.integrate(s.view.depth, s.view.mask, s.view.in, Eigen::Isometry3d::Identity());
  s.surface = volume.extractSurfacePoints();
  return s;
}

// A session keeps each view's segments (segmentsOf) and passes them in: the sizes, centres
// and per-image measurements must be those of segmenting every view on the call, and a view
// left without given segments (past the end of the list) is segmented on the call.
TEST(Sizing, GivenSegmentsSizeAsSegmentingOnTheCall) {
  const FusedSphere sphere = fuseOneSphereView();
  const SphereView& v = sphere.view;
  const std::vector<Eigen::Vector3f>& pts = sphere.surface;
  const sizing::SizingView view{v.mask, v.disparity, v.in, Eigen::Isometry3d::Identity(), {}};
  const sizing::SizingConfig config;
  const auto segmented = sizing::sizeFruitlets({view, view}, pts, nullptr, config);
  ASSERT_EQ(segmented.fruitlets.size(), 1u);
  const auto segments = std::make_shared<const sizing::ViewSegments>(sizing::segmentsOf(view));
  EXPECT_EQ(cv::countNonZero(segments->labels), cv::countNonZero(v.mask));
  for (const auto& given : {std::vector{segments, segments}, std::vector{segments}}) {
    const auto result = sizing::sizeFruitlets({view, view}, given, pts, nullptr, config);
    ASSERT_EQ(result.fruitlets.size(), 1u);
    const auto& a = result.fruitlets[0];
    const auto& b = segmented.fruitlets[0];
    EXPECT_EQ(a.size_ours_mm, b.size_ours_mm);
    EXPECT_EQ(a.size_paper_mm, b.size_paper_mm);
    EXPECT_EQ(a.sphere_center_m, b.sphere_center_m);
    ASSERT_EQ(a.per_image.size(), b.per_image.size());
    for (std::size_t i = 0; i < a.per_image.size(); ++i) {
      const sizing::ImageSize &pa = a.per_image[i], &pb = b.per_image[i];
      EXPECT_EQ(pa.view, pb.view);
      EXPECT_EQ(pa.size_ours_mm, pb.size_ours_mm);
      EXPECT_EQ(pa.minor_axis_px, pb.minor_axis_px);
      EXPECT_EQ(pa.visible_fraction, pb.visible_fraction);
      EXPECT_EQ(pa.ellipse_center_px, pb.ellipse_center_px);
      EXPECT_EQ(pa.ellipse_axes_px, pb.ellipse_axes_px);
    }
  }
}

// The support rule (docs/sizing.md): a fragment split off a fruitlet's surface (here a
// small patch behind it, where mask pixels bled onto a leaf) falls on the fruitlet's segment
// and would be sized as large as the fruitlet, but shows a few percent of the surface that
// size implies; the fruitlet's own TSDF surface, from a single view, more than the quarter
// asked.
TEST(Sizing, SupportRuleDropsAFragmentAndKeepsTheFruitlet) {
  const FusedSphere sphere = fuseOneSphereView();
  const Eigen::Vector3d& c = sphere.center_m;
  const SphereView& v = sphere.view;
  std::vector<Eigen::Vector3f> pts = sphere.surface;
  const std::size_t sphere_points = pts.size();
  // 81 points on a 2.4 mm square 15 mm behind the centre, on the optical axis: DBSCAN's
  // 2 mm cannot join it to the sphere.
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j)
      pts.emplace_back(float(0.0003 * (i - 4)), float(0.0003 * (j - 4)), 0.315f);
  const sizing::SizingView view{v.mask, v.disparity, v.in, Eigen::Isometry3d::Identity(), {}};
  sizing::SizingConfig config;
  const auto kept = sizing::sizeFruitlets({view, view}, pts, nullptr, config);
  ASSERT_EQ(kept.fruitlets.size(), 1u);
  ASSERT_EQ(kept.unsupported.size(), 1u);
  EXPECT_EQ(kept.events.unsupported_detections, 1u);
  const auto& fruitlet = kept.fruitlets[0];
  EXPECT_LT((fruitlet.sphere_center_m - c).norm(), 3e-4);
  // One view of an unoccluded sphere shows 0.7 of its near hemisphere (the grazing rim gives
  // no depth): 0.35 of the sphere against the quarter asked.
  EXPECT_GT(double(fruitlet.points), 1.3 * fruitlet.support.required_points);
  EXPECT_GE(fruitlet.points, sphere_points * 9 / 10);
  const auto& fragment = kept.unsupported[0];
  EXPECT_EQ(fragment.points, 81u);
  // Sized off the fruitlet's segment in both images, which it shares.
  EXPECT_NEAR(fragment.size_ours_mm, fruitlet.size_ours_mm, 0.5);
  EXPECT_EQ(fragment.support.own_segment_images, 0);
  EXPECT_LT(double(fragment.points), 0.25 * fragment.support.required_points);
  // With the fragment gone the fruitlet's segment is its own again: sized from its two
  // well-seen images, not from its sphere fit.
  EXPECT_EQ(fruitlet.support.own_segment_images, 2);
  EXPECT_EQ(fruitlet.support.well_seen_images, 2);
  EXPECT_EQ(fruitlet.size_source, sizing::SizeSource::kWellSeenImages);
  EXPECT_NEAR(fruitlet.size_ours_mm, 10.0, 0.15);
  // Without the rule the fragment is a second fruitlet, and it makes the fruitlet's
  // segment shared in every image: the rule is what drops it and restores the sizing.
  config.min_support_area_fraction = 0.0;
  config.sphere_fit_support_area_fraction = 0.0;
  const auto all = sizing::sizeFruitlets({view, view}, pts, nullptr, config);
  ASSERT_EQ(all.fruitlets.size(), 2u);
  EXPECT_TRUE(all.unsupported.empty());
  for (const auto& f : all.fruitlets) EXPECT_EQ(f.support.own_segment_images, 0);
  EXPECT_EQ(all.events.not_visible, kept.events.not_visible);
  EXPECT_EQ(all.events.unsized_clusters, kept.events.unsized_clusters);
}

/// Points of a sphere's cap facing the camera at the origin (within cap_deg of the ray to
/// its centre), at the TSDF's surface density (1.5 points per 0.5 mm voxel face).
std::vector<Eigen::Vector3f> sphereCap(const Eigen::Vector3d& c, double r, double cap_deg) {
  const int n = int(std::lround(1.5 / (0.0005 * 0.0005) * 4.0 * M_PI * r * r));
  const Eigen::Vector3d towards_camera = -c.normalized();
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < n; ++i) {  // a Fibonacci sphere: even spacing
    const double z = 1.0 - 2.0 * (i + 0.5) / n, ring = std::sqrt(1.0 - z * z);
    const double a = i * M_PI * (3.0 - std::sqrt(5.0));
    const Eigen::Vector3d normal(ring * std::cos(a), ring * std::sin(a), z);
    if (normal.dot(towards_camera) >= std::cos(cap_deg * M_PI / 180.0))
      pts.push_back((c + r * normal).cast<float>());
  }
  return pts;
}

TEST(Sizing, OverlapRuleMergesAFruitletSeenTwiceAndKeepsTouchingNeighbours) {
  const Eigen::Vector3d c(0.0, 0.0, 0.3);
  const double r = 0.005;
  const SphereView v = renderSphere(c, r);
  const sizing::SizingView view{v.mask, v.disparity, v.in, Eigen::Isometry3d::Identity(), {}};
  // The same fruitlet's near cap twice, 4 mm apart along the line of sight (views whose
  // poses disagree): the caps stay over 2 mm apart, so DBSCAN keeps them as two detections,
  // but their spheres overlap by 1.2 radii: no two firm fruitlets can.
  std::vector<Eigen::Vector3f> pts = sphereCap(c, r, 70.0);
  for (const auto& p : sphereCap(c + Eigen::Vector3d(0, 0, 0.004), r, 70.0)) pts.push_back(p);
  sizing::SizingConfig config;
  const auto merged = sizing::sizeFruitlets({view, view}, pts, nullptr, config);
  ASSERT_EQ(merged.fruitlets.size(), 1u);
  EXPECT_TRUE(merged.unsupported.empty());
  EXPECT_EQ(merged.events.overlapping_detections_merged, 1u);
  const auto& f = merged.fruitlets[0];
  EXPECT_EQ(f.support.merged_detections, 1);
  // One detection on its segment: sized from both well-seen images, not from a sphere fit
  // of two shells; its centre between the copies.
  EXPECT_EQ(f.support.well_seen_images, 2);
  EXPECT_EQ(f.size_source, sizing::SizeSource::kWellSeenImages);
  EXPECT_NEAR(f.size_ours_mm, 10.0, 0.15);
  EXPECT_LT((f.sphere_center_m - c).norm(), 0.004);
  // The clusters' points carry one label.
  std::set<int> labels;
  for (int label : merged.labels)
    if (label != sizing::kDbscanNoise) labels.insert(label);
  EXPECT_EQ(labels.size(), 1u);
  // Without the rule each copy is sized by its sphere fit alone (each on the other's
  // segment) from a third of its sphere: the hemisphere rule drops one, and the other, its
  // segment its own again, is sized from its images, its points half the merged ones.
  config.max_detection_overlap_fraction = INFINITY;
  const auto one_copy = sizing::sizeFruitlets({view, view}, pts, nullptr, config);
  ASSERT_EQ(one_copy.fruitlets.size(), 1u);
  ASSERT_EQ(one_copy.unsupported.size(), 1u);
  EXPECT_EQ(one_copy.unsupported[0].size_source, sizing::SizeSource::kSphereFit);
  EXPECT_EQ(one_copy.fruitlets[0].size_source, sizing::SizeSource::kWellSeenImages);
  EXPECT_EQ(f.points, one_copy.fruitlets[0].points + one_copy.unsupported[0].points);
  // Without either, the copies are two detections.
  config.sphere_fit_support_area_fraction = 0.0;
  const auto both = sizing::sizeFruitlets({view, view}, pts, nullptr, config);
  ASSERT_EQ(both.fruitlets.size(), 2u);
  EXPECT_EQ(both.events.overlapping_detections_merged, 0u);
  for (const auto& d : both.fruitlets) EXPECT_EQ(d.support.well_seen_images, 0);
  EXPECT_EQ(f.points, both.fruitlets[0].points + both.fruitlets[1].points);
  config.sphere_fit_support_area_fraction = 0.5;

  // Two fruitlets side by side, touching: their spheres meet but do not overlap.
  const Eigen::Vector3d left(-0.005, 0.0, 0.3), right(0.005, 0.0, 0.3);
  const SphereView pair = renderSphere(left, r);
  const SphereView other = renderSphere(right, r);
  cv::Mat mask = pair.mask | other.mask, disparity = cv::max(pair.disparity, other.disparity);
  const sizing::SizingView pair_view{mask, disparity, pair.in, Eigen::Isometry3d::Identity(), {}};
  std::vector<Eigen::Vector3f> neighbours = sphereCap(left, r, 70.0);
  for (const auto& p : sphereCap(right, r, 70.0)) neighbours.push_back(p);
  config.max_detection_overlap_fraction = 0.5;
  // Each shows a third of its sphere in one view: the overlap rule alone, without the
  // hemisphere asked of their sphere-fit sizes (the hemisphere test shows that cost).
  config.sphere_fit_support_area_fraction = 0.0;
  const auto two = sizing::sizeFruitlets({pair_view}, neighbours, nullptr, config);
  EXPECT_EQ(two.fruitlets.size(), 2u);
  EXPECT_EQ(two.events.overlapping_detections_merged, 0u);
}

// The hemisphere rule (docs/sizing.md, "Sized by its 3-D surface alone"): what the quarter
// rule left of the spurious detections were 3.5-5 mm sphere fits on a segment a real
// fruitlet owns, each showing 1.2-2.1 quarters of its sphere. Here a 10 mm fruitlet is seen
// over 100 degrees of its surface (several views: 0.59 of its sphere) and behind it, within
// its silhouette, lies a 4.5 mm cap of 75 degrees (points its mask carried onto the leaf):
// 0.37 of its sphere, 1.5 quarters, 9 mm from the fruitlet's surface.
TEST(Sizing, HemisphereRuleDropsASphereFitFragmentOnAFruitletsSegment) {
  const Eigen::Vector3d c(0.0, 0.0, 0.3);
  const double r = 0.005, fragment_r = 0.00225;
  const Eigen::Vector3d fragment_c(0.003, 0.0, 0.312);
  const SphereView v = renderSphere(c, r);
  std::vector<Eigen::Vector3f> pts = sphereCap(c, r, 100.0);
  const std::size_t fruitlet_points = pts.size();
  for (const auto& p : sphereCap(fragment_c, fragment_r, 75.0)) pts.push_back(p);
  const sizing::SizingView view{v.mask, v.disparity, v.in, Eigen::Isometry3d::Identity(), {}};
  sizing::SizingConfig config;
  const auto result = sizing::sizeFruitlets({view, view}, pts, nullptr, config);
  ASSERT_EQ(result.fruitlets.size(), 1u);
  ASSERT_EQ(result.unsupported.size(), 1u);
  const auto& fragment = result.unsupported[0];
  EXPECT_GE(fragment.points, (pts.size() - fruitlet_points) * 3 / 4);  // less outliers
  EXPECT_EQ(fragment.size_source, sizing::SizeSource::kSphereFit);
  EXPECT_NEAR(fragment.size_ours_mm, 4.5, 0.2);
  EXPECT_EQ(fragment.support.required_area_fraction, 0.5);
  EXPECT_GT(double(fragment.points), 0.5 * fragment.support.required_points);  // over a quarter
  EXPECT_LT(double(fragment.points), fragment.support.required_points);
  // With the fragment gone the fruitlet's images are its own: sized from them.
  const auto& fruitlet = result.fruitlets[0];
  EXPECT_GE(fruitlet.points, fruitlet_points * 9 / 10);
  EXPECT_EQ(fruitlet.size_source, sizing::SizeSource::kWellSeenImages);
  EXPECT_NEAR(fruitlet.size_ours_mm, 10.0, 0.3);
  EXPECT_EQ(fruitlet.support.required_area_fraction, 0.25);

  // The quarter alone keeps both, each sized by its sphere fit: the fruitlet right (it shows
  // more than a hemisphere), the fragment a phantom.
  config.sphere_fit_support_area_fraction = 0.0;
  const auto quarter = sizing::sizeFruitlets({view, view}, pts, nullptr, config);
  ASSERT_EQ(quarter.fruitlets.size(), 2u);
  for (const auto& d : quarter.fruitlets) EXPECT_EQ(d.size_source, sizing::SizeSource::kSphereFit);

  // Two touching fruitlets merged in 2-D, each seen over 100 degrees: sized by their sphere
  // fits alone, each showing more than a hemisphere, both stay.
  config.sphere_fit_support_area_fraction = 0.5;
  const Eigen::Vector3d left(-0.005, 0.0, 0.3), right(0.005, 0.0, 0.3);
  const SphereView pair = renderSphere(left, r), other = renderSphere(right, r);
  cv::Mat mask = pair.mask | other.mask, disparity = cv::max(pair.disparity, other.disparity);
  const sizing::SizingView pair_view{mask, disparity, pair.in, Eigen::Isometry3d::Identity(), {}};
  std::vector<Eigen::Vector3f> neighbours = sphereCap(left, r, 100.0);
  for (const auto& p : sphereCap(right, r, 100.0)) neighbours.push_back(p);
  const auto two = sizing::sizeFruitlets({pair_view, pair_view}, neighbours, nullptr, config);
  ASSERT_EQ(two.fruitlets.size(), 2u);
  EXPECT_TRUE(two.unsupported.empty());
  for (const auto& d : two.fruitlets) {
    EXPECT_EQ(d.size_source, sizing::SizeSource::kSphereFit);
    EXPECT_NEAR(d.size_ours_mm, 10.0, 0.3);
  }
  // The rule's cost: the same pair seen over 70 degrees only (a third of each sphere) is
  // dropped, one for its sphere fit, the other then sized from the pair's merged outline
  // (13 mm) and short of that size's quarter. Instance masks, or a view that separates their
  // outlines, size them apart.
  std::vector<Eigen::Vector3f> narrow = sphereCap(left, r, 70.0);
  for (const auto& p : sphereCap(right, r, 70.0)) narrow.push_back(p);
  const auto lost = sizing::sizeFruitlets({pair_view}, narrow, nullptr, config);
  EXPECT_TRUE(lost.fruitlets.empty());
  EXPECT_EQ(lost.unsupported.size(), 2u);
  sizing::SizingConfig bad;
  bad.sphere_fit_support_area_fraction = 1.5;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

/// A view of the sphere (c, r) in front of a leaf: the plane z = leaf_z_m (world), from a
/// camera at `position` looking at c. Depth, disparity and the sphere's mask.
SphereView viewOfSphereAndLeaf(const Eigen::Vector3d& c, double r, double leaf_z_m,
                               const Eigen::Vector3d& position) {
  const Eigen::Isometry3d T_world_camera = lookAtPose(position, c);
  SphereView v;
  static_cast<testing::SphereView&>(v) =
      testing::renderSpheres({Eigen::Vector4d(c.x(), c.y(), c.z(), r)}, T_world_camera);
  v.disparity = cv::Mat(v.depth.size(), CV_32F, cv::Scalar(0));
  const Eigen::Matrix3d R = T_world_camera.linear();
  for (int y = 0; y < v.depth.rows; ++y)
    for (int x = 0; x < v.depth.cols; ++x) {
      float z = v.depth.at<float>(y, x);
      if (!(z > 0.0f)) {  // the leaf: the ray (x', y', 1) z meets the plane
        const Eigen::Vector3d ray((x - v.in.cx_px) / v.in.fx_px, (y - v.in.cy_px) / v.in.fy_px, 1);
        z = float((leaf_z_m - position.z()) / (R * ray).z());
      }
      v.disparity.at<float>(y, x) = float(v.in.fx_px * v.in.baseline_m / z);
    }
  return v;
}

// The views' agreement (docs/sizing.md): a patch that one view's mask calls fruitlet (mask
// pixels bled onto the leaf beside a fruitlet's silhouette; or stereo points in the air at its
// depth edge) is seen as leaf, or seen through, by a view from 30 degrees aside, and hidden
// behind the fruitlet from 30 degrees the other way (no evidence). The fruitlet's surface is
// on fruitlet pixels wherever a view sees it.
TEST(Sizing, ViewAgreementTellsAFruitletFromAPatchOneMaskCalledFruitlet) {
  const Eigen::Vector3d c(0.0, 0.0, 0.3);
  const double r = 0.005, leaf_z = 0.32;
  const Eigen::Vector3d aside(0.15, 0.0, 0.04), other_side(-0.15, 0.0, 0.04);
  for (const double patch_z : {leaf_z, 0.31}) {  // on the leaf; in the air before it
    SCOPED_TRACE(patch_z);
    // 81 points, 1.6 mm square, just beside the fruitlet's silhouette as the first view sees it.
    std::vector<Eigen::Vector3f> pts = sphereCap(c, r, 80.0);
    const std::size_t sphere_points = pts.size();
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 9; ++j)
        pts.emplace_back(float(0.0055 + 0.0002 * i), float(0.0002 * (j - 4)), float(patch_z));
    SphereView front = viewOfSphereAndLeaf(c, r, leaf_z, Eigen::Vector3d::Zero());
    for (std::size_t k = sphere_points; k < pts.size(); ++k) {  // the first view's mistake
      const auto px = front.in.project(pts[k].cast<double>());
      ASSERT_TRUE(px);
      const cv::Point at(int(std::lround(px->x())), int(std::lround(px->y())));
      cv::line(front.mask, at, cv::Point(int(front.in.cx_px), int(front.in.cy_px)), 255, 3);
      cv::circle(front.disparity, at, 1, front.in.fx_px * front.in.baseline_m / pts[k].z(), -1);
    }
    const SphereView side = viewOfSphereAndLeaf(c, r, leaf_z, aside);
    const SphereView hidden = viewOfSphereAndLeaf(c, r, leaf_z, other_side);
    std::vector<sizing::SizingView> views;
    for (const SphereView* v : {&std::as_const(front), &side, &hidden})
      views.push_back({v->mask, v->disparity, v->in, v->T_world_camera, {}});
    sizing::SizingConfig config;
    config.min_support_area_fraction = 0.0;  // keep the patch in the fruitlets, to find it
    config.sphere_fit_support_area_fraction = 0.0;
    const auto result = sizing::sizeFruitlets(views, pts, nullptr, config);
    ASSERT_EQ(result.fruitlets.size(), 2u);
    const auto& fruitlet =
        result.fruitlets[0].points > 81 ? result.fruitlets[0] : result.fruitlets[1];
    const auto& patch = result.fruitlets[0].points > 81 ? result.fruitlets[1] : result.fruitlets[0];
    EXPECT_EQ(patch.points, 81u);
    EXPECT_GT(fruitlet.support.view_agreement, 0.95);
    EXPECT_GT(fruitlet.support.view_evidence_points, sphere_points);
    // The first view and the one aside each give all 81 points; the other side a few, those
    // that show past the fruitlet's rim, beside its pixels.
    EXPECT_GE(patch.support.view_evidence_points, 162u);
    EXPECT_LE(patch.support.view_evidence_points, 190u);
    EXPECT_GT(patch.support.view_agreement, 0.45);
    EXPECT_LT(patch.support.view_agreement, 0.6);
    // Without the view aside nothing contradicts the first: the statistic says so.
    const auto two = sizing::sizeFruitlets({views[0], views[2]}, pts, nullptr, config);
    ASSERT_EQ(two.fruitlets.size(), 2u);
    for (const auto& f : two.fruitlets) EXPECT_GT(f.support.view_agreement, 0.95);
    // The agreement rule, for registered views only: the patch (agreement about 0.5, sized
    // well by fewer than two images) is denied at a threshold of 0.7, the fruitlet kept.
    sizing::SizingConfig rule = config;
    rule.min_view_agreement_registered = 0.7;
    const auto unregistered = sizing::sizeFruitlets(views, pts, nullptr, rule);
    EXPECT_EQ(unregistered.fruitlets.size(), 2u);
    EXPECT_EQ(unregistered.events.denied_by_views, 0u);
    rule.registered_views = true;
    const auto registered = sizing::sizeFruitlets(views, pts, nullptr, rule);
    ASSERT_EQ(registered.fruitlets.size(), 1u);
    EXPECT_GT(registered.fruitlets[0].points, 81u);
    EXPECT_EQ(registered.events.denied_by_views, 1u);
    ASSERT_EQ(registered.unsupported.size(), 1u);
    EXPECT_EQ(registered.unsupported[0].points, 81u);
  }
  sizing::SizingConfig bad;
  bad.view_agreement_disparity_px = 0.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = {};
  bad.min_view_agreement_registered = 1.5;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

TEST(Sizing, EmptyInputsAreCountedNotErrors) {
  sizing::SizingConfig config;
  const auto empty = sizing::sizeFruitlets({}, {}, nullptr, config);
  EXPECT_TRUE(empty.fruitlets.empty());
  // A cluster no image sees.
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 200; ++i) pts.emplace_back(0.001f * (i % 10), 0.001f * (i / 10 % 10), 1.0f);
  sizing::SizingView blank{cv::Mat(1080, 1440, CV_8U, cv::Scalar(0)),
                           cv::Mat(1080, 1440, CV_32F, cv::Scalar(0)),
                           {},
                           Eigen::Isometry3d::Identity(),
                           {}};
  const auto unseen = sizing::sizeFruitlets({blank}, pts, nullptr, config);
  EXPECT_TRUE(unseen.fruitlets.empty());
  EXPECT_EQ(unseen.events.unsized_clusters, 1u);
  EXPECT_EQ(unseen.events.not_visible, 1u);
}

TEST(Sizing, DisparityWindowsBeyondTheSensorRangeAreInvalidAndCounted) {
  const Eigen::Vector3d c(0.0, 0.0, 0.3);
  SphereView v = renderSphere(c, 0.005);
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 400; ++i) {
    const double a = 0.1 * i, z = -1.0 + 0.9 * (i % 100) / 100.0;
    pts.push_back((c + 0.005 * Eigen::Vector3d(std::sqrt(1 - z * z) * std::cos(a),
                                               std::sqrt(1 - z * z) * std::sin(a), z))
                      .cast<float>());
  }
  // SGBM speckles: 1.4 px of disparity is 39 m away, far beyond max_depth_m.
  v.disparity.setTo(1.4f, v.mask);
  const sizing::SizingView view{v.mask, v.disparity, v.in, Eigen::Isometry3d::Identity(), {}};
  const auto r = sizing::sizeFruitlets({view}, pts, nullptr, sizing::SizingConfig{});
  EXPECT_TRUE(r.fruitlets.empty());
  EXPECT_EQ(r.events.invalid_disparity_windows, 1u);
  EXPECT_EQ(r.events.unsized_clusters, 1u);
}

}  // namespace
}  // namespace fvp::host
