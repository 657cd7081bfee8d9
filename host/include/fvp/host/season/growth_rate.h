// A fruitlet's growth rate over a season's visits (docs/season.md): the slope of its sizes
// against the day, with the slope's standard error from the sizings' own standard errors.
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

namespace fvp::host::season {

/// One fruitlet's size on one day of the season.
struct SizeOnDay {
  double day = 0.0;      ///< days since the season's first visit (any origin: only spans count)
  double size_mm = 0.0;  ///< diameter
  /// The sizing's own standard error; NaN where it is not known.
  double standard_error_mm = std::numeric_limits<double>::quiet_NaN();
};

struct GrowthRate {
  double mm_per_day = std::numeric_limits<double>::quiet_NaN();  ///< NaN: fewer than two days
  /// NaN where neither the sizes' standard errors nor three or more sizes give one.
  double standard_error_mm_per_day = std::numeric_limits<double>::quiet_NaN();
  std::size_t sizes = 0;  ///< the sizes the rate rests on
};

/// The smallest standard error a size may state (a micrometre): below it the weights of the
/// fit overflow.
inline constexpr double kMinStandardErrorMm = 1e-6;

/// The least-squares slope of size against day: weighted by 1 / standard error^2 when every
/// size has one (the slope's standard error then follows from them), else unweighted (its
/// standard error from the residuals, with three or more sizes). A fruitlet sized on one day
/// only has no rate (NaN), an expected outcome; a non-finite day or size, or a standard error
/// below kMinStandardErrorMm, is std::invalid_argument.
GrowthRate fitGrowthRate(const std::vector<SizeOnDay>& sizes);

}  // namespace fvp::host::season
