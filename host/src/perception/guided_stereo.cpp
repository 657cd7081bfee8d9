#include "fvp/host/perception/guided_stereo.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <stdexcept>
#include <vector>

#include "fvp/accel/backend.h"
#include "fvp/accel/kernels.h"
#include "fvp/accel/sequence.h"

namespace fvp::host {
namespace {

// The guide as the kernels read it: disparity * 16, rounded, 0 where none.
std::vector<std::int32_t> packGuide(const cv::Mat& guide_px) {
  std::vector<std::int32_t> out(guide_px.total(), 0);
  for (int v = 0; v < guide_px.rows; ++v) {
    const float* row = guide_px.ptr<float>(v);
    for (int u = 0; u < guide_px.cols; ++u)
      if (row[u] > 0.0f && std::isfinite(row[u]))
        out[std::size_t(v) * guide_px.cols + u] = std::max(1, int(std::lround(row[u] * 16.0f)));
  }
  return out;
}

// OpenCV's speckle filter over the band, as SGBM runs it: regions of fewer than `window`
// pixels whose disparities step by more than `range` from the rest become invalid. The
// window codes (outside, unguided) stay what they are.
void filterSpeckles(cv::Mat& disparity, const GuidedBandRules& rules) {
  if (rules.speckle_window_size <= 0) return;
  const short invalid = static_cast<short>((rules.min_disparity_px - 1) * 16);
  cv::Mat fixed = GuidedStereo::sgbmFixedPoint(disparity, rules.min_disparity_px);
  cv::filterSpeckles(fixed, invalid, rules.speckle_window_size, 16 * rules.speckle_range);
  for (int v = 0; v < disparity.rows; ++v) {
    int* out = disparity.ptr<int>(v);
    const short* in = fixed.ptr<short>(v);
    for (int u = 0; u < disparity.cols; ++u)
      if (out[u] >= 0 && in[u] == invalid) out[u] = FVP_STEREO_INVALID;
  }
}

}  // namespace

void GuidedStereoConfig::validate() const {
  if (p1 < 0 || p2 <= p1 || p2 > 8000)
    throw std::invalid_argument("guided stereo config: p1/p2: expected 0 <= p1 < p2 <= 8000");
}

cv::Mat GuidedStereo::sgbmFixedPoint(const cv::Mat& found, int min_disparity_px) {
  const short invalid = static_cast<short>((min_disparity_px - 1) * 16);
  cv::Mat fixed(found.size(), CV_16S);
  for (int v = 0; v < found.rows; ++v) {
    const int* in = found.ptr<int>(v);
    short* out = fixed.ptr<short>(v);
    for (int u = 0; u < found.cols; ++u) out[u] = in[u] >= 0 ? short(in[u]) : invalid;
  }
  return fixed;
}

GuidedStereo::GuidedStereo(accel::Backend& backend, GuidedStereoConfig config)
    : backend_(backend), config_(config) {
  config_.validate();
}

GuidedStereo::~GuidedStereo() = default;

accel::DeviceBuffer& GuidedStereo::buffer(int slot, std::size_t size_bytes) {
  std::unique_ptr<accel::DeviceBuffer>& b = buffers_[slot];
  if (!b || b->sizeBytes() < size_bytes) b = backend_.createBuffer(size_bytes);
  return *b;
}

cv::Mat GuidedStereo::compute(const cv::Mat& left_grey, const cv::Mat& right_grey, cv::Rect band,
                              const cv::Mat& guide_px, int guide_scale,
                              const GuidedBandRules& rules) {
  if (left_grey.type() != CV_8UC1 || right_grey.type() != CV_8UC1 ||
      left_grey.size() != right_grey.size() || guide_px.type() != CV_32F || guide_px.empty())
    throw std::invalid_argument(
        "GuidedStereo::compute: expected two CV_8UC1 images of equal size and a CV_32F guide");
  accel::StereoParams p{};
  p.image_width_px = left_grey.cols;
  p.image_height_px = left_grey.rows;
  p.band_x_px = band.x;
  p.band_y_px = band.y;
  p.band_width_px = band.width;
  p.band_height_px = band.height;
  p.coarse_width_px = guide_px.cols;
  p.coarse_height_px = guide_px.rows;
  p.coarse_scale = guide_scale;
  p.min_disparity_px = rules.min_disparity_px;
  p.max_disparity_px = rules.max_disparity_px;
  p.p1 = config_.p1;
  p.p2 = config_.p2;
  p.uniqueness_ratio = rules.uniqueness_ratio;
  p.disp12_max_diff = rules.disp12_max_diff;

  const std::size_t pixels = band.area();
  // Both grey images in one buffer, left first, four 8-bit pixels a word: uploaded straight
  // from the images (rows contiguous) into their halves.
  const cv::Mat left_rows = left_grey.isContinuous() ? left_grey : left_grey.clone();
  const cv::Mat right_rows = right_grey.isContinuous() ? right_grey : right_grey.clone();
  const std::size_t image_bytes = left_rows.total();
  const std::vector<std::int32_t> guide_words = packGuide(guide_px);
  accel::DeviceBuffer* grey = &buffer(0, (2 * image_bytes + 3) / 4 * sizeof(std::uint32_t));
  accel::DeviceBuffer* guide = &buffer(1, guide_words.size() * sizeof(std::int32_t));
  const int right_width = band.br().x - std::max(0, band.x - rules.max_disparity_px);
  accel::DeviceBuffer* census =
      &buffer(2, 2 * std::size_t(band.height) * (band.width + right_width) * sizeof(std::uint32_t));
  accel::DeviceBuffer* windows = &buffer(3, pixels * sizeof(std::uint32_t));
  accel::DeviceBuffer* costs = &buffer(4, pixels * 4 * sizeof(std::uint32_t));
  accel::DeviceBuffer* sums = &buffer(5, pixels * 8 * sizeof(std::uint32_t));
  accel::DeviceBuffer* right_best = &buffer(
      6, std::size_t(band.height) * (band.width + rules.max_disparity_px) * sizeof(std::uint32_t));
  accel::DeviceBuffer* disparity = &buffer(7, pixels * sizeof(std::int32_t));

  // One submission: the kernels in order, each reading what the one before wrote.
  accel::Sequence seq(backend_);
  cv::Mat out(band.size(), CV_32S);
  seq.upload(*grey, left_rows.data, image_bytes)
      .upload(*grey, right_rows.data, image_bytes, image_bytes)
      .upload(*guide, guide_words.data(), guide_words.size() * sizeof(std::int32_t))
      .run(accel::kernels::stereoCensus(), p, {grey, census})
      .run(accel::kernels::stereoCost(), p, {census, guide, windows, costs});
  for (int family = 0; family < 4; ++family) {
    p.path_family = family;
    p.first_family = family == 0 ? 1 : 0;
    seq.run(accel::kernels::stereoAggregate(), p, {windows, costs, sums});
  }
  seq.run(accel::kernels::stereoSelect(), p, {windows, sums, right_best, disparity})
      .download(*disparity, out.data, pixels * sizeof(std::int32_t))
      .eval();
  filterSpeckles(out, rules);
  return out;
}

}  // namespace fvp::host
