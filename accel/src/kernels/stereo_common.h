// What the four stereo kernels' descriptors share (kernels/fvp_stereo.h): their parameter
// checks and buffer sizes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fvp/accel/kernel_types.h"
#include "kernel_code.h"

namespace fvp::accel::kernels::stereo {

inline const StereoParams& sp(const void* p) {
  return detail::paramsOf<StereoParams>(p);
}
inline std::size_t bandPixels(const void* p) {
  return std::size_t(sp(p).band_width_px) * std::size_t(sp(p).band_height_px);
}
/// Census pixels: the band, and the right image's columns it may match; two words each.
inline std::size_t censusPixels(const void* p) {
  const StereoParams& s = sp(p);
  return std::size_t(s.band_height_px) *
         (std::size_t(s.band_width_px) + std::size_t(fvp_stereo_right_width(&s)));
}
inline std::size_t censusWords(const void* p) {
  return 2 * censusPixels(p);
}
inline std::size_t greyWords(const void* p) {
  return (2 * std::size_t(sp(p).image_width_px) * std::size_t(sp(p).image_height_px) + 3) / 4;
}
inline std::size_t coarsePixels(const void* p) {
  return std::size_t(sp(p).coarse_width_px) * std::size_t(sp(p).coarse_height_px);
}
inline std::size_t costWords(const void* p) {
  return bandPixels(p) * (FVP_STEREO_CANDIDATES / 4);
}
inline std::size_t sumWords(const void* p) {
  return bandPixels(p) * (FVP_STEREO_CANDIDATES / 2);
}
inline std::size_t rightBestWords(const void* p) {
  return std::size_t(sp(p).band_height_px) *
         (std::size_t(sp(p).band_width_px) + std::size_t(sp(p).max_disparity_px));
}

/// Throws std::invalid_argument naming the kernel and the field for parameters no backend
/// may run: indices stay 32-bit, disparities fit a window word's 15 bits, and eight paths'
/// sums fit 16 bits.
inline void validate(const void* params, const char* what) {
  const StereoParams& p = sp(params);
  const auto fail = [&](const std::string& field, const std::string& expected) {
    throw std::invalid_argument(std::string(what) + ": " + field + ": expected " + expected);
  };
  if (p.image_width_px <= 0 || p.image_height_px <= 0 ||
      std::int64_t{p.image_width_px} * p.image_height_px >= (std::int64_t{1} << 29))
    fail("image size", "positive, fewer than 2^29 pixels");
  if (p.band_width_px <= 0 || p.band_height_px <= 0 || p.band_x_px < 0 || p.band_y_px < 0 ||
      p.band_x_px + p.band_width_px > p.image_width_px ||
      p.band_y_px + p.band_height_px > p.image_height_px)
    fail("band", "a non-empty rectangle inside the image");
  // The guide's values are disparities * 16 / scale: bounded scales keep their products in
  // 32 bits.
  if (p.coarse_scale < 1 || p.coarse_scale > 8 || p.coarse_width_px <= 0 || p.coarse_height_px <= 0)
    fail("guide", "a scale in [1, 8] and a non-empty image");
  if (p.min_disparity_px < 0 || p.max_disparity_px >= 16384 ||
      p.max_disparity_px - p.min_disparity_px + 1 < FVP_STEREO_CANDIDATES)
    fail("disparity range", "0 <= min, max < 16384, at least 16 disparities");
  if (p.p1 < 0 || p.p2 <= p.p1 || p.p2 > 8000) fail("p1/p2", "0 <= p1 < p2 <= 8000");
  if (p.uniqueness_ratio < 0 || p.uniqueness_ratio > 100) fail("uniqueness_ratio", "[0, 100]");
  if (p.path_family < 0 || p.path_family > 3) fail("path_family", "0..3");
}

}  // namespace fvp::accel::kernels::stereo
