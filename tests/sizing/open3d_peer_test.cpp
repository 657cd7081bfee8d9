// The sizing chain's filters and the TSDF against Open3D (Debian's libopen3d-dev, a peer for
// tests and benchmarks only) on the same data: statistical outlier removal keeps the same
// points, DBSCAN finds the same clusters up to label permutation, and the TSDF surfaces of
// the same views agree by chamfer distance.
#include <gtest/gtest.h>

#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>
#include <map>
#include <random>

#include "fvp/host/core/look_at.h"
#include "fvp/host/sizing/point_filters.h"
#include "fvp/host/tsdf/tsdf_volume.h"
#include "sphere_views.h"

namespace fvp::host {
namespace {

// Three fruitlet-sized blobs of surface-like points and uniform noise around them.
std::vector<Eigen::Vector3f> blobsWithNoise(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> n(0.0f, 0.0012f);
  std::uniform_real_distribution<float> u(-0.04f, 0.04f);
  std::vector<Eigen::Vector3f> pts;
  for (const Eigen::Vector3f& c :
       {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(0.02f, 0, 0), Eigen::Vector3f(0, 0.025f, 0.01f)})
    for (int i = 0; i < 600; ++i) pts.push_back(c + Eigen::Vector3f(n(rng), n(rng), n(rng)));
  for (int i = 0; i < 150; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  return pts;
}

open3d::geometry::PointCloud toOpen3d(const std::vector<Eigen::Vector3f>& pts) {
  open3d::geometry::PointCloud cloud;
  for (const auto& p : pts) cloud.points_.push_back(p.cast<double>());
  return cloud;
}

TEST(Open3dPeer, StatisticalOutlierRemovalKeepsTheSamePoints) {
  const auto pts = blobsWithNoise(21);
  const auto ours = sizing::statisticalOutlierInliers(pts, 20, 2.0);
  const auto [cloud, kept] = toOpen3d(pts).RemoveStatisticalOutliers(20, 2.0);
  const std::vector<std::size_t> theirs(kept.begin(), kept.end());
  EXPECT_LT(ours.size(), pts.size());  // some noise removed
  EXPECT_GT(ours.size(), 1700u);       // the blobs kept
  EXPECT_EQ(ours, theirs);
}

TEST(Open3dPeer, DbscanFindsTheSameClustersUpToLabels) {
  const auto pts = blobsWithNoise(22);
  const double eps = 0.002;
  const int min_samples = 10;
  const auto ours = sizing::dbscan(pts, eps, min_samples);
  const auto theirs = toOpen3d(pts).ClusterDBSCAN(eps, min_samples, false);
  ASSERT_EQ(ours.size(), theirs.size());
  std::map<int, int> ours_to_theirs, theirs_to_ours;
  std::size_t clustered = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    ASSERT_EQ(ours[i] == sizing::kDbscanNoise, theirs[i] < 0) << "point " << i;
    if (ours[i] == sizing::kDbscanNoise) continue;
    ++clustered;
    // A bijection between the label sets.
    const auto [a, a_new] = ours_to_theirs.emplace(ours[i], theirs[i]);
    const auto [b, b_new] = theirs_to_ours.emplace(theirs[i], ours[i]);
    ASSERT_EQ(a->second, theirs[i]) << "point " << i;
    ASSERT_EQ(b->second, ours[i]) << "point " << i;
  }
  EXPECT_EQ(ours_to_theirs.size(), 3u);
  EXPECT_GT(clustered, 1700u);
}

TEST(Open3dPeer, TsdfSurfacesAgreeByChamferDistance) {
  const Eigen::Vector3d centre(0.0, 0.0, 0.3);
  const std::vector<Eigen::Vector4d> spheres = {{0.0, 0.0, 0.3, 0.006},
                                                {0.013, 0.002, 0.305, 0.005}};
  const tsdf::TsdfConfig config;
  tsdf::TsdfVolume ours(config, Eigen::AlignedBox3d(centre.array() - 0.03, centre.array() + 0.03));
  open3d::pipelines::integration::ScalableTSDFVolume theirs(
      config.voxel_size_m, config.truncation_m,
      open3d::pipelines::integration::TSDFVolumeColorType::NoColor, 8);
  for (int view = 0; view < 4; ++view) {
    const double a = 0.6 * view - 0.9;
    const Eigen::Vector3d eye = centre + 0.25 * Eigen::Vector3d(std::sin(a), 0.3, -std::cos(a));
    const testing::SphereView v = testing::renderSpheres(spheres, lookAtPose(eye, centre));
    ours.integrate(v.depth, v.mask, v.in, v.T_world_camera);
    open3d::geometry::Image depth, colour;
    depth.Prepare(v.in.width_px, v.in.height_px, 1, 4);
    colour.Prepare(v.in.width_px, v.in.height_px, 1, 1);
    for (int y = 0; y < v.in.height_px; ++y)
      for (int x = 0; x < v.in.width_px; ++x)
        *depth.PointerAt<float>(x, y) = v.mask.at<std::uint8_t>(y, x) ? v.depth.at<float>(y, x) : 0;
    const auto rgbd =
        open3d::geometry::RGBDImage::CreateFromColorAndDepth(colour, depth, 1.0, 10.0, false);
    theirs.Integrate(
        *rgbd,
        open3d::camera::PinholeCameraIntrinsic(v.in.width_px, v.in.height_px, v.in.fx_px,
                                               v.in.fy_px, v.in.cx_px, v.in.cy_px),
        v.T_world_camera.inverse().matrix());
  }
  const auto a = ours.extractSurfacePoints();
  std::vector<Eigen::Vector3f> b;
  const auto cloud = theirs.ExtractPointCloud();  // the range below must not outlive it
  for (const auto& p : cloud->points_) b.push_back(p.cast<float>());
  ASSERT_GT(a.size(), 1000u);
  ASSERT_GT(b.size(), 1000u);
  const double chamfer_m = sizing::chamferDistance_m(a, b);
  // Both lie on the spheres to a fraction of a 0.5 mm voxel; they differ in weighting
  // (voxblox's 1/z^2 against Open3D's 1) and in where each interpolates the crossing.
  EXPECT_LT(chamfer_m, 0.0001) << "chamfer " << chamfer_m * 1e3 << " mm";
  std::cout << "TSDF surfaces: ours " << a.size() << " points, Open3D's " << b.size()
            << ", chamfer distance " << chamfer_m * 1e3 << " mm\n";
}

}  // namespace
}  // namespace fvp::host
