#include "fvp/robot/sim/segmentation_model.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "fvp/robot/sim/object_ids.h"

namespace fvp::robot::sim {
namespace {

// "segm" in ASCII: a stream apart from the other simulated errors'.
constexpr std::uint64_t kSegmentationStream = 0x7365676d;

// A smooth random field of RMS rms_px: normal draws on a coarse grid, interpolated.
cv::Mat smoothField(cv::Size size, double rms_px, std::mt19937_64& rng) {
  const int step = SegmentationModel::kBoundaryCorrelationPx;
  cv::Mat coarse(size.height / step + 2, size.width / step + 2, CV_32F);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  for (int r = 0; r < coarse.rows; ++r)
    for (int c = 0; c < coarse.cols; ++c) coarse.at<float>(r, c) = normal(rng);
  cv::Mat fine;
  cv::resize(coarse, fine, cv::Size(coarse.cols * step, coarse.rows * step), 0, 0, cv::INTER_CUBIC);
  fine = fine(cv::Rect(0, 0, size.width, size.height)).clone();
  cv::Scalar mean, stddev;
  cv::meanStdDev(fine, mean, stddev);
  if (stddev[0] > 0.0) fine = (fine - mean[0]) * (rms_px / stddev[0]);
  return fine;
}

// 255 on the pixels of every fruitlet not in `missed` (indexed by fruitlet).
cv::Mat fruitletPixels(const cv::Mat& object_id, const std::vector<bool>& missed) {
  CV_Assert(object_id.type() == CV_32S);
  cv::Mat mask(object_id.size(), CV_8U, cv::Scalar(0));
  for (int v = 0; v < object_id.rows; ++v) {
    const int* id = object_id.ptr<int>(v);
    std::uint8_t* m = mask.ptr<std::uint8_t>(v);
    for (int u = 0; u < object_id.cols; ++u)
      m[u] = isFruitletId(id[u]) && !missed[id[u] - kFirstFruitletId] ? 255 : 0;
  }
  return mask;
}

}  // namespace

SegmentationModel::SegmentationModel(const WorldConfig& c, std::uint64_t seed)
    : enabled_(c.segmentation_model == 1),
      instances_(c.segmentation_instances == 1),
      seed_(seed),
      boundary_px_(c.segmentation_boundary_px),
      miss_rate_(c.segmentation_miss_rate),
      false_blobs_(c.segmentation_false_blobs) {}

cv::Mat SegmentationModel::trueMask(const cv::Mat& object_id) {
  return fruitletPixels(object_id, std::vector<bool>(kMaxFruitlets, false));
}

cv::Mat SegmentationModel::maskFor(const cv::Mat& object_id, int view) const {
  cv::Mat mask;
  cv::compare(instancesFor(object_id, view), 0, mask, cv::CMP_NE);
  return mask;
}

cv::Mat SegmentationModel::instancesFor(const cv::Mat& object_id, int view) const {
  std::seed_seq seq{seed_, kSegmentationStream, static_cast<std::uint64_t>(view)};
  std::mt19937_64 rng(seq);
  std::uniform_real_distribution<double> unit(0.0, 1.0);

  // Misses: whole instances dropped, each with miss_rate (one draw per possible fruitlet,
  // so a fruitlet's fate in a view does not depend on which others are visible).
  std::vector<bool> missed(kMaxFruitlets);
  for (int i = 0; i < kMaxFruitlets; ++i) missed[i] = unit(rng) < miss_rate_;
  cv::Mat mask = fruitletPixels(object_id, missed);

  // Boundary: the signed distance to the mask's boundary (inside positive) plus a smooth
  // field; a pixel is fruitlet where the sum is positive. Far from fruitlets nothing changes.
  if (boundary_px_ > 0.0 && cv::countNonZero(mask) > 0) {
    cv::Mat inside, outside, not_mask;
    cv::distanceTransform(mask, inside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    cv::bitwise_not(mask, not_mask);
    cv::distanceTransform(not_mask, outside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    // The boundary runs half a pixel beyond the last inside pixel's centre: distances to it
    // are the transforms' less 0.5.
    cv::Mat inside01;
    mask.convertTo(inside01, CV_32F, 1.0 / 255.0);
    const cv::Mat signed_px = inside - outside - (inside01 - 0.5f);
    const cv::Mat field = smoothField(mask.size(), boundary_px_, rng);
    mask = (signed_px + field) > 0.0f;
  }

  // Each pixel of the mask belongs to the fruitlet whose true pixels are nearest: a
  // network's instance boundaries follow the outline as its mask does, and touching
  // fruitlets stay apart where they meet.
  cv::Mat instances(object_id.size(), CV_16U, cv::Scalar(0));
  const cv::Mat kept = fruitletPixels(object_id, missed);
  if (cv::countNonZero(kept) > 0) {
    cv::Mat not_kept, distance, nearest;
    cv::bitwise_not(kept, not_kept);
    cv::distanceTransform(not_kept, distance, nearest, cv::DIST_L2, cv::DIST_MASK_5,
                          cv::DIST_LABEL_PIXEL);
    std::vector<int> fruitlet_of_source(1, 0);  // DIST_LABEL_PIXEL: one label per source pixel
    for (int v = 0; v < object_id.rows; ++v)
      for (int u = 0; u < object_id.cols; ++u)
        if (kept.at<std::uint8_t>(v, u)) {
          const int source = nearest.at<int>(v, u);
          if (source >= int(fruitlet_of_source.size())) fruitlet_of_source.resize(source + 1, 0);
          fruitlet_of_source[source] = object_id.at<int>(v, u) - kFirstFruitletId + 1;
        }
    for (int v = 0; v < object_id.rows; ++v)
      for (int u = 0; u < object_id.cols; ++u)
        if (mask.at<std::uint8_t>(v, u)) {
          const int source = nearest.at<int>(v, u);
          instances.at<std::uint16_t>(v, u) = static_cast<std::uint16_t>(
              source < int(fruitlet_of_source.size()) ? fruitlet_of_source[source] : 0);
        }
  }

  // False blobs: centred on leaf pixels, a Poisson number per view, each an instance.
  std::vector<cv::Point> leaf_pixels;
  if (false_blobs_ > 0.0) {
    for (int v = 0; v < object_id.rows; ++v) {
      const int* id = object_id.ptr<int>(v);
      for (int u = 0; u < object_id.cols; ++u)
        if (id[u] >= kFirstLeafId && id[u] < kTreeId) leaf_pixels.emplace_back(u, v);
    }
  }
  const int blobs = false_blobs_ > 0.0 ? std::poisson_distribution<int>(false_blobs_)(rng) : 0;
  for (int b = 0; b < blobs && !leaf_pixels.empty(); ++b) {
    const cv::Point centre =
        leaf_pixels[std::uniform_int_distribution<std::size_t>(0, leaf_pixels.size() - 1)(rng)];
    std::uniform_real_distribution<double> radius(kMinBlobRadiusPx, kMaxBlobRadiusPx);
    const cv::Size axes(static_cast<int>(std::lround(radius(rng))),
                        static_cast<int>(std::lround(radius(rng))));
    cv::Mat blob(mask.size(), CV_8U, cv::Scalar(0));
    cv::ellipse(blob, centre, axes, 360.0 * unit(rng), 0.0, 360.0, cv::Scalar(255), cv::FILLED);
    instances.setTo(kMaxFruitlets + 1 + b, blob & (instances == 0));
  }

  // A network numbers its instances in no particular order, and not the same way in two
  // views: the ids are shuffled per view (drawn last, so the mask above does not change).
  std::vector<std::uint16_t> id_of(kMaxFruitlets + 2 + blobs);
  std::iota(id_of.begin(), id_of.end(), std::uint16_t(0));
  std::shuffle(id_of.begin() + 1, id_of.end(), rng);
  for (int v = 0; v < instances.rows; ++v) {
    std::uint16_t* id = instances.ptr<std::uint16_t>(v);
    for (int u = 0; u < instances.cols; ++u) id[u] = id_of[id[u]];
  }
  return instances;
}

}  // namespace fvp::robot::sim
