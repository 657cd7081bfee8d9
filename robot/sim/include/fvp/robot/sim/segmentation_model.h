// A stand-in for a trained fruitlet segmentation network (docs/simulation.md "Appearance and
// segmentation"). It is not a network: it starts from the renderer's exact instance masks and
// adds the errors such networks make on fruitlets, each a WorldConfig key: boundaries off by
// a pixel or two (a smooth random displacement of RMS segmentation_boundary_px), fruitlets
// missing from some views (segmentation_miss_rate each), and small false blobs on leaves
// (segmentation_false_blobs per view, Poisson). Deterministic per (seed, view).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "fvp/robot/sim/world_config.h"

namespace fvp::robot::sim {

class SegmentationModel {
 public:
  /// The boundary displacement varies smoothly over about this many pixels (a network's
  /// errors follow the image's structure, not single pixels).
  static constexpr int kBoundaryCorrelationPx = 16;
  /// False blobs are ellipses with semi-axes in this range, pixels: a 3-8 mm fruitlet at
  /// 0.2-0.4 m spans 8-40 px across.
  static constexpr double kMinBlobRadiusPx = 4.0, kMaxBlobRadiusPx = 12.0;

  SegmentationModel(const WorldConfig& config, std::uint64_t seed);

  /// Whether the world asks for it (segmentation_model: 1).
  bool enabled() const { return enabled_; }
  /// Whether it hands over instances (segmentation_instances: 1) or a binary mask.
  bool instances() const { return instances_; }

  /// The instance mask (CV_16U: 0 = background, each fruitlet and each false blob an id of
  /// its own, numbered afresh in each view) a network would hand over for view `view`, from
  /// the left image's object ids (CV_32S, object_ids.h).
  cv::Mat instancesFor(const cv::Mat& object_id, int view) const;

  /// The same mask without the instances (CV_8U, 255 = fruitlet).
  cv::Mat maskFor(const cv::Mat& object_id, int view) const;

  /// The exact mask: every fruitlet pixel of object_id.
  static cv::Mat trueMask(const cv::Mat& object_id);

 private:
  bool enabled_ = false, instances_ = true;
  std::uint64_t seed_ = 0;
  double boundary_px_ = 0.0, miss_rate_ = 0.0, false_blobs_ = 0.0;
};

}  // namespace fvp::robot::sim
