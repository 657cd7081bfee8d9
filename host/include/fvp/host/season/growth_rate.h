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
  /// (estimate - true rate) / standard error follows Student's t with these degrees of
  /// freedom: infinite (the normal) where the sizes' own standard errors give it, sizes - 2
  /// where the residuals estimate it (with three sizes one degree: a 95 % interval is 12.7
  /// standard errors wide each side, not 1.96). Infinite by default: a rate given with a
  /// standard error and nothing more is read as normal.
  double degrees_of_freedom = std::numeric_limits<double>::infinity();
  std::size_t sizes = 0;  ///< the sizes the rate rests on
};

/// The smallest standard error a size may state (a micrometre): below it the weights of the
/// fit overflow.
inline constexpr double kMinStandardErrorMm = 1e-6;

/// The largest a visit's reader takes (a metre: a fruitlet is a few centimetres; far beyond
/// it the weights underflow).
inline constexpr double kMaxStandardErrorMm = 1000.0;

/// The least-squares slope of size against day: weighted by 1 / standard error^2 when every
/// size has one (the slope's standard error then follows from them), else unweighted (its
/// standard error from the residuals, with three or more sizes). A fruitlet sized on one day
/// only has no rate (NaN), an expected outcome; a non-finite day or size, or a standard error
/// below kMinStandardErrorMm, is std::invalid_argument.
GrowthRate fitGrowthRate(const std::vector<SizeOnDay>& sizes);

/// P(T <= t) for the rate's error in standard errors (GrowthRate::degrees_of_freedom:
/// infinite is the normal). Throws std::invalid_argument for degrees of freedom below 1 or
/// NaN, or a NaN t.
double rateErrorCdf(double t, double degrees_of_freedom);

/// The half-width, in standard errors, of the two-sided interval that holds the true rate
/// with probability `level` (0.95: 1.96 for the normal, 12.71 for one degree of freedom).
/// Throws std::invalid_argument for a level outside (0, 1) or bad degrees of freedom.
double rateIntervalHalfWidth(double level, double degrees_of_freedom);

}  // namespace fvp::host::season
