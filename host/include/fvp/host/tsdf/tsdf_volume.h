// The fruitlets' TSDF (paper, "Fruitlet Sizing"; DESIGN.md section 1 step 2): sparse blocks
// of 8^3 voxels at 0.5 mm, allocated only inside the truncation band of ROI points, fed by
// projective integration of each view's ROI depth with voxblox's weighting (1/z^2, and a
// linear drop-off behind the surface). Each voxel is updated by exactly one thread in a
// fixed order, so results do not depend on the thread count.
//
// This is the CPU integrator; the surface it gives feeds the sizing chain.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <unordered_map>
#include <vector>

#include "fvp/host/core/stereo_intrinsics.h"

namespace fvp::host::tsdf {

inline constexpr double kDefaultTsdfVoxelSizeM = 0.0005;
inline constexpr double kDefaultTruncationM = 0.002;  ///< 4 voxels
inline constexpr float kDefaultMaxWeight = 10000.0f;
inline constexpr int kBlockSide = 8;
inline constexpr int kBlockVoxels = kBlockSide * kBlockSide * kBlockSide;

struct TsdfConfig {
  double voxel_size_m = kDefaultTsdfVoxelSizeM;
  double truncation_m = kDefaultTruncationM;
  float max_weight = kDefaultMaxWeight;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

struct TsdfIntegrateStats {
  std::size_t roi_pixels = 0;        ///< ROI pixels with a valid depth
  std::size_t blocks_allocated = 0;  ///< new blocks this view
  std::size_t voxels_updated = 0;
  double seconds = 0.0;
};

class TsdfVolume {
 public:
  explicit TsdfVolume(const TsdfConfig& config = {});
  const TsdfConfig& config() const { return config_; }

  /// depth_m: CV_32F z-depth of the left camera, 0 (or non-finite) = invalid; roi_mask:
  /// CV_8U, nonzero = fruitlet, the same size. Only ROI pixels are integrated.
  TsdfIntegrateStats integrate(const cv::Mat& depth_m, const cv::Mat& roi_mask,
                               const StereoIntrinsics& intrinsics,
                               const Eigen::Isometry3d& T_world_camera);

  /// Zero crossings between face-neighbouring voxels that both have weight > 0, linearly
  /// interpolated (world frame, metres).
  std::vector<Eigen::Vector3f> extractSurfacePoints() const;

  std::size_t blockCount() const { return blocks_.size(); }
  /// Bytes of voxel data (distance + weight per voxel) and the block table.
  std::size_t memoryBytes() const;

  /// Distance and weight of the voxel containing p (weight 0 where unallocated).
  std::pair<float, float> voxel(const Eigen::Vector3d& p_m) const;

 private:
  struct Block {
    std::array<int, 3> coord;
    std::vector<float> distance, weight;
  };
  struct KeyHash {
    std::size_t operator()(const std::array<int, 3>& k) const {
      return (std::size_t(std::uint32_t(k[0])) * 73856093u) ^
             (std::size_t(std::uint32_t(k[1])) * 19349663u) ^
             (std::size_t(std::uint32_t(k[2])) * 83492791u);
    }
  };
  const Block* findBlock(const std::array<int, 3>& coord) const;

  TsdfConfig config_;
  std::vector<Block> blocks_;
  std::unordered_map<std::array<int, 3>, std::size_t, KeyHash> index_;
};

/// Left-camera z-depth from a disparity map (CV_32F, 0 = invalid): fx * baseline / d.
cv::Mat depthFromDisparity(const cv::Mat& disparity_px, const StereoIntrinsics& intrinsics);

}  // namespace fvp::host::tsdf
