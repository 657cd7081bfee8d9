// Counts of the expected events of one perception pass (dropped disparities, rejected
// saturations, points produced) and its timings. Nothing here is an error.
#pragma once

#include <cstdint>
#include <iosfwd>

namespace fvp::host {

struct PerceptionStats {
  // Disparity stage (StereoMatcher): one count per disparity sample (full-resolution pixel
  // inside the fine band, coarse pixel elsewhere). The matcher writes 0 for every rejected
  // sample, so these five are a breakdown of `nonpositive` below, not additional drops.
  std::int64_t fine_samples = 0;    ///< samples computed at full resolution
  std::int64_t coarse_samples = 0;  ///< samples of the coarse (reduced resolution) pass
  std::int64_t sgbm_invalid = 0;    ///< SGBM marked invalid (uniqueness, L-R check, speckle)
  std::int64_t saturated = 0;       ///< at the top of the search range: object too near
  std::int64_t blind_band = 0;      ///< in the left band where SGBM cannot match
  /// The left image's matching window is dark: nothing the flash lit, only sensor noise,
  /// so any disparity SGBM put there is a guess (it fills black sky from its neighbours).
  std::int64_t no_signal = 0;
  /// Fine samples at an edge of the disparity window (the object is nearer or farther than
  /// the window) that the coarse pass could not place: rejected.
  std::int64_t outside_window = 0;
  /// Fine samples the coarse pass placed wholly outside the window: they keep the coarse
  /// value (not a drop; counted in fine_samples too).
  std::int64_t window_from_coarse = 0;

  // Projection stage (CloudProjector): one count per sample considered.
  std::int64_t nonfinite = 0;     ///< NaN / inf disparities
  std::int64_t nonpositive = 0;   ///< zero (invalid marker or infinitely far) or negative
  std::int64_t out_of_range = 0;  ///< depth outside [min_depth_m, max_depth_m]
  std::int64_t roi_points = 0;
  std::int64_t other_points = 0;

  // Wall times, seconds.
  double segmentation_s = 0.0;
  double tag_s = 0.0;
  double sgbm_s = 0.0;
  double projection_s = 0.0;

  std::int64_t droppedDisparities() const { return nonfinite + nonpositive + out_of_range; }
};

/// One line per group, human readable (used by `fvp capture`).
std::ostream& operator<<(std::ostream& os, const PerceptionStats& stats);

}  // namespace fvp::host
