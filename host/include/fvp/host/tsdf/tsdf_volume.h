// The fruitlets' TSDF (paper, "Fruitlet Sizing"; docs/design.md section 1 step 2): a brick layer
// (host/map/brick_layer.h) of 8^3-voxel bricks at 0.5 mm over a bounded box (the Cluster
// Region's cube), bricks allocated only inside the truncation band of ROI points, with two
// channels, distance and weight, fed by projective integration of each view's ROI depth
// with voxblox's weighting (1/z^2, and a linear drop-off behind the surface).
//
// Integration is the tsdf_integrate kernel (kernels/fvp_tsdf.h) on any backend: the host
// finds the band's bricks and crops the ROI depth to the pixels that hold some, the kernel
// updates every voxel of those bricks, each voxel by exactly one work item. Reads
// (extractSurfacePoints, voxel) go through a host copy of the channels, downloaded once
// after new views.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "fvp/host/core/stereo_intrinsics.h"
#include "fvp/host/map/grid_geometry.h"
#include "fvp/host/tsdf/marching_cubes.h"

namespace fvp::accel {
class Backend;
}
namespace fvp::host::map {
class BrickLayer;
}

namespace fvp::host::tsdf {

inline constexpr double kDefaultTsdfVoxelSizeM = 0.0005;
inline constexpr double kDefaultTruncationM = 0.002;  ///< 4 voxels
inline constexpr float kDefaultMaxWeight = 10000.0f;
// The brick layer's bricks (the kernel indexes voxels by them).
inline constexpr int kBlockSide = accel::kBrickEdge;
inline constexpr int kBlockVoxels = accel::kBrickVoxels;

struct TsdfConfig {
  double voxel_size_m = kDefaultTsdfVoxelSizeM;
  double truncation_m = kDefaultTruncationM;
  float max_weight = kDefaultMaxWeight;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

struct TsdfIntegrateStats {
  std::size_t roi_pixels = 0;             ///< ROI pixels with a valid depth
  std::size_t blocks_allocated = 0;       ///< new blocks this view
  std::size_t blocks_updated = 0;         ///< blocks in the band (every voxel visited)
  std::size_t voxels_updated = 0;         ///< voxel slots the kernel visited (blocks_updated * 512)
  std::size_t depth_pixels_uploaded = 0;  ///< the cropped ROI depth image
  double seconds = 0.0;
};

class TsdfVolume {
 public:
  /// The volume covers bounds_m (snapped outward to whole bricks); nothing outside is
  /// integrated. backend: where the kernel runs; null: a cpu backend of its own.
  TsdfVolume(const TsdfConfig& config, const Eigen::AlignedBox3d& bounds_m,
             accel::Backend* backend = nullptr);
  ~TsdfVolume();
  TsdfVolume(const TsdfVolume&) = delete;
  TsdfVolume& operator=(const TsdfVolume&) = delete;
  const TsdfConfig& config() const { return config_; }
  const map::GridGeometry& geometry() const { return geometry_; }

  /// depth_m: CV_32F z-depth of the left camera, 0 (or non-finite) = invalid; roi_mask:
  /// CV_8U, nonzero = fruitlet, the same size. Only ROI pixels are integrated.
  TsdfIntegrateStats integrate(const cv::Mat& depth_m, const cv::Mat& roi_mask,
                               const StereoIntrinsics& intrinsics,
                               const Eigen::Isometry3d& T_world_camera);

  /// Zero crossings between face-neighbouring voxels that both have weight > 0, linearly
  /// interpolated (world frame, metres), in slot order.
  std::vector<Eigen::Vector3f> extractSurfacePoints() const;
  /// The zero level set as a triangle mesh (marching cubes over cubes whose eight voxels
  /// all have weight > 0), world frame, metres: for looking at, not for sizing.
  TriangleMesh extractMesh() const;

  std::size_t blockCount() const;
  /// Bytes of the brick layer on its device (table, coordinates, distance and weight).
  std::size_t memoryBytes() const;

  /// Distance and weight of the voxel containing p (weight 0 where unallocated or outside).
  std::pair<float, float> voxel(const Eigen::Vector3d& p_m) const;
  /// Every allocated voxel's distance and weight, in slot order (what the kernel wrote).
  const std::vector<float>& distances() const;
  const std::vector<float>& weights() const;

 private:
  void syncHost() const;

  TsdfConfig config_;
  map::GridGeometry geometry_;
  std::unique_ptr<accel::Backend> own_backend_;
  accel::Backend* backend_;
  std::unique_ptr<map::BrickLayer> layer_;
  std::size_t distance_channel_ = 0, weight_channel_ = 0;
  mutable bool host_stale_ = false;
  mutable std::vector<float> host_distance_, host_weight_;
  /// One flag per grid brick, all 0 between calls of integrate (only the band's are set and
  /// cleared): the grid spans the Cluster Region's cube, ~10^5 bricks, the band ~10^2.
  std::vector<std::uint8_t> band_flags_;
};

/// Left-camera z-depth from a disparity map (CV_32F, 0 = invalid): fx * baseline / d.
cv::Mat depthFromDisparity(const cv::Mat& disparity_px, const StereoIntrinsics& intrinsics);

}  // namespace fvp::host::tsdf
